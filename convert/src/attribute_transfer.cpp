// Attribute transfer through the common sphere (Asirvatham, Praun, Hoppe 2005, §5, Fig. 6);
// the design (per-vertex interpolation, per-corner texture coordinates with charts, the
// object-space normal map) is explained in attribute_transfer.h.
#include "spherekit/convert/attribute_transfer.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <utility>

namespace spherekit::convert {
namespace {

Status check_member(const TriMesh& mesh, const RowMat3d& S, const char* who) {
  if (mesh.V.rows() == 0 || mesh.F.rows() == 0) return Status(ErrorCode::InvalidInput, std::string(who) + ": empty mesh");
  if (S.rows() != mesh.V.rows())
    return Status(ErrorCode::InvalidInput, std::string(who) + ": sphere map has " + std::to_string(S.rows()) +
                                               " points for " + std::to_string(mesh.V.rows()) + " vertices");
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.V.rows())
    return Status(ErrorCode::InvalidInput, std::string(who) + ": face index out of range");
  if (!S.allFinite()) return Status(ErrorCode::InvalidInput, std::string(who) + ": non-finite sphere point");
  return Status();
}

/// Every target vertex located in the source map.
Result<std::vector<SphereLocation>> locate_all(const SphereLocator& locator, const RowMat3d& S_to, int* in_holes) {
  std::vector<SphereLocation> out(static_cast<std::size_t>(S_to.rows()));
  *in_holes = 0;
  for (Eigen::Index v = 0; v < S_to.rows(); ++v) {
    SphereLocation loc = locator.locate(S_to.row(v).transpose());
    if (loc.face < 0) return Status(ErrorCode::InvalidInput, "the source sphere map has no usable face");
    *in_holes += !loc.inside;
    out[static_cast<std::size_t>(v)] = loc;
  }
  return out;
}

/// Union-find over faces, for the charts of a texture atlas.
int find_root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

/// Chart id per face: faces are in one chart when they share an edge whose two vertices have
/// the same texture index on both sides. Ids are numbered by first face (deterministic).
std::vector<int> texture_charts(const RowMat3i& F, const RowMat3i& FT, int* count) {
  const auto nf = static_cast<int>(F.rows());
  std::vector<int> parent(static_cast<std::size_t>(nf));
  std::iota(parent.begin(), parent.end(), 0);
  // Undirected edge -> (face, corner) of its first occurrence.
  std::map<std::pair<int, int>, std::pair<int, int>> first;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      auto [it, inserted] = first.emplace(std::minmax(a, b), std::make_pair(f, k));
      if (inserted) continue;
      const auto [g, m] = it->second;
      // Texture indices at a and b in face g (corner m holds F(g, m), m+1 the other end).
      const int ga = F(g, m) == a ? FT(g, m) : FT(g, (m + 1) % 3);
      const int gb = F(g, m) == a ? FT(g, (m + 1) % 3) : FT(g, m);
      if (ga == FT(f, k) && gb == FT(f, (k + 1) % 3)) parent[static_cast<std::size_t>(find_root(parent, f))] = find_root(parent, g);
    }
  }
  std::vector<int> chart(static_cast<std::size_t>(nf), -1), id_of_root(static_cast<std::size_t>(nf), -1);
  int n = 0;
  for (int f = 0; f < nf; ++f) {
    const int r = find_root(parent, f);
    if (id_of_root[static_cast<std::size_t>(r)] < 0) id_of_root[static_cast<std::size_t>(r)] = n++;
    chart[static_cast<std::size_t>(f)] = id_of_root[static_cast<std::size_t>(r)];
  }
  *count = n;
  return chart;
}

std::uint8_t encode_unit(double x) {
  const double c = std::round(127.5 * (std::clamp(x, -1.0, 1.0) + 1.0));
  return static_cast<std::uint8_t>(std::clamp(c, 0.0, 255.0));
}

}  // namespace

