// Levels of detail by quadric simplification of the original mesh with octahedral texture
// coordinates (see original_lods.h). References: Garland & Heckbert 1997 (quadrics); Hoppe
// 1996 (half-edge collapses); Praun & Hoppe 2003 (the octahedral domain and its fold).
#include "spherekit/convert/original_lods.h"

#include "lod_constraints.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include "spherekit/fill_holes.h"
#include "spherekit/geometry_image.h"
#include "spherekit/progressive_mesh.h"

namespace spherekit::convert {
namespace {

int sign3(double x) { return x > 0 ? 1 : (x < 0 ? -1 : 0); }

// The mesh while it is cut: vertices (positions, sphere points), faces, hole flags.
struct Cutter {
  std::vector<Eigen::Vector3d> V, S;
  std::vector<std::array<int, 3>> F;
  std::vector<std::uint8_t> hole;
  std::vector<FoldCutMesh::EdgePoint> edge_points;  // per vertex made by a split

  // Splits every edge whose sphere chord strictly crosses the plane `axis` = 0 (and, if
  // on_plane >= 0, lies in the plane on_plane = 0), then re-triangulates the faces.
  void split(int axis, int on_plane) {
    std::map<std::pair<int, int>, int> cut;
    auto crossing = [&](int a, int b) {
      if (sign3(S[a][axis]) * sign3(S[b][axis]) >= 0) return false;
      return on_plane < 0 || (S[a][on_plane] == 0 && S[b][on_plane] == 0);
    };
    auto mid = [&](int a, int b) -> int {
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      auto it = cut.find(key);
      if (it != cut.end()) return it->second;
      const int p = key.first, q = key.second;  // the same arithmetic from both faces
      const double t = S[p][axis] / (S[p][axis] - S[q][axis]);
      Eigen::Vector3d s = S[p] + t * (S[q] - S[p]);
      s[axis] = 0;
      s.normalize();
      V.push_back(V[p] + t * (V[q] - V[p]));
      S.push_back(s);
      edge_points.push_back({p, q, t});
      const int id = static_cast<int>(V.size()) - 1;
      cut.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> out;
    std::vector<std::uint8_t> out_hole;
    out.reserve(F.size() + F.size() / 8);
    auto emit = [&](int a, int b, int c, std::uint8_t h) {
      out.push_back({a, b, c});
      out_hole.push_back(h);
    };
    for (std::size_t f = 0; f < F.size(); ++f) {
      const auto& t = F[f];
      std::array<int, 3> m{-1, -1, -1};  // m[k]: cut vertex on edge (t[k], t[k+1])
      int cuts = 0;
      for (int k = 0; k < 3; ++k)
        if (crossing(t[k], t[(k + 1) % 3])) {
          m[k] = mid(t[k], t[(k + 1) % 3]);
          ++cuts;
        }
      const std::uint8_t h = hole[f];
      if (cuts == 0) {
        emit(t[0], t[1], t[2], h);
      } else if (cuts == 1) {
        int k = 0;
        while (m[k] < 0) ++k;
        const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        emit(a, m[k], c, h);
        emit(m[k], b, c, h);
      } else if (cuts == 2) {
        int k = 0;  // the uncut edge is (t[k+2], t[k]): cuts on (a, b) and (b, c)
        while (!(m[k] >= 0 && m[(k + 1) % 3] >= 0)) ++k;
        const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        const int mab = m[k], mbc = m[(k + 1) % 3];
        emit(mab, b, mbc, h);
        // The quad (a, mab, mbc, c) along its shorter diagonal.
        if ((V[a] - V[mbc]).squaredNorm() <= (V[mab] - V[c]).squaredNorm()) {
          emit(a, mab, mbc, h);
          emit(a, mbc, c, h);
        } else {
          emit(a, mab, c, h);
          emit(mab, mbc, c, h);
        }
      } else {
        emit(t[0], m[0], m[2], h);
        emit(m[0], t[1], m[1], h);
        emit(m[2], m[1], t[2], h);
        emit(m[0], m[1], m[2], h);
      }
    }
    F = std::move(out);
    hole = std::move(out_hole);
  }
};

// Fold edges (both ends on x = 0 or both on y = 0, in the lower hemisphere) and the rim
// between hole faces and the others, as sorted unique (min, max) pairs.
std::vector<std::array<int, 2>> constraint_edges(const FoldCutMesh& cut) {
  std::vector<std::array<int, 2>> edges;
  const RowMat3i& F = cut.mesh.F;
  const RowMat3d& S = cut.S;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      const bool on_x = S(a, 0) == 0 && S(b, 0) == 0, on_y = S(a, 1) == 0 && S(b, 1) == 0;
      const bool lower = S(a, 2) <= 0 && S(b, 2) <= 0 && !(S(a, 2) == 0 && S(b, 2) == 0);
      if ((on_x || on_y) && lower) edges.push_back({std::min(a, b), std::max(a, b)});
    }
  detail::add_rim_edges(F, cut.hole_faces, edges);  // sorts and removes duplicates
  return edges;
}

}  // namespace

std::vector<Eigen::Vector2d> octahedral_copies(const Eigen::Vector3d& s) {
  const double l1 = std::abs(s.x()) + std::abs(s.y()) + std::abs(s.z());
  if (!(l1 > 0)) return {Eigen::Vector2d(0, 0)};
  const Eigen::Vector3d q = s / l1;
  if (q.z() >= 0) return {Eigen::Vector2d(q.x(), q.y())};
  std::vector<Eigen::Vector2d> out;
  const std::vector<double> sx = q.x() == 0 ? std::vector<double>{-1, 1} : std::vector<double>{q.x() > 0 ? 1.0 : -1.0};
  const std::vector<double> sy = q.y() == 0 ? std::vector<double>{-1, 1} : std::vector<double>{q.y() > 0 ? 1.0 : -1.0};
  for (double a : sx)
    for (double b : sy) out.emplace_back((1.0 - std::abs(q.y())) * a, (1.0 - std::abs(q.x())) * b);
  return out;
}

Eigen::Vector2d octahedral_to_texcoord(const Eigen::Vector2d& uv, int texture_size) {
  const double T = texture_size;
  const double j = (uv.x() + 1) * (T - 1) / 2, i = (uv.y() + 1) * (T - 1) / 2;
  return {(j + 0.5) / T, (i + 0.5) / T};
}

Result<FoldCutMesh> cut_along_octahedral_fold(const TriMesh& mesh, const RowMat3d& S) {
  if (S.rows() != mesh.V.rows())
    return Status(ErrorCode::InvalidInput, "sphere map has " + std::to_string(S.rows()) + " points for " +
                                               std::to_string(mesh.V.rows()) + " vertices");
  for (Eigen::Index v = 0; v < S.rows(); ++v)
    if (!(S.row(v).norm() > 0) || !S.row(v).allFinite())
      return Status(ErrorCode::InvalidInput, "sphere point " + std::to_string(v) + " is zero or not finite");
  SPHEREKIT_ASSIGN_OR_RETURN(FilledMesh filled, fill_holes(mesh));
  Cutter c;
  const Eigen::Index nv = filled.mesh.V.rows();
  for (Eigen::Index v = 0; v < nv; ++v) {
    c.V.push_back(filled.mesh.V.row(v).transpose());
    if (v < S.rows()) c.S.push_back(S.row(v).transpose().normalized());
    else c.S.emplace_back(Eigen::Vector3d::Zero());
  }
  for (std::size_t h = 0; h < filled.loops.size(); ++h) {
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int v : filled.loops[h]) s += c.S[static_cast<std::size_t>(v)];
    if (!(s.norm() > 0)) s = c.S[static_cast<std::size_t>(filled.loops[h][0])];
    c.S[static_cast<std::size_t>(filled.original_vertices) + h] = s.normalized();
  }
  for (Eigen::Index f = 0; f < filled.mesh.F.rows(); ++f) {
    c.F.push_back({filled.mesh.F(f, 0), filled.mesh.F(f, 1), filled.mesh.F(f, 2)});
    c.hole.push_back(filled.is_hole_face(static_cast<int>(f)) ? 1 : 0);
  }
  c.split(0, -1);  // x = 0
  c.split(1, -1);  // y = 0 (makes the poles vertices on the x = 0 cut)
  c.split(2, 0);   // the x = 0 cut at z = 0: the fold ends (0, +-1, 0)
  c.split(2, 1);   // the y = 0 cut at z = 0: (+-1, 0, 0)
  FoldCutMesh out;
  out.original_vertices = static_cast<int>(mesh.V.rows());
  out.mesh.V.resize(static_cast<Eigen::Index>(c.V.size()), 3);
  out.S.resize(static_cast<Eigen::Index>(c.S.size()), 3);
  for (std::size_t v = 0; v < c.V.size(); ++v) {
    out.mesh.V.row(static_cast<Eigen::Index>(v)) = c.V[v].transpose();
    out.S.row(static_cast<Eigen::Index>(v)) = c.S[v].transpose();
  }
  out.mesh.F.resize(static_cast<Eigen::Index>(c.F.size()), 3);
  for (std::size_t f = 0; f < c.F.size(); ++f)
    for (int k = 0; k < 3; ++k) out.mesh.F(static_cast<Eigen::Index>(f), k) = c.F[f][static_cast<std::size_t>(k)];
  out.hole_faces = std::move(c.hole);
  out.edge_points = std::move(c.edge_points);
  return out;
}

