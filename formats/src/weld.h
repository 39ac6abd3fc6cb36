// Vertex welding for formats that do not share vertices between faces. STL stores three
// positions per triangle, and glTF splits a vertex wherever any attribute (normal, UV,
// material) has a seam; both must be re-indexed before the mesh has any topology.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <unordered_map>

#include "mesh_builder.h"

namespace spherekit::formats::detail {

/// Gives one vertex index per distinct position. Positions are compared bit for bit (after
/// mapping -0.0 to +0.0): writers copy the same coordinates to every split copy, so exact
/// comparison merges exactly the copies and never two distinct, merely close, points.
class PositionWelder {
 public:
  explicit PositionWelder(MeshBuilder& builder) : builder_(builder) {}

  /// The index of the vertex at (x, y, z), adding it to the builder on first sight.
  Status add(double x, double y, double z, std::int64_t& index) {
    Key key{bits(x), bits(y), bits(z)};
    auto [it, inserted] = index_.try_emplace(key, builder_.num_vertices());
    if (inserted) SPHEREKIT_RETURN_IF_ERROR(builder_.add_vertex(x, y, z));
    index = it->second;
    return {};
  }
  void reserve(std::size_t n) { index_.reserve(n); }

 private:
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      // 64-bit multiply-xorshift mix: coordinates differ mostly in low mantissa bits.
      std::uint64_t h = k[0] * 0x9E3779B97F4A7C15ull;
      h = (h ^ (h >> 29) ^ k[1]) * 0xBF58476D1CE4E5B9ull;
      h = (h ^ (h >> 32) ^ k[2]) * 0x94D049BB133111EBull;
      return static_cast<std::size_t>(h ^ (h >> 31));
    }
  };
  static std::uint64_t bits(double v) {
    v += 0.0;  // -0.0 + 0.0 == +0.0: the two zeros are the same point
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  }

  MeshBuilder& builder_;
  std::unordered_map<Key, std::int64_t, KeyHash> index_;
};

}  // namespace spherekit::formats::detail
