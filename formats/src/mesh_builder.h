// Collects vertices and polygons from any reader and turns them into a validated TriMesh.
// One place for the checks every format shares: polygon policy, corner counts, index range,
// finite coordinates and "no faces", so all readers word their errors the same way.
//
// Design note: vertices and triangles go straight into the output Eigen matrices, grown by
// doubling; Eigen resizes row-major matrices with realloc, so growing (mremap for large
// blocks) and the final shrink are cheap and nothing is copied at the end. Triangles go in as
// they arrive; polygons reserve their n - 2 rows and keep their corners until finish(), which
// triangulates them (polygon_triangulation.h) once every vertex position is known (OBJ allows
// forward references, PLY may list faces before vertices). Indices are checked against the
// vertex count once the file is fully read, because OBJ allows forward references and PLY
// may list faces before vertices; only the rare indices that are not yet known to be valid
// are remembered (with their source position) for that check.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/polygon_triangulation.h"

namespace spherekit::formats::detail {

/// Where a face came from, for error messages: a text line ("m.obj:17:") or the 0-based
/// number of the face in a binary or element-structured file ("m.ply: face 17:").
struct FaceSource {
  enum class Kind { Line, Element };
  Kind kind = Kind::Element;
  std::uint64_t number = 0;

  static FaceSource line(std::uint64_t n) { return {Kind::Line, n}; }
  static FaceSource element(std::uint64_t n) { return {Kind::Element, n}; }
};

class MeshBuilder {
 public:
  /// `index_base` is only used to print indices as the file wrote them (1 for OBJ).
  MeshBuilder(const std::string& path, PolygonPolicy policy, int index_base = 0)
      : path_(path), policy_(policy), index_base_(index_base) {}

  /// Pre-sizes storage. Callers pass counts already clamped by what the file size can hold,
  /// so a header claiming 2^40 vertices cannot trigger a huge allocation.
  void reserve(std::size_t vertices, std::size_t triangles) {
    const auto v = static_cast<Eigen::Index>(std::min<std::size_t>(vertices, kMaxIndex));
    const auto t = static_cast<Eigen::Index>(std::min<std::size_t>(triangles, kMaxIndex));
    if (v > V_.rows()) V_.conservativeResize(v, 3);
    if (t > F_.rows()) F_.conservativeResize(t, 3);
  }

  std::int64_t num_vertices() const { return nv_; }

  Status add_vertex(double x, double y, double z) {
    if (nv_ >= kMaxIndex) return Status(ErrorCode::Unsupported, path_ + ": more than 2^31-1 vertices");
    if (nv_ == V_.rows()) V_.conservativeResize(grown(V_.rows()), 3);
    V_(nv_, 0) = x;
    V_(nv_, 1) = y;
    V_(nv_, 2) = z;
    ++nv_;
    return {};
  }

  /// Also carry a second index per face corner (OBJ texture-coordinate indices) through the
  /// triangulation: corner_channel() then gives it per triangle corner.
  void enable_corner_channel() { channel_enabled_ = true; }

  /// Adds a polygon of `n` 0-based corner indices (relative OBJ indices already resolved).
  /// `channel`: n values of the corner channel, or nullptr if this face has none.
  Status add_face(const std::int64_t* corners, std::size_t n, FaceSource where,
                  const std::int64_t* channel = nullptr) {
    if (n < 3) {
      return Status(ErrorCode::ParseError, subject(where) + " has " + std::to_string(n) +
                                               (n == 1 ? " corner" : " corners") + " (need at least 3)");
    }
    if (n > 3 && policy_ == PolygonPolicy::Reject) {
      return Status(ErrorCode::InvalidInput, subject(where) + " has " + std::to_string(n) +
                                                 " corners (polygons are rejected by the read options)");
    }
    if (first_corner_count_ == 0) first_corner_count_ = n;
    if (n != first_corner_count_ && policy_ == PolygonPolicy::TriangulateUniform) {
      std::size_t lo = std::min(n, first_corner_count_), hi = std::max(n, first_corner_count_);
      return Status(ErrorCode::InvalidInput, prefix(where) + "mixed " + corner_noun(lo) + " and " +
                                                 corner_noun(hi) +
                                                 " faces (PolygonPolicy::Triangulate accepts them)");
    }
    if (nf_ + static_cast<std::int64_t>(n - 2) > kMaxIndex) {
      return Status(ErrorCode::Unsupported, path_ + ": more than 2^31-1 triangles");
    }
    for (std::size_t i = 0; i < n; ++i) {
      // Indices that are not yet known to be valid are checked in finish().
      if (corners[i] < 0 || corners[i] >= num_vertices()) pending_.push_back({corners[i], where});
    }
    const auto polygon = static_cast<std::int32_t>(counts_.faces);
    ++counts_.faces;
    if (n == 3) {
      ++counts_.triangles;
    } else if (n == 4) {
      ++counts_.quads;
    } else {
      ++counts_.ngons;
    }
    if (channel_enabled_ && !channel) channel_complete_ = false;
    if (n > 3) {
      // Rows reserved now, filled by finish(): the corners' positions may not be read yet.
      polygons_.push_back({nf_, corner_store_.size(), n});
      corner_store_.insert(corner_store_.end(), corners, corners + n);
      if (channel_enabled_ && channel) channel_store_.insert(channel_store_.end(), channel, channel + n);
      if (channel_enabled_ && !channel) channel_store_.resize(channel_store_.size() + n, -1);
    }
    for (std::size_t i = 1; i + 1 < n; ++i) {
      if (nf_ == F_.rows()) F_.conservativeResize(grown(F_.rows()), 3);
      F_(nf_, 0) = clamp_index(corners[0]);
      F_(nf_, 1) = clamp_index(corners[i]);
      F_(nf_, 2) = clamp_index(corners[i + 1]);
      face_polygon_.push_back(polygon);
      if (channel_enabled_) channel_.insert(channel_.end(), {channel ? channel[0] : -1, channel ? channel[i] : -1,
                                                             channel ? channel[i + 1] : -1});
      ++nf_;
    }
    return {};
  }