Result<std::vector<GltfMesh>> original_lod_meshes(const TriMesh& mesh, const RowMat3d& S,
                                                  const OriginalLodOptions& options, const ProgressFn& progress) {
  SPHEREKIT_RETURN_IF_ERROR(check_original_lod_options(options));
  SPHEREKIT_ASSIGN_OR_RETURN(FoldCutMesh cut, cut_along_octahedral_fold(mesh, S));
  SPHEREKIT_ASSIGN_OR_RETURN(auto levels, fold_cut_lod_meshes(cut, cut.mesh.V, options, progress));
  std::vector<GltfMesh> out;
  for (auto& level : levels) out.push_back(std::move(level[0]));
  return out;
}

Status check_original_lod_options(const OriginalLodOptions& options) {
  if (options.levels < 1 || options.levels > 16)
    return Status(ErrorCode::InvalidArgument, "original-mesh levels of detail: levels must be in 1..16");
  if (!is_geometry_image_size(options.texture_size))
    return Status(ErrorCode::InvalidArgument, "original-mesh levels of detail: texture size must be 2^k+1");
  if (options.lod0_max_vertices < 0)
    return Status(ErrorCode::InvalidArgument, "original-mesh levels of detail: lod0 vertex cap must be >= 0");
  return Status();
}