Result<AttributeTransferResult> transfer_vertex_attributes(const TriMesh& from, const RowMat3d& S_from,
                                                           const RowMatXd& values, const TriMesh& to,
                                                           const RowMat3d& S_to) {
  SPHEREKIT_RETURN_IF_ERROR(check_member(from, S_from, "source"));
  SPHEREKIT_RETURN_IF_ERROR(check_member(to, S_to, "target"));
  if (values.rows() != from.V.rows() || values.cols() < 1)
    return Status(ErrorCode::InvalidInput, "source values: " + std::to_string(values.rows()) + " rows for " +
                                               std::to_string(from.V.rows()) + " vertices");
  if (!values.allFinite()) return Status(ErrorCode::InvalidInput, "source values: non-finite value");
  const SphereLocator locator(from.F, S_from);
  AttributeTransferResult out;
  SPHEREKIT_ASSIGN_OR_RETURN(const std::vector<SphereLocation> locs, locate_all(locator, S_to, &out.vertices_in_holes));
  out.values.resize(to.V.rows(), values.cols());
  for (Eigen::Index v = 0; v < to.V.rows(); ++v) {
    const SphereLocation& l = locs[static_cast<std::size_t>(v)];
    out.values.row(v) = l.bary(0) * values.row(from.F(l.face, 0)) + l.bary(1) * values.row(from.F(l.face, 1)) +
                        l.bary(2) * values.row(from.F(l.face, 2));
  }
  return out;
}

RowMat3d vertex_normals(const TriMesh& mesh) {
  RowMat3d N = RowMat3d::Zero(mesh.V.rows(), 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::RowVector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a);  // length = twice the area: area weighting
    for (int k = 0; k < 3; ++k) N.row(mesh.F(f, k)) += n;
  }
  for (Eigen::Index v = 0; v < N.rows(); ++v) {
    const double len = N.row(v).norm();
    if (len > 0 && std::isfinite(len)) {
      N.row(v) /= len;
    } else {
      N.row(v) << 0, 0, 1;
    }
  }
  return N;
}

Result<AttributeTransferResult> transfer_vertex_normals(const TriMesh& from, const RowMat3d& S_from,
                                                        const RowMat3d& normals, const TriMesh& to,
                                                        const RowMat3d& S_to, const Eigen::Matrix3d& rotation) {
  SPHEREKIT_ASSIGN_OR_RETURN(AttributeTransferResult out,
                             transfer_vertex_attributes(from, S_from, RowMatXd(normals), to, S_to));
  const SphereLocator fallback_locator(from.F, S_from);
  for (Eigen::Index v = 0; v < out.values.rows(); ++v) {
    Eigen::Vector3d n = rotation * Eigen::Vector3d(out.values.row(v).transpose());
    const double len = n.norm();
    // Opposite normals at one face's corners can cancel (a knife edge); a zero-length
    // interpolant has no direction, so the first corner's normal stands in.
    if (len > 1e-12 && std::isfinite(len)) {
      n /= len;
    } else {
      const SphereLocation l = fallback_locator.locate(S_to.row(v).transpose());
      n = (rotation * normals.row(from.F(l.face, 0)).transpose()).normalized();
    }
    out.values.row(v) = n.transpose();
  }
  return out;
}

