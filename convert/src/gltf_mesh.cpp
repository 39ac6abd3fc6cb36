// glTF primitives from geometry images and triangle meshes (see gltf_mesh.h).
//
// The triangulation repeats geometry_image_mesh's (spherekit/geometry_image.h: cells in
// row-major order, each split along the diagonal parallel to its quadrant's diamond edge,
// ALGORITHM.md §1.5) on texel points instead of welded vertices; a test checks that the two
// agree face for face through position_index.
#include "spherekit/convert/gltf_mesh.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "spherekit/remove_faces.h"

namespace spherekit::convert {

Status check_gltf_mesh(const GltfMesh& mesh) {
  const Eigen::Index points = mesh.V.rows();
  if (points == 0 || mesh.F.rows() == 0) return Status(ErrorCode::InvalidInput, "glTF primitive has no points or no faces");
  if (mesh.N.rows() != 0 && mesh.N.rows() != points)
    return Status(ErrorCode::InvalidInput, "glTF primitive: " + std::to_string(mesh.N.rows()) + " normals for " +
                                               std::to_string(points) + " points");
  if (mesh.UV.rows() != 0 && mesh.UV.rows() != points)
    return Status(ErrorCode::InvalidInput, "glTF primitive: " + std::to_string(mesh.UV.rows()) +
                                               " texture coordinates for " + std::to_string(points) + " points");
  if (!mesh.position_index.empty() && static_cast<Eigen::Index>(mesh.position_index.size()) != points)
    return Status(ErrorCode::InvalidInput, "glTF primitive: position_index has " +
                                               std::to_string(mesh.position_index.size()) + " entries for " +
                                               std::to_string(points) + " points");
  for (std::size_t p = 0; p < mesh.position_index.size(); ++p)
    if (mesh.position_index[p] < 0)
      return Status(ErrorCode::InvalidInput, "glTF primitive: negative position_index at point " + std::to_string(p));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= points)
        return Status(ErrorCode::InvalidInput, "glTF primitive: face " + std::to_string(f) + " has point index " +
                                                   std::to_string(mesh.F(f, k)) + " out of range");
  if (!mesh.V.allFinite() || !mesh.N.allFinite() || !mesh.UV.allFinite())
    return Status(ErrorCode::InvalidInput, "glTF primitive has NaN or infinite values");
  return Status();
}

Result<GeometryImage> subsample_geometry_image(const GeometryImage& image, int size) {
  const int n = image.size;
  const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  if (!is_geometry_image_size(n) || image.positions.size() != 3 * texels || image.normals.size() != 3 * texels)
    return Status(ErrorCode::InvalidArgument, "malformed geometry image (size " + std::to_string(n) + ")");
  if (!is_geometry_image_size(size) || size > n)
    return Status(ErrorCode::InvalidArgument, "cannot subsample a " + std::to_string(n) + " x " + std::to_string(n) +
                                                  " geometry image to " + std::to_string(size) +
                                                  " (must be 2^k+1 and not larger)");
  // Both sizes are 2^k+1, so the stride is a power of two.
  const int stride = (n - 1) / (size - 1);
  GeometryImage out;
  out.size = size;
  const auto m = static_cast<std::size_t>(size) * static_cast<std::size_t>(size);
  out.positions.resize(3 * m);
  out.normals.resize(3 * m);
  const bool faces = image.face_ids.size() == texels, holes = image.in_hole.size() == texels;
  if (faces) out.face_ids.resize(m);
  if (holes) out.in_hole.resize(m);
  for (int a = 0; a < size; ++a)
    for (int b = 0; b < size; ++b) {
      const std::size_t src = static_cast<std::size_t>(a) * stride * n + static_cast<std::size_t>(b) * stride;
      const std::size_t dst = static_cast<std::size_t>(a) * size + b;
      for (int c = 0; c < 3; ++c) {
        out.positions[3 * dst + c] = image.positions[3 * src + c];
        out.normals[3 * dst + c] = image.normals[3 * src + c];
      }
      if (faces) out.face_ids[dst] = image.face_ids[src];
      if (holes) {
        out.in_hole[dst] = image.in_hole[src];
        out.texels_in_holes += image.in_hole[src] != 0;
      }
    }
  return out;
}