Result<std::vector<std::vector<GltfMesh>>> fold_cut_lod_meshes(const FoldCutMesh& cut, const RowMatXd& P,
                                                               const OriginalLodOptions& options,
                                                               const ProgressFn& progress) {
  SPHEREKIT_RETURN_IF_ERROR(check_original_lod_options(options));
  const auto nv = static_cast<int>(cut.mesh.V.rows());
  const RowMat3i& F = cut.mesh.F;
  if (P.rows() != nv || P.cols() < 3 || P.cols() % 3 != 0 || !P.allFinite())
    return Status(ErrorCode::InvalidArgument, "original-mesh levels of detail: positions must be finite, one row of 3n per vertex");
  const auto nm = static_cast<int>(P.cols() / 3);

  ProgressiveMeshOptions pm_options;
  pm_options.constraint_edges = constraint_edges(cut);
  // Memoryless quadrics (the distances to the current level's planes) and a light edge-length
  // tie-break: the bunny's levels 1-3 are 3.6/3.9/2.0 dB better than with accumulated quadrics
  // and the remesh's tie-break 0.01, at the same vertex counts (eval-surface of the files).
  // With several members, each member's distance to its own planes, summed (model_planes in
  // progressive_mesh.h: the 2-plane in R^3n also charges the members' tangential
  // disagreement, which is no error of a level).
  pm_options.memoryless = true;
  pm_options.model_planes = true;
  pm_options.edge_length_weight = 0.001;
  pm_options.degenerate_faces_free = true;  // the cut leaves slivers where it passes near a vertex
  pm_options.face_weights.assign(cut.hole_faces.size(), 1.0);
  for (std::size_t f = 0; f < cut.hole_faces.size(); ++f)
    if (cut.hole_faces[f]) pm_options.face_weights[f] = 1e-3;
  std::vector<int> on_path(static_cast<std::size_t>(nv), 0);
  for (const auto& e : pm_options.constraint_edges) {
    ++on_path[static_cast<std::size_t>(e[0])];
    ++on_path[static_cast<std::size_t>(e[1])];
  }
  pm_options.keep_vertices.assign(static_cast<std::size_t>(nv), 0);
  int kept = 0;
  for (int v = 0; v < nv; ++v) {
    const int p = on_path[static_cast<std::size_t>(v)];
    pm_options.keep_vertices[static_cast<std::size_t>(v)] = p == 1 || p > 2;
    kept += p == 1 || p > 2;
  }
  double lod0 = static_cast<double>(cut.original_vertices);
  if (options.lod0_max_vertices > 0) lod0 = std::min(lod0, static_cast<double>(options.lod0_max_vertices));
  std::vector<int> targets;
  for (int k = 0; k < options.levels; ++k)
    targets.push_back(std::min(nv, std::max(kept + 8, static_cast<int>(std::lround(lod0 / std::pow(4.0, k))))));
  pm_options.target_vertices = targets.back();
  SPHEREKIT_ASSIGN_OR_RETURN(ProgressiveMesh pm, build_progressive_mesh(P, F, pm_options, progress));

  std::vector<std::vector<Eigen::Vector2d>> copies(static_cast<std::size_t>(nv));
  for (int v = 0; v < nv; ++v) copies[static_cast<std::size_t>(v)] = octahedral_copies(cut.S.row(v).transpose());

  CollapseReplay replay(pm);
  std::vector<std::vector<GltfMesh>> out;
  for (int k = 0; k < options.levels; ++k) {
    const std::size_t want = static_cast<std::size_t>(std::max(0, nv - targets[static_cast<std::size_t>(k)]));
    replay.advance_to(want);
    // Per face, the corners' copies making its texture triangle smallest (perimeter; ties:
    // the first in copy order).
    std::vector<std::array<std::pair<int, int>, 3>> faces;  // (vertex, copy) per corner
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      if (!replay.alive(static_cast<int>(f)) || cut.hole_faces[static_cast<std::size_t>(f)]) continue;
      const std::array<int, 3> v{replay.find(F(f, 0)), replay.find(F(f, 1)), replay.find(F(f, 2))};
      const auto& c0 = copies[static_cast<std::size_t>(v[0])];
      const auto& c1 = copies[static_cast<std::size_t>(v[1])];
      const auto& c2 = copies[static_cast<std::size_t>(v[2])];
      std::array<int, 3> best{0, 0, 0};
      if (c0.size() > 1 || c1.size() > 1 || c2.size() > 1) {
        double best_len = std::numeric_limits<double>::infinity();
        for (std::size_t a = 0; a < c0.size(); ++a)
          for (std::size_t b = 0; b < c1.size(); ++b)
            for (std::size_t c = 0; c < c2.size(); ++c) {
              const double len = (c0[a] - c1[b]).norm() + (c1[b] - c2[c]).norm() + (c2[c] - c0[a]).norm();
              if (len < best_len) {
                best_len = len;
                best = {static_cast<int>(a), static_cast<int>(b), static_cast<int>(c)};
              }
            }
      }
      faces.push_back({std::make_pair(v[0], best[0]), std::make_pair(v[1], best[1]), std::make_pair(v[2], best[2])});
    }
    // Points = used (vertex, copy) pairs in ascending order: the same for every member.
    std::map<std::pair<int, int>, int> point_of;
    for (const auto& t : faces)
      for (const auto& p : t) point_of.emplace(p, 0);
    GltfMesh shape;
    const auto np = static_cast<Eigen::Index>(point_of.size());
    shape.UV.resize(np, 2);
    std::vector<int> vertex_rank(static_cast<std::size_t>(nv), -1), vertex_of;
    int vertices = 0;
    Eigen::Index p = 0;
    for (auto& [key, id] : point_of) {
      id = static_cast<int>(p);
      vertex_of.push_back(key.first);
      shape.UV.row(p) =
          octahedral_to_texcoord(copies[static_cast<std::size_t>(key.first)][static_cast<std::size_t>(key.second)],
                                 options.texture_size)
              .transpose();
      int& r = vertex_rank[static_cast<std::size_t>(key.first)];
      if (r < 0) r = vertices++;
      shape.position_index.push_back(r);
      ++p;
    }
    shape.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t f = 0; f < faces.size(); ++f)
      for (int c = 0; c < 3; ++c) shape.F(static_cast<Eigen::Index>(f), c) = point_of[faces[f][static_cast<std::size_t>(c)]];
    std::vector<GltfMesh> level;
    for (int m = 0; m < nm; ++m) {
      GltfMesh mesh = shape;
      mesh.V.resize(np, 3);
      mesh.N = RowMat3d::Zero(np, 3);
      auto pos = [&](int v) -> Eigen::Vector3d { return P.row(v).segment<3>(3 * m).transpose(); };
      for (Eigen::Index q = 0; q < np; ++q) mesh.V.row(q) = pos(vertex_of[static_cast<std::size_t>(q)]).transpose();
      // Area-weighted vertex normals of the member's level (shared by a vertex's copies).
      std::vector<Eigen::Vector3d> vn(static_cast<std::size_t>(nv), Eigen::Vector3d::Zero());
      for (const auto& t : faces) {
        const int a = t[0].first, b = t[1].first, c = t[2].first;
        const Eigen::Vector3d n = (pos(b) - pos(a)).cross(pos(c) - pos(a));
        for (int x : {a, b, c}) vn[static_cast<std::size_t>(x)] += n;
      }
      for (Eigen::Index q = 0; q < np; ++q) {
        const Eigen::Vector3d n = vn[static_cast<std::size_t>(vertex_of[static_cast<std::size_t>(q)])];
        const double len = n.norm();
        mesh.N.row(q) = (len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d(0, 0, 1)).transpose();
      }
      level.push_back(std::move(mesh));
    }
    out.push_back(std::move(level));
  }
  return out;
}

}  // namespace spherekit::convert