Result<UvTransferResult> transfer_texture_coordinates(const TriMesh& from, const RowMat3d& S_from, const RowMat2d& UV,
                                                      const RowMat3i& FT, const TriMesh& to, const RowMat3d& S_to) {
  SPHEREKIT_RETURN_IF_ERROR(check_member(from, S_from, "source"));
  SPHEREKIT_RETURN_IF_ERROR(check_member(to, S_to, "target"));
  if (FT.rows() != from.F.rows())
    return Status(ErrorCode::InvalidInput, "source texture faces: " + std::to_string(FT.rows()) + " for " +
                                               std::to_string(from.F.rows()) + " faces");
  if (UV.rows() == 0 || FT.minCoeff() < 0 || FT.maxCoeff() >= UV.rows())
    return Status(ErrorCode::InvalidInput, "source texture index out of range (" + std::to_string(UV.rows()) +
                                               " texture coordinates)");
  if (!UV.allFinite()) return Status(ErrorCode::InvalidInput, "source texture coordinates: non-finite value");

  UvTransferResult out;
  const std::vector<int> chart = texture_charts(from.F, FT, &out.charts);
  const SphereLocator locator(from.F, S_from);
  SPHEREKIT_ASSIGN_OR_RETURN(const std::vector<SphereLocation> locs, locate_all(locator, S_to, &out.vertices_in_holes));
  auto interpolate = [&](int face, const Eigen::Vector3d& bary) -> Eigen::RowVector2d {
    return bary(0) * UV.row(FT(face, 0)) + bary(1) * UV.row(FT(face, 1)) + bary(2) * UV.row(FT(face, 2));
  };

  // One texture coordinate per target vertex, in the chart of the face that contains it; the
  // extrapolated corners are appended after them.
  std::vector<Eigen::RowVector2d> uv;
  uv.reserve(static_cast<std::size_t>(to.V.rows()));
  for (Eigen::Index v = 0; v < to.V.rows(); ++v) {
    const SphereLocation& l = locs[static_cast<std::size_t>(v)];
    uv.push_back(interpolate(l.face, l.bary));
  }
  out.FT.resize(to.F.rows(), 3);
  for (Eigen::Index f = 0; f < to.F.rows(); ++f) {
    const Eigen::Vector3d centre =
        S_to.row(to.F(f, 0)).transpose() + S_to.row(to.F(f, 1)).transpose() + S_to.row(to.F(f, 2)).transpose();
    // A sphere triangle's vertex sum is never zero for a valid (small, positively oriented)
    // face; a degenerate one falls back to its first corner's chart.
    const int home = centre.norm() > 0 ? locator.locate(centre.normalized()).face : locs[static_cast<std::size_t>(to.F(f, 0))].face;
    bool seam = false;
    for (int k = 0; k < 3; ++k) {
      const int v = to.F(f, k);
      const SphereLocation& l = locs[static_cast<std::size_t>(v)];
      if (home < 0 || chart[static_cast<std::size_t>(l.face)] == chart[static_cast<std::size_t>(home)]) {
        out.FT(f, k) = v;
        continue;
      }
      // Across a seam: extrapolate the home face's coordinates (its gnomonic barycentrics of
      // the corner's sphere point, negative outside the face).
      Eigen::Vector3d bary;
      const Eigen::Vector3d a = S_from.row(from.F(home, 0)), b = S_from.row(from.F(home, 1)), c = S_from.row(from.F(home, 2));
      if (!gnomonic_barycentrics(a, b, c, S_to.row(v).transpose(), bary)) {
        out.FT(f, k) = v;  // the ray misses the plane (a corner a quarter-sphere away): keep the vertex's own
        continue;
      }
      seam = true;
      out.FT(f, k) = static_cast<std::int32_t>(uv.size());
      uv.push_back(interpolate(home, bary));
    }
    out.seam_faces += seam;
  }
  out.UV.resize(static_cast<Eigen::Index>(uv.size()), 2);
  for (std::size_t i = 0; i < uv.size(); ++i) out.UV.row(static_cast<Eigen::Index>(i)) = uv[i];
  return out;
}

Result<Image8> bake_normal_map(const GeometryImage& image, const Eigen::Matrix3d& rotation) {
  const auto n = static_cast<std::size_t>(image.size);
  if (!is_geometry_image_size(image.size) || image.normals.size() != 3 * n * n)
    return Status(ErrorCode::InvalidArgument, "malformed geometry image (size " + std::to_string(image.size) + ")");
  Image8 out = Image8::filled(image.size, image.size, {0, 0, 0});
  for (int i = 0; i < image.size; ++i) {
    for (int j = 0; j < image.size; ++j) {
      Eigen::Vector3d nrm = rotation * image.normal(i, j).cast<double>();
      const double len = nrm.norm();
      nrm = len > 0 && std::isfinite(len) ? Eigen::Vector3d(nrm / len) : Eigen::Vector3d(0, 0, 1);
      std::uint8_t* p = out.at(j, i);
      for (int k = 0; k < 3; ++k) p[k] = encode_unit(nrm(k));
    }
  }
  return out;
}

Eigen::Vector3d decode_normal_pixel(const std::uint8_t* rgb) {
  Eigen::Vector3d n(rgb[0] / 127.5 - 1.0, rgb[1] / 127.5 - 1.0, rgb[2] / 127.5 - 1.0);
  const double len = n.norm();
  return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d(0, 0, 1);
}

}  // namespace spherekit::convert