Result<GltfMesh> gltf_mesh_from_geometry_image(const GeometryImage& image, int texture_size) {
  const int n = image.size;
  const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  if (!is_geometry_image_size(n) || image.positions.size() != 3 * texels || image.normals.size() != 3 * texels)
    return Status(ErrorCode::InvalidArgument, "malformed geometry image (size " + std::to_string(n) + ")");
  const int T = texture_size == 0 ? n : texture_size;
  if (!is_geometry_image_size(T) || T < n || (T - 1) % (n - 1) != 0)
    return Status(ErrorCode::InvalidArgument, "texture size " + std::to_string(T) + " does not contain a " +
                                                  std::to_string(n) + " x " + std::to_string(n) +
                                                  " geometry image as a subsampling");
  const int stride = (T - 1) / (n - 1);  // a power of two: both sizes are 2^k+1

  GltfMesh out;
  out.texture_size = T;
  out.V.resize(static_cast<Eigen::Index>(texels), 3);
  out.N.resize(static_cast<Eigen::Index>(texels), 3);
  out.UV.resize(static_cast<Eigen::Index>(texels), 2);
  out.position_index.resize(texels);
  // Welded vertex numbering of geometry_image_mesh.
  const std::vector<int> vertex_of = geometry_image_welded_ids(n, nullptr);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto p = static_cast<Eigen::Index>(i) * n + j;
      out.V.row(p) = image.position(i, j).cast<double>().transpose();
      Eigen::Vector3d nrm = image.normal(i, j).cast<double>();
      const double len = nrm.norm();
      // Image normals are unit up to float rounding; a zero normal (degenerate source faces)
      // gets +z so that the accessor stays a unit vector (glTF requires unit NORMALs).
      nrm = len > 0 ? Eigen::Vector3d(nrm / len) : Eigen::Vector3d(0, 0, 1);
      out.N.row(p) = nrm.transpose();
      // Texel centre in the full texture (gltf_mesh.h).
      out.UV(p, 0) = (static_cast<double>(j) * stride + 0.5) / T;
      out.UV(p, 1) = (static_cast<double>(i) * stride + 0.5) / T;
      out.position_index[static_cast<std::size_t>(p)] = vertex_of[static_cast<std::size_t>(p)];
    }

  out.F = geometry_image_grid_faces(n);
  return out;
}

std::vector<std::uint8_t> gltf_mesh_hole_faces(const GltfMesh& mesh, const GeometryImage& image) {
  const int T = image.size;
  std::vector<std::uint8_t> out;
  if (!is_geometry_image_size(T) || image.in_hole.size() != static_cast<std::size_t>(T) * T ||
      mesh.UV.rows() != mesh.V.rows() || mesh.UV.rows() == 0)
    return out;
  // Inverse of the texel-centre formula; rounding absorbs the texture-coordinate quantization
  // (a fraction of a texel, gltf_draco.h).
  auto texel = [T](double x) {
    return static_cast<int>(std::clamp(std::lround(x * T - 0.5), 0L, static_cast<long>(T - 1)));
  };
  out.resize(static_cast<std::size_t>(mesh.F.rows()), 0);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    int corners = 0;  // in a hole; the rule of geometry_image_hole_faces: two or three
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index p = mesh.F(f, k);
      if (p < 0 || p >= mesh.UV.rows()) continue;
      const int i = texel(mesh.UV(p, 1)), j = texel(mesh.UV(p, 0));
      corners += image.in_hole[static_cast<std::size_t>(i) * T + j] != 0;
    }
    out[static_cast<std::size_t>(f)] = corners >= 2 ? 1 : 0;
  }
  return out;
}

