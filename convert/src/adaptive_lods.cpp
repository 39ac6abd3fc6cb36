// Adaptive levels of detail by one n-D quadric simplification of the geometry-image remesh
// (see adaptive_lods.h). References: Garland & Heckbert 1998 (n-D quadrics); Hoppe 1996
// (half-edge collapses, replayed here up to each level's vertex count); Asirvatham, Praun &
// Hoppe 2005 §3 (the R^3n mesh of a consistent collection).
#include "spherekit/convert/adaptive_lods.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Cholesky>

#include "lod_constraints.h"
#include "spherekit/progressive_mesh.h"

namespace spherekit::convert {
namespace {

// The folded border of the octahedral square as simplifier path edges (welded vertex ids):
// consecutive texels along one side of the square. Each welded edge appears twice (once per
// side of the fold); duplicates are removed.
std::vector<std::array<int, 2>> seam_edges(int n, const std::vector<int>& welded) {
  std::vector<std::array<int, 2>> edges;
  auto add = [&](int i0, int j0, int i1, int j1) {
    int a = welded[static_cast<std::size_t>(i0) * n + j0], b = welded[static_cast<std::size_t>(i1) * n + j1];
    if (a == b) return;
    edges.push_back({std::min(a, b), std::max(a, b)});
  };
  for (int s = 0; s + 1 < n; ++s) {
    add(0, s, 0, s + 1);
    add(n - 1, s, n - 1, s + 1);
    add(s, 0, s + 1, 0);
    add(s, n - 1, s + 1, n - 1);
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

// Per face corner, the copy (texel) of each corner's vertex that makes the face's triangle in
// the texel grid smallest (perimeter): faces never span the fold, so the right copies are
// neighbours in the square and any other choice reaches across it. Ties: the first candidate
// in texel order (deterministic).
std::array<int, 3> face_texels(const std::array<int, 3>& v, const std::vector<std::vector<int>>& copies, int n) {
  const auto& c0 = copies[static_cast<std::size_t>(v[0])];
  const auto& c1 = copies[static_cast<std::size_t>(v[1])];
  const auto& c2 = copies[static_cast<std::size_t>(v[2])];
  if (c0.size() == 1 && c1.size() == 1 && c2.size() == 1) return {c0[0], c1[0], c2[0]};
  auto dist = [n](int a, int b) {
    const double di = a / n - b / n, dj = a % n - b % n;
    return std::sqrt(di * di + dj * dj);
  };
  std::array<int, 3> best{c0[0], c1[0], c2[0]};
  double best_len = std::numeric_limits<double>::infinity();
  for (int a : c0)
    for (int b : c1)
      for (int c : c2) {
        const double len = dist(a, b) + dist(b, c) + dist(c, a);
        if (len < best_len) {
          best_len = len;
          best = {a, b, c};
        }
      }
  return best;
}

// Garland & Heckbert 1997's plane quadric of one 3D model: Q(x) = x'Ax + 2b'x + c, the
// area-weighted squared distance of x to the planes summed into it.
struct PlaneQuadric {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  void add_face(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2, double weight) {
    Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
    const double twice_area = n.norm();
    if (!(twice_area > 0)) return;
    n /= twice_area;
    const double w = weight * 0.5 * twice_area;
    const double d = -n.dot(p0);
    A += w * n * n.transpose();
    b += w * d * n;
  }
  void add(const PlaneQuadric& q) {
    A += q.A;
    b += q.b;
  }
};

// Each level vertex of each member at the minimum of its cluster's plane quadric (the fine
// vertices that collapsed into it, each with a third of its faces' planes): a coarse surface
// through samples of the fine one lies inside it wherever it is convex and outside where
// concave; the quadric's minimum moves the vertex to straddle the fine surface, so both
// directions of the surface distance shrink (Garland & Heckbert 1997 §5; the peers'
// simplifiers keep input vertices). Regularized towards the texel sample (a flat cluster's
// quadric has no unique minimum), and a vertex whose minimum lies farther from its sample
// than the cluster's own extent keeps the sample (a degenerate or folded cluster).
void fit_level_positions(const RowMatXd& P, const RowMat3i& F, const std::vector<std::uint8_t>& hole_faces,
                         const CollapseReplay& replay, int nm, RowMatXd* fitted) {
  const int nv = static_cast<int>(P.rows());
  *fitted = P;
  for (int m = 0; m < nm; ++m) {
    std::vector<PlaneQuadric> q(static_cast<std::size_t>(nv));
    std::vector<double> extent(static_cast<std::size_t>(nv), 0.0);
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      if (!hole_faces.empty() && hole_faces[static_cast<std::size_t>(f)]) continue;
      const Eigen::Vector3d p0 = P.row(F(f, 0)).segment<3>(3 * m).transpose();
      const Eigen::Vector3d p1 = P.row(F(f, 1)).segment<3>(3 * m).transpose();
      const Eigen::Vector3d p2 = P.row(F(f, 2)).segment<3>(3 * m).transpose();
      PlaneQuadric face;
      face.add_face(p0, p1, p2, 1.0 / 3.0);
      for (int k = 0; k < 3; ++k) q[static_cast<std::size_t>(replay.find(F(f, k)))].add(face);
    }
    for (int v = 0; v < nv; ++v) {
      const int c = replay.find(v);
      const double dist = (P.row(v).segment<3>(3 * m) - P.row(c).segment<3>(3 * m)).norm();
      extent[static_cast<std::size_t>(c)] = std::max(extent[static_cast<std::size_t>(c)], dist);
    }
    for (int c = 0; c < nv; ++c) {
      if (replay.find(c) != c) continue;
      const PlaneQuadric& qc = q[static_cast<std::size_t>(c)];
      const double tr = qc.A.trace();
      if (!(tr > 0) || !(extent[static_cast<std::size_t>(c)] > 0)) continue;
      const Eigen::Vector3d x0 = P.row(c).segment<3>(3 * m).transpose();
      const double lambda = 1e-3 * tr;
      const Eigen::Matrix3d A = qc.A + lambda * Eigen::Matrix3d::Identity();
      const Eigen::Vector3d x = A.ldlt().solve(lambda * x0 - qc.b);
      if (!x.allFinite() || (x - x0).norm() > extent[static_cast<std::size_t>(c)]) continue;
      fitted->row(c).segment<3>(3 * m) = x.transpose();
    }
  }
}

Status check_members(const std::vector<GeometryImage>& members, const AdaptiveLodOptions& options) {
  if (members.empty()) return Status(ErrorCode::InvalidArgument, "adaptive levels of detail: no member");
  const int n = members[0].size;
  for (std::size_t m = 0; m < members.size(); ++m) {
    const GeometryImage& g = members[m];
    const auto texels = static_cast<std::size_t>(g.size) * static_cast<std::size_t>(g.size);
    if (g.size != n || !is_geometry_image_size(n) || g.positions.size() != 3 * texels || g.normals.size() != 3 * texels)
      return Status(ErrorCode::InvalidArgument,
                    "adaptive levels of detail: member " + std::to_string(m) + " is not a " + std::to_string(n) +
                        " x " + std::to_string(n) + " geometry image");
  }
  if (options.levels < 1 || options.levels > 16)
    return Status(ErrorCode::InvalidArgument, "adaptive levels of detail: levels must be in 1..16");
  if (options.lod0_max_vertices < 0)
    return Status(ErrorCode::InvalidArgument, "adaptive levels of detail: lod0 vertex cap must be >= 0");
  if (!(options.lod0_vertex_fraction > 0 && options.lod0_vertex_fraction <= 1))
    return Status(ErrorCode::InvalidArgument, "adaptive levels of detail: lod0 vertex fraction must be in (0, 1]");
  return Status();
}

}  // namespace

Result<std::vector<std::vector<GltfMesh>>> adaptive_lod_meshes(const std::vector<GeometryImage>& members,
                                                              const AdaptiveLodOptions& options,
                                                              const ProgressFn& progress) {
  SPHEREKIT_RETURN_IF_ERROR(check_members(members, options));
  const int n = members[0].size;
  const auto nm = static_cast<int>(members.size());
  int nv = 0;
  const std::vector<int> welded = geometry_image_welded_ids(n, &nv);
  std::vector<std::vector<int>> copies(static_cast<std::size_t>(nv));  // texels of each vertex, ascending
  for (std::size_t t = 0; t < welded.size(); ++t) copies[static_cast<std::size_t>(welded[t])].push_back(static_cast<int>(t));

  // The R^3n remesh: vertex v = every member's position of its texel (fold copies are equal).
  RowMatXd P(nv, 3 * nm);
  for (int v = 0; v < nv; ++v) {
    const std::size_t t = static_cast<std::size_t>(copies[static_cast<std::size_t>(v)][0]);
    for (int m = 0; m < nm; ++m)
      for (int c = 0; c < 3; ++c) P(v, 3 * m + c) = members[static_cast<std::size_t>(m)].positions[3 * t + c];
  }
  const RowMat3i grid = geometry_image_grid_faces(n);
  RowMat3i F(grid.rows(), 3);
  for (Eigen::Index f = 0; f < grid.rows(); ++f)
    for (int k = 0; k < 3; ++k) F(f, k) = welded[static_cast<std::size_t>(grid(f, k))];

  ProgressiveMeshOptions pm_options;
  pm_options.constraint_edges = seam_edges(n, welded);
  pm_options.degenerate_faces_free = true;  // hole texels sit on the rim (progressive_mesh.h)
  // A level's error is each member's own surface error (progressive_mesh.h, model_planes).
  pm_options.model_planes = true;
  std::vector<std::uint8_t> hole_faces;
  if (options.drop_hole_faces) hole_faces = geometry_image_hole_faces(members[0]);
  if (!hole_faces.empty()) {
    detail::add_rim_edges(F, hole_faces, pm_options.constraint_edges);
    // The faces spanning holes are left out, so their shape must not steer the surface's.
    pm_options.face_weights.assign(hole_faces.size(), 1.0);
    for (std::size_t f = 0; f < hole_faces.size(); ++f)
      if (hole_faces[f]) pm_options.face_weights[f] = 1e-3;
  }
  // Fold ends (one seam edge) and the corner vertex (four) never move (progressive_mesh.h).
  std::vector<int> on_seam(static_cast<std::size_t>(nv), 0);
  for (const auto& e : pm_options.constraint_edges) {
    ++on_seam[static_cast<std::size_t>(e[0])];
    ++on_seam[static_cast<std::size_t>(e[1])];
  }
  pm_options.keep_vertices.assign(static_cast<std::size_t>(nv), 0);
  for (int v = 0; v < nv; ++v)
    pm_options.keep_vertices[static_cast<std::size_t>(v)] =
        on_seam[static_cast<std::size_t>(v)] == 1 || on_seam[static_cast<std::size_t>(v)] > 2;
  std::vector<int> targets;
  double lod0 = nv * options.lod0_vertex_fraction;
  if (options.lod0_max_vertices > 0) lod0 = std::min(lod0, static_cast<double>(options.lod0_max_vertices));
  for (int k = 0; k < options.levels; ++k)
    targets.push_back(std::max(6, static_cast<int>(std::lround(lod0 / std::pow(4.0, static_cast<double>(k))))));
  pm_options.target_vertices = std::min(nv, targets.back());
  SPHEREKIT_ASSIGN_OR_RETURN(ProgressiveMesh pm, build_progressive_mesh(P, F, pm_options, progress));

  // Replay the collapses up to each level's vertex count.
  CollapseReplay replay(pm);
  std::vector<std::vector<GltfMesh>> out;
  for (int k = 0; k < options.levels; ++k) {
    const std::size_t want = static_cast<std::size_t>(std::max(0, nv - targets[static_cast<std::size_t>(k)]));
    replay.advance_to(want);
    RowMatXd level_positions;
    if (options.fit_positions) fit_level_positions(P, F, hole_faces, replay, nm, &level_positions);
    // Faces in input order, corners as texels; points = texels used, ascending.
    std::vector<std::array<int, 3>> faces;
    std::vector<char> used(welded.size(), 0);
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      if (!replay.alive(static_cast<int>(f))) continue;
      if (!hole_faces.empty() && hole_faces[static_cast<std::size_t>(f)]) continue;
      const std::array<int, 3> v{replay.find(F(f, 0)), replay.find(F(f, 1)), replay.find(F(f, 2))};
      const std::array<int, 3> t = face_texels(v, copies, n);
      for (int x : t) used[static_cast<std::size_t>(x)] = 1;
      faces.push_back(t);
    }
    std::vector<int> point_of(welded.size(), -1), texel_of;
    std::vector<int> vertex_rank(static_cast<std::size_t>(nv), -1);
    int vertices = 0;
    for (std::size_t t = 0; t < welded.size(); ++t) {
      if (!used[t]) continue;
      point_of[t] = static_cast<int>(texel_of.size());
      texel_of.push_back(static_cast<int>(t));
    }
    GltfMesh shape;
    shape.texture_size = n;
    shape.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t f = 0; f < faces.size(); ++f)
      for (int c = 0; c < 3; ++c) shape.F(static_cast<Eigen::Index>(f), c) = point_of[static_cast<std::size_t>(faces[f][c])];
    const auto np = static_cast<Eigen::Index>(texel_of.size());
    shape.UV.resize(np, 2);
    for (Eigen::Index p = 0; p < np; ++p) {
      const int t = texel_of[static_cast<std::size_t>(p)];
      shape.UV(p, 0) = (static_cast<double>(t % n) + 0.5) / n;
      shape.UV(p, 1) = (static_cast<double>(t / n) + 0.5) / n;
      int& r = vertex_rank[static_cast<std::size_t>(welded[static_cast<std::size_t>(t)])];
      if (r < 0) r = vertices++;
      shape.position_index.push_back(r);
    }
    std::vector<GltfMesh> level;
    for (int m = 0; m < nm; ++m) {
      const GeometryImage& g = members[static_cast<std::size_t>(m)];
      GltfMesh mesh = shape;
      mesh.V.resize(np, 3);
      mesh.N.resize(np, 3);
      for (Eigen::Index p = 0; p < np; ++p) {
        const std::size_t t = static_cast<std::size_t>(texel_of[static_cast<std::size_t>(p)]);
        if (options.fit_positions) {
          const int v = welded[t];
          for (int c = 0; c < 3; ++c) mesh.V(p, c) = level_positions(v, 3 * m + c);
        } else {
          for (int c = 0; c < 3; ++c) mesh.V(p, c) = g.positions[3 * t + c];
        }
        Eigen::Vector3d nrm(g.normals[3 * t], g.normals[3 * t + 1], g.normals[3 * t + 2]);
        const double len = nrm.norm();
        // As gltf_mesh_from_geometry_image: glTF NORMALs must be unit vectors.
        nrm = len > 0 ? Eigen::Vector3d(nrm / len) : Eigen::Vector3d(0, 0, 1);
        mesh.N.row(p) = nrm.transpose();
      }
      level.push_back(std::move(mesh));
    }
    out.push_back(std::move(level));
  }
  return out;
}

}  // namespace spherekit::convert