  /// Validates everything, triangulates the polygons and returns the mesh. Errors:
  /// InvalidInput for no faces, an index out of range or a non-finite coordinate.
  Result<TriMesh> finish(ReadInfo& info) {
    const std::int64_t nv = nv_;
    for (const Pending& p : pending_) {
      if (p.index < 0 || p.index >= nv) {
        return Status(ErrorCode::InvalidInput, subject(p.where) + " index " +
                                                   std::to_string(p.index + index_base_) +
                                                   " out of range (" + std::to_string(nv) + " vertices)");
      }
    }
    if (nf_ == 0) return Status(ErrorCode::InvalidInput, path_ + ": no faces");
    for (Eigen::Index i = 0; i < nv_; ++i) {
      if (!std::isfinite(V_(i, 0)) || !std::isfinite(V_(i, 1)) || !std::isfinite(V_(i, 2))) {
        return Status(ErrorCode::InvalidInput, path_ + ": vertex " + std::to_string(i) + " has a non-finite coordinate");
      }
    }
    triangulate_polygons();
    TriMesh mesh;
    V_.conservativeResize(nv_, 3);
    F_.conservativeResize(nf_, 3);
    mesh.V = std::move(V_);
    mesh.F = std::move(F_);
    info.polygons_triangulated = static_cast<int>(counts_.quads + counts_.ngons);
    info.faces = counts_;
    info.face_polygon = std::move(face_polygon_);
    return mesh;
  }

  /// After finish(): the corner channel of every triangle corner (3 per triangle, in F's
  /// order), or empty if it was not enabled or some face had none.
  std::vector<std::int64_t> corner_channel() {
    if (!channel_enabled_ || !channel_complete_) return {};
    return std::move(channel_);
  }

 private:
  static constexpr std::int64_t kMaxIndex = std::numeric_limits<std::int32_t>::max();

  struct Pending {
    std::int64_t index;
    FaceSource where;
  };
  struct Polygon {
    std::int64_t first_triangle;
    std::size_t first_corner;  // in corner_store_ (and channel_store_)
    std::size_t corners;
  };

  /// Replaces the placeholder fan of every polygon by its triangulation (indices are valid now).
  void triangulate_polygons() {
    std::vector<Eigen::Vector3d> points;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    for (const Polygon& p : polygons_) {
      const std::int64_t* c = corner_store_.data() + p.first_corner;
      points.resize(p.corners);
      for (std::size_t i = 0; i < p.corners; ++i) points[i] = V_.row(static_cast<Eigen::Index>(c[i])).transpose();
      triangles.clear();
      triangulate_polygon(points, triangles);
      for (std::size_t t = 0; t < triangles.size(); ++t) {
        const Eigen::Index row = static_cast<Eigen::Index>(p.first_triangle) + static_cast<Eigen::Index>(t);
        for (int k = 0; k < 3; ++k) {
          const std::size_t local = triangles[t][static_cast<std::size_t>(k)];
          F_(row, k) = static_cast<std::int32_t>(c[local]);
          if (channel_enabled_ && channel_complete_)
            channel_[3 * static_cast<std::size_t>(row) + static_cast<std::size_t>(k)] =
                channel_store_[p.first_corner + local];
        }
      }
    }
  }

  static Eigen::Index grown(Eigen::Index rows) {
    return std::min<Eigen::Index>(kMaxIndex, std::max<Eigen::Index>(64, 2 * rows));
  }
  static std::int32_t clamp_index(std::int64_t i) {
    return (i < 0 || i > kMaxIndex) ? 0 : static_cast<std::int32_t>(i);  // invalid ones are in pending_
  }
  static std::string corner_noun(std::size_t n) {
    return n == 3 ? "triangle" : std::to_string(n) + "-corner";
  }
  /// "m.obj:17: " or "m.ply: face 17: "
  std::string prefix(FaceSource w) const {
    if (w.kind == FaceSource::Kind::Line) return path_ + ":" + std::to_string(w.number) + ": ";
    return path_ + ": face " + std::to_string(w.number) + ": ";
  }
  /// "m.obj:17: face" or "m.ply: face 17"
  std::string subject(FaceSource w) const {
    if (w.kind == FaceSource::Kind::Line) return path_ + ":" + std::to_string(w.number) + ": face";
    return path_ + ": face " + std::to_string(w.number);
  }

  std::string path_;
  PolygonPolicy policy_;
  int index_base_;
  RowMat3d V_;  // rows [0, nv_) are vertices; the rest is capacity
  RowMat3i F_;  // rows [0, nf_) are triangles; the rest is capacity
  std::int64_t nv_ = 0, nf_ = 0;
  std::vector<Pending> pending_;
  std::size_t first_corner_count_ = 0;
  FaceCounts counts_;
  std::vector<std::int32_t> face_polygon_;
  std::vector<Polygon> polygons_;
  std::vector<std::int64_t> corner_store_;
  bool channel_enabled_ = false, channel_complete_ = true;
  std::vector<std::int64_t> channel_, channel_store_;
};

}  // namespace spherekit::formats::detail