GltfMesh gltf_mesh_without_faces(const GltfMesh& mesh, const std::vector<std::uint8_t>& drop) {
  if (drop.size() != static_cast<std::size_t>(mesh.F.rows()) || !check_gltf_mesh(mesh).ok()) return mesh;
  std::vector<int> new_index;
  const TriMesh kept = remove_faces(TriMesh{mesh.V, mesh.F}, drop, &new_index);
  GltfMesh out;
  out.V = kept.V;
  out.F = kept.F;
  out.texture_size = mesh.texture_size;
  if (mesh.N.rows() > 0) out.N.resize(kept.V.rows(), 3);
  if (mesh.UV.rows() > 0) out.UV.resize(kept.V.rows(), 2);
  if (!mesh.position_index.empty()) out.position_index.resize(static_cast<std::size_t>(kept.V.rows()));
  for (Eigen::Index p = 0; p < mesh.V.rows(); ++p) {
    const int q = new_index[static_cast<std::size_t>(p)];
    if (q < 0) continue;
    if (mesh.N.rows() > 0) out.N.row(q) = mesh.N.row(p);
    if (mesh.UV.rows() > 0) out.UV.row(q) = mesh.UV.row(p);
    if (!mesh.position_index.empty())
      out.position_index[static_cast<std::size_t>(q)] = mesh.position_index[static_cast<std::size_t>(p)];
  }
  return out;
}

std::vector<std::int32_t> gltf_point_vertices(const GltfMesh& mesh, std::int32_t* vertices) {
  std::vector<std::int32_t> vertex_of_point;
  *vertices = static_cast<std::int32_t>(mesh.V.rows());
  if (mesh.position_index.empty()) return vertex_of_point;
  const std::int32_t largest = *std::max_element(mesh.position_index.begin(), mesh.position_index.end());
  std::vector<std::int32_t> dense(static_cast<std::size_t>(largest) + 1, -1);
  *vertices = 0;
  vertex_of_point.reserve(mesh.position_index.size());
  for (const std::int32_t v : mesh.position_index) {
    std::int32_t& d = dense[static_cast<std::size_t>(v)];
    if (d < 0) d = (*vertices)++;
    vertex_of_point.push_back(d);
  }
  return vertex_of_point;
}

GltfMesh gltf_mesh_without_texcoords(const GltfMesh& mesh) {
  if (!check_gltf_mesh(mesh).ok()) return mesh;
  GltfMesh out;
  if (mesh.position_index.empty()) {
    out = mesh;
    out.UV.resize(0, 2);
    out.texture_size = 0;
    return out;
  }
  std::int32_t vertices = 0;
  const std::vector<std::int32_t> point_of = gltf_point_vertices(mesh, &vertices);
  std::vector<Eigen::Index> first(static_cast<std::size_t>(vertices), -1);  // each vertex's first point
  for (Eigen::Index p = mesh.V.rows() - 1; p >= 0; --p) first[static_cast<std::size_t>(point_of[static_cast<std::size_t>(p)])] = p;
  const auto kept = static_cast<Eigen::Index>(vertices);
  out.V.resize(kept, 3);
  if (mesh.N.rows() > 0) out.N.resize(kept, 3);
  for (Eigen::Index q = 0; q < kept; ++q) {
    out.V.row(q) = mesh.V.row(first[static_cast<std::size_t>(q)]);
    if (mesh.N.rows() > 0) out.N.row(q) = mesh.N.row(first[static_cast<std::size_t>(q)]);
  }
  out.F.resize(mesh.F.rows(), 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) out.F(f, c) = point_of[static_cast<std::size_t>(mesh.F(f, c))];
  return out;
}

Result<GltfMesh> gltf_mesh_from_trimesh(const TriMesh& mesh) {
  const Eigen::Index nv = mesh.V.rows();
  if (nv == 0 || mesh.F.rows() == 0) return Status(ErrorCode::InvalidInput, "empty mesh");
  if (!mesh.V.allFinite()) return Status(ErrorCode::InvalidInput, "mesh has NaN or infinite coordinates");
  RowMat3d N = RowMat3d::Zero(nv, 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= nv)
        return Status(ErrorCode::InvalidInput, "face " + std::to_string(f) + " has vertex index " +
                                                   std::to_string(mesh.F(f, k)) + " out of range");
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    // The cross product's length is twice the face area: area weighting for free.
    const Eigen::Vector3d w = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) N.row(mesh.F(f, k)) += w.transpose();
  }
  for (Eigen::Index v = 0; v < nv; ++v) {
    const double len = N.row(v).norm();
    if (len > 0 && std::isfinite(len))
      N.row(v) /= len;
    else
      N.row(v) << 0, 0, 1;
  }
  GltfMesh out;
  out.V = mesh.V;
  out.N = std::move(N);
  out.F = mesh.F;
  return out;
}

}  // namespace spherekit::convert
