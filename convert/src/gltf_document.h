// Internal: building a binary glTF (.glb) with tinygltf (the only header that includes
// <tiny_gltf.h>). Packaged libtinygltf 2.7.0 is used for writing only; it is linked before
// Draco because libdraco exports an older copy of some tinygltf symbols (ECOSYSTEM.md §1.4).
//
// One GLB = one JSON chunk + one BIN chunk (glTF 2.0 "Binary glTF Layout"): every array goes
// into buffer 0, which tinygltf writes as the BIN chunk. bufferViews start on 4-byte
// boundaries, so float and uint32 accessors are aligned (glTF 2.0 "Data Alignment").
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <string>
#include <vector>

#include "spherekit/convert/gltf_draco.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert::detail {

// glTF enums (glTF 2.0 "Accessors" and "Meshes").
inline constexpr int kFloat = 5126;          // componentType FLOAT
inline constexpr int kUnsignedShort = 5123;  // componentType UNSIGNED_SHORT
inline constexpr int kUnsignedInt = 5125;    // componentType UNSIGNED_INT
inline constexpr int kArrayBuffer = 34962;   // bufferView target for vertex attributes
inline constexpr int kElementArrayBuffer = 34963;  // bufferView target for indices
inline constexpr int kTriangles = 4;         // primitive mode

/// Index component type for `points` vertices: UNSIGNED_SHORT while every index fits below
/// 65535 (glTF 2.0: indices must not use the largest value of their type, the primitive
/// restart value), else UNSIGNED_INT.
int index_component_type(std::int64_t points);

/// A glTF document under construction, written as one .glb.
class GlbBuilder {
 public:
  GlbBuilder();

  tinygltf::Model& model() { return model_; }

  /// Appends `bytes` to the binary buffer as a new bufferView (target 0: none) and returns it.
  int add_buffer_view(const void* bytes, std::size_t size, int target);

  /// An accessor without bufferView (its data is in a Draco bitstream) describing `count`
  /// elements; `min`/`max` written when non-empty.
  int add_accessor_without_data(int component_type, int type, std::size_t count, const std::vector<double>& min,
                                const std::vector<double>& max);

  /// Float accessor over the rows of `M` (2 or 3 columns: VEC2/VEC3, stored as float) in a new
  /// bufferView; with_bounds: min/max of the stored floats.
  int add_float_accessor(const RowMatXd& M, bool with_bounds);

  /// Index accessor (SCALAR, type by index_component_type(points)) over F in a new bufferView.
  int add_index_accessor(const RowMat3i& F, std::int64_t points);

  /// A mesh with one Draco-compressed primitive: accessors from the decoded data (counts,
  /// POSITION min/max of the decoded floats, written as their shortest decimals),
  /// KHR_draco_mesh_compression pointing at a new bufferView holding `primitive.bytes`;
  /// `extras` null: none. Returns the mesh index.
  int add_draco_mesh(const DracoPrimitive& primitive, const std::string& name, tinygltf::Value extras);

  /// Declares an extension used (once), and required if `required`.
  void use_extension(const std::string& name, bool required);

  /// Serializes the document as a .glb. Errors: Internal.
  Result<std::string> to_glb();

 private:
  tinygltf::Model model_;
};

/// The shortest decimal that reads back as `x` (as float), as a double: 0.1f gives 0.1, not
/// 0.100000001490116. POSITION bounds are written so (a float's exact double value needs up to
/// 17 digits; a level file's JSON is part of its size), and still read back as the same float.
double shortest_float_decimal(float x);

/// JSON helpers for extras.
tinygltf::Value json_number(double x);
tinygltf::Value json_int(std::int64_t x);
tinygltf::Value json_string(const std::string& s);
tinygltf::Value json_array(const std::vector<double>& xs);
tinygltf::Value json_object(tinygltf::Value::Object o);

/// The "quantization" object of a primitive's extras: bits, grids, steps and the budget.
tinygltf::Value quantization_json(const QuantizationChoice& choice, bool has_normals, bool has_texcoords);

/// asset.extras.spherekit: toolkit version, format version, and what the caller adds.
tinygltf::Value provenance_json(tinygltf::Value::Object fields);

}  // namespace spherekit::convert::detail
