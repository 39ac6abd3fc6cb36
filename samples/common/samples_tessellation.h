// Internal to the sample collection: triangulations of the unit sphere (the template
// domain) with different connectivity, and an editor that adapts one to a surface
// X: S^2 -> R^3 by edge bisection, edge flips and vertex smoothing while every template
// triangle stays positively oriented on the sphere (so the template triangulation stays
// a valid tiling of S^2 and ground-truth lookups by gnomonic barycentrics stay well
// defined).
//
// Everything is deterministic: randomness comes from the portable Rng below (not from
// <random> distributions, whose output differs between standard libraries), and no
// result depends on the iteration order of a hash map.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <queue>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace spherekit::samples::detail {

using Vec3 = Eigen::Vector3d;
using Tri = std::array<int, 3>;

/// SplitMix64: tiny, portable, and good enough for shape and meshing jitter.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

 private:
  std::uint64_t state_;
};

/// det[a b c]: positive when the spherical triangle (a, b, c) is counter-clockwise seen
/// from outside; for unit vectors about twice its area when small.
inline double sphere_orient(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); }

/// Template triangles thinner than this (in det[a b c]) are refused by edits. Rounding
/// error of the determinant of unit vectors is ~1e-16, so 1e-13 is a safe strict sign
/// test while still allowing the smallest triangles adaptive refinement makes (~1e-6).
inline constexpr double kMinTemplateOrient = 1e-13;

struct SphereTriangulation {
  std::vector<Vec3> U;  ///< unit vectors
  std::vector<Tri> F;   ///< counter-clockwise seen from outside
};

inline std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

/// Icosahedron with every triangle split into four `level` times, vertices projected.
inline SphereTriangulation icosphere(int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  SphereTriangulation s;
  s.U = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& u : s.U) u.normalize();
  s.F = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::unordered_map<std::uint64_t, int> midpoint;  // only looked up, never iterated
    auto mid = [&](int a, int b) {
      const auto key = edge_key(std::min(a, b), std::max(a, b));
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      s.U.push_back((s.U[a] + s.U[b]).normalized());
      return midpoint[key] = static_cast<int>(s.U.size()) - 1;
    };
    std::vector<Tri> finer;
    finer.reserve(4 * s.F.size());
    for (const Tri& f : s.F) {
      const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      finer.push_back({f[0], ab, ca});
      finer.push_back({f[1], bc, ab});
      finer.push_back({f[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    s.F = std::move(finer);
  }
  return s;
}

/// Cube with each face an n x n grid, projected to the sphere with the equal-angle map
/// (tan) so cells have similar sizes; each quad is split along its shorter diagonal.
inline SphereTriangulation cube_sphere(int n) {
  SphereTriangulation s;
  const int m = n + 1;
  std::vector<int> id(static_cast<size_t>(m) * m * m, -1);
  auto vertex = [&](int i, int j, int k) {
    int& v = id[(static_cast<size_t>(i) * m + j) * m + k];
    if (v < 0) {
      auto coord = [&](int c) { return std::tan(M_PI / 4 * (2.0 * c / n - 1.0)); };
      s.U.push_back(Vec3(coord(i), coord(j), coord(k)).normalized());
      v = static_cast<int>(s.U.size()) - 1;
    }
    return v;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {0, n}) {
      for (int p = 0; p < n; ++p) {
        for (int q = 0; q < n; ++q) {
          std::array<int, 4> quad;
          const int pq[4][2] = {{p, q}, {p + 1, q}, {p + 1, q + 1}, {p, q + 1}};
          for (int c = 0; c < 4; ++c) {
            int ijk[3];
            ijk[axis] = side;
            ijk[(axis + 1) % 3] = pq[c][0];
            ijk[(axis + 2) % 3] = pq[c][1];
            quad[c] = vertex(ijk[0], ijk[1], ijk[2]);
          }
          const bool split02 = (s.U[quad[0]] - s.U[quad[2]]).norm() <= (s.U[quad[1]] - s.U[quad[3]]).norm();
          std::array<Tri, 2> tris = split02 ? std::array<Tri, 2>{Tri{quad[0], quad[1], quad[2]}, Tri{quad[0], quad[2], quad[3]}}
                                            : std::array<Tri, 2>{Tri{quad[0], quad[1], quad[3]}, Tri{quad[1], quad[2], quad[3]}};
          for (Tri t : tris) {
            if (sphere_orient(s.U[t[0]], s.U[t[1]], s.U[t[2]]) < 0) std::swap(t[1], t[2]);
            s.F.push_back(t);
          }
        }
      }
    }
  }
  return s;
}

/// Convex hull of points on the unit sphere (= their spherical Delaunay triangulation), by
/// incremental insertion. Every point on a sphere is a hull vertex, so each insertion
/// sees a non-empty, connected set of faces; the result is validated (Euler, edge
/// pairing, orientation) and false returned if rounding ever broke it.
inline bool sphere_hull(const std::vector<Vec3>& P, std::vector<Tri>* out) {
  const int n = static_cast<int>(P.size());
  if (n < 4) return false;
  auto above = [&](const Tri& f, const Vec3& p) {
    return (P[f[1]] - P[f[0]]).cross(P[f[2]] - P[f[0]]).dot(p - P[f[0]]);
  };
  std::vector<Tri> F;
  std::vector<char> alive;
  std::unordered_map<std::uint64_t, int> face_of;  // directed edge -> face; lookups only
  auto add = [&](int a, int b, int c) {
    const int f = static_cast<int>(F.size());
    F.push_back({a, b, c});
    alive.push_back(1);
    face_of[edge_key(a, b)] = face_of[edge_key(b, c)] = face_of[edge_key(c, a)] = f;
  };
  // Start from four points spread along the input order (a spiral for Fibonacci points).
  int i0 = 0, i1 = n / 3, i2 = 2 * n / 3, i3 = n - 1;
  if (above({i0, i1, i2}, P[i3]) > 0) std::swap(i1, i2);
  add(i0, i1, i2);
  add(i0, i3, i1);
  add(i1, i3, i2);
  add(i2, i3, i0);
  std::vector<char> visible;
  std::vector<int> stack, region;
  for (int p = 0; p < n; ++p) {
    if (p == i0 || p == i1 || p == i2 || p == i3) continue;
    // Points come roughly sorted by height, so recent faces are the likely visible ones.
    int seed = -1;
    for (int f = static_cast<int>(F.size()) - 1; f >= 0 && seed < 0; --f)
      if (alive[f] && above(F[f], P[p]) > 0) seed = f;
    if (seed < 0) return false;
    visible.resize(F.size(), 0);
    region.assign(1, seed);
    stack.assign(1, seed);
    visible[seed] = 1;
    while (!stack.empty()) {
      const Tri f = F[stack.back()];
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const auto it = face_of.find(edge_key(f[(k + 1) % 3], f[k]));
        if (it == face_of.end()) return false;
        const int g = it->second;
        if (!visible[g] && above(F[g], P[p]) > 0) {
          visible[g] = 1;
          region.push_back(g);
          stack.push_back(g);
        }
      }
    }
    std::vector<std::pair<int, int>> horizon;
    for (int f : region) {
      for (int k = 0; k < 3; ++k) {
        const int a = F[f][k], b = F[f][(k + 1) % 3];
        if (!visible[face_of.at(edge_key(b, a))]) horizon.emplace_back(a, b);
      }
    }
    for (int f : region) {
      alive[f] = 0;
      visible[f] = 0;
      for (int k = 0; k < 3; ++k) {
        auto it = face_of.find(edge_key(F[f][k], F[f][(k + 1) % 3]));
        if (it != face_of.end() && it->second == f) face_of.erase(it);
      }
    }
    for (const auto& [a, b] : horizon) add(a, b, p);
  }
  out->clear();
  for (size_t f = 0; f < F.size(); ++f)
    if (alive[f]) out->push_back(F[f]);
  if (static_cast<int>(out->size()) != 2 * n - 4) return false;
  for (const Tri& f : *out) {
    if (sphere_orient(P[f[0]], P[f[1]], P[f[2]]) <= kMinTemplateOrient) return false;
    for (int k = 0; k < 3; ++k)
      if (!face_of.count(edge_key(f[(k + 1) % 3], f[k]))) return false;
  }
  return true;
}

/// `n` points of the Fibonacci spiral (near-uniform, no lattice symmetry), each moved by a
/// tiny random amount so no four are cocircular, triangulated as their convex hull.
inline bool fibonacci_sphere(int n, Rng& rng, SphereTriangulation* out) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0)), spacing = std::sqrt(4 * M_PI / n);
  out->U.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec3 p(r * std::cos(golden * i), r * std::sin(golden * i), z);
    const Vec3 wiggle(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    out->U[i] = (p + 1e-3 * spacing * wiggle).normalized();
  }
  return sphere_hull(out->U, &out->F);
}

/// A uniformly random rotation (Shoemake's random unit quaternion).
inline Eigen::Matrix3d random_rotation(Rng& rng) {
  const double u1 = rng.uniform(), u2 = 2 * M_PI * rng.uniform(), u3 = 2 * M_PI * rng.uniform();
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return Eigen::Quaterniond(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3))
      .normalized()
      .toRotationMatrix();
}

/// Moves every vertex tangentially by up to `fraction` of its shortest edge, keeping the
/// move only if all its triangles stay well oriented: irregular vertex positions.
inline void jitter(SphereTriangulation& s, double fraction, Rng& rng) {
  std::vector<std::vector<int>> faces_of(s.U.size());
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f)
    for (int v : s.F[f]) faces_of[v].push_back(f);
  for (int v = 0; v < static_cast<int>(s.U.size()); ++v) {
    double shortest = INFINITY;
    for (int f : faces_of[v])
      for (int w : s.F[f])
        if (w != v) shortest = std::min(shortest, (s.U[w] - s.U[v]).norm());
    Vec3 d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    d -= d.dot(s.U[v]) * s.U[v];
    const Vec3 old = s.U[v];
    s.U[v] = (old + fraction * shortest * d / std::max(1.0, d.norm())).normalized();
    for (int f : faces_of[v]) {
      // Keep triangles at least a third as "thick" as an equilateral one of that size.
      const Tri& t = s.F[f];
      if (sphere_orient(s.U[t[0]], s.U[t[1]], s.U[t[2]]) < 0.3 * shortest * shortest) {
        s.U[v] = old;
        break;
      }
    }
  }
}

/// A sphere triangulation U with surface points X = surface(U), edited by bisection and
/// flips. Faces keep their slots when edited so ids stay stable during a pass.
class SurfaceMeshEditor {
 public:
  using SurfaceFn = std::function<Vec3(const Vec3&)>;

  SurfaceMeshEditor(SphereTriangulation base, SurfaceFn surface)
      : U_(std::move(base.U)), F_(std::move(base.F)), surface_(std::move(surface)) {
    X_.reserve(U_.size());
    for (const Vec3& u : U_) X_.push_back(surface_(u));
    for (int f = 0; f < static_cast<int>(F_.size()); ++f) link(f);
  }

  const std::vector<Vec3>& U() const { return U_; }
  const std::vector<Vec3>& X() const { return X_; }
  const std::vector<Tri>& F() const { return F_; }
  int num_vertices() const { return static_cast<int>(U_.size()); }

  /// Makes template point u a vertex: the nearest corner of the triangle containing u is
  /// moved there when it is within 30% of the triangle's shortest edge (splitting would
  /// leave a tiny edge and thin triangles), is not `fixed` (an earlier landmark) and the
  /// move keeps its triangles fat; otherwise the triangle is split into three, or, if u
  /// lies on one of its edges, that edge is split at u. (Landmarks in the symmetry plane
  /// of the animal lie exactly on edges between earlier ones.) Returns the vertex.
  int insert_point(const Vec3& u, const std::vector<char>& fixed) {
    for (int f = 0; f < static_cast<int>(F_.size()); ++f) {
      const Tri t = F_[f];
      if (u.dot(U_[t[0]]) <= 0) continue;
      double side[3];
      int on_edge = -1, zeros = 0;
      for (int k = 0; k < 3; ++k) {
        side[k] = sphere_orient(U_[t[k]], U_[t[(k + 1) % 3]], u);
        if (std::abs(side[k]) <= kMinTemplateOrient) {
          on_edge = k;
          ++zeros;
        }
      }
      if (std::min({side[0], side[1], side[2]}) < -kMinTemplateOrient) continue;  // outside
      if (zeros >= 2) {  // on a corner already
        int corner = t[0];
        for (int v : t)
          if ((U_[v] - u).norm() < (U_[corner] - u).norm()) corner = v;
        return corner;
      }
      double shortest = INFINITY;
      int nearest = t[0];
      for (int k = 0; k < 3; ++k) {
        shortest = std::min(shortest, (U_[t[k]] - U_[t[(k + 1) % 3]]).norm());
        if ((U_[t[k]] - u).norm() < (U_[nearest] - u).norm()) nearest = t[k];
      }
      const bool pinned = nearest < static_cast<int>(fixed.size()) && fixed[nearest];
      if (!pinned && (U_[nearest] - u).norm() < 0.3 * shortest && move_vertex(nearest, u)) return nearest;
      if (on_edge >= 0) return split(t[on_edge], t[(on_edge + 1) % 3], u);
      const int m = add_vertex(u);
      set_face(f, {t[0], t[1], m});
      add_face({t[1], t[2], m});
      add_face({t[2], t[0], m});
      return m;
    }
    return -1;  // not reached for a closed triangulation of the sphere
  }

  /// Bisects edges, most important first, until there are `target` vertices. Importance
  /// is the surface edge length plus twice the largest deviation of the surface from the
  /// straight edge at three points along it: long edges get shorter (uniform sampling of
  /// the final surface, so thin limbs get many more template samples than their small
  /// template area would), and edges passing over a feature not yet sampled are split.
  ///
  /// Which edge is bisected first is decided on the surface, but how is decided in the
  /// template: Rivara's longest-edge bisection (an edge is bisected only when it is the
  /// longest template edge of both its triangles; otherwise the longer edge goes first).
  /// That bounds template angles from below (by half the initial smallest one), whereas
  /// bisecting whatever edge the surface picks lets thin template triangles get thinner
  /// until new vertices land on old ones.
  void refine_to(int target) {
    using Entry = std::tuple<double, int, int>;  // ties broken by vertex ids: deterministic
    std::priority_queue<Entry> queue;
    auto push = [&](int a, int b) { queue.emplace(importance(a, b), std::min(a, b), std::max(a, b)); };
    for (const Tri& t : F_)
      for (int k = 0; k < 3; ++k)
        if (t[k] < t[(k + 1) % 3]) push(t[k], t[(k + 1) % 3]);
    std::vector<std::pair<int, int>> path;  // longest-edge propagation path
    while (num_vertices() < target && !queue.empty()) {
      const auto [priority, a0, b0] = queue.top();
      queue.pop();
      path.assign(1, {a0, b0});
      while (!path.empty() && num_vertices() < target) {
        const auto [a, b] = path.back();
        if (!face_of_.count(edge_key(a, b))) {  // stale: already split
          path.pop_back();
          continue;
        }
        const int c = opposite(a, b), d = opposite(b, a);
        const auto longer = longest_template_edge(a, b, c, d);
        if (longer.first != a || longer.second != b) {
          path.push_back(longer);
          continue;
        }
        const int m = split(a, b);
        for (int w : {a, b, c, d}) push(m, w);
        path.pop_back();
      }
    }
  }

  /// Flips edges toward a Delaunay triangulation of the surface points (opposite angles
  /// summing to more than pi), where the flip keeps template triangles valid and does not
  /// cut across a crease. Returns the number of flips.
  int improve_by_flips(int max_passes) {
    int total = 0;
    for (int pass = 0; pass < max_passes; ++pass) {
      int flips = 0;
      for (int f = 0; f < static_cast<int>(F_.size()); ++f) {
        for (int k = 0; k < 3; ++k) {
          const int a = F_[f][k], b = F_[f][(k + 1) % 3];
          if (a > b) continue;
          const int c = opposite(a, b), d = opposite(b, a);
          if (angle(c, a, b) + angle(d, b, a) <= M_PI + 1e-9 || !flip_allowed(a, b)) continue;
          flip(a, b);
          ++flips;
          break;  // face f changed; its other edges are visited in later passes
        }
      }
      total += flips;
      if (flips == 0) break;
    }
    return total;
  }

  /// Moves vertices toward the centroid of their neighbours on the surface (keeping them
  /// on it: the move is solved for in template coordinates through the local Jacobian of
  /// the surface map). A move is kept only if every template triangle around the vertex
  /// stays valid and the smallest surface angle around it grows: it can only improve.
  /// `fixed` vertices (the landmarks) never move. Returns the number of moves kept.
  int smooth(const std::vector<char>& fixed) {
    std::vector<std::vector<int>> star(U_.size());
    for (int f = 0; f < static_cast<int>(F_.size()); ++f)
      for (int v : F_[f]) star[v].push_back(f);
    int moved = 0;
    for (int v = 0; v < num_vertices(); ++v) {
      if (v < static_cast<int>(fixed.size()) && fixed[v]) continue;
      Vec3 centroid = Vec3::Zero();
      for (int f : star[v])
        for (int w : F_[f])
          if (w != v) centroid += X_[w];
      centroid /= 2.0 * star[v].size();  // every neighbour is seen from two faces
      const Vec3 u = U_[v];
      Vec3 e1 = u.unitOrthogonal(), e2 = u.cross(e1);
      // Finite differences for dX/du: 1e-6 radians is far above rounding (1e-16 relative)
      // and far below the scale on which the surface bends.
      const double h = 1e-6;
      Eigen::Matrix<double, 3, 2> J;
      J.col(0) = (surface_((u + h * e1).normalized()) - X_[v]) / h;
      J.col(1) = (surface_((u + h * e2).normalized()) - X_[v]) / h;
      const Eigen::Vector2d step = J.colPivHouseholderQr().solve(0.5 * (centroid - X_[v]));
      const Vec3 u_new = (u + step(0) * e1 + step(1) * e2).normalized();
      const double before = star_min_angle(star[v]);
      const Vec3 x_old = X_[v];
      U_[v] = u_new;
      X_[v] = surface_(u_new);
      bool keep = star_min_angle(star[v]) > before;
      for (int f : star[v]) keep = keep && sphere_orient(U_[F_[f][0]], U_[F_[f][1]], U_[F_[f][2]]) > kMinTemplateOrient;
      if (keep) {
        ++moved;
      } else {
        U_[v] = u;
        X_[v] = x_old;
      }
    }
    return moved;
  }

  /// Flips randomly chosen edges (each with `probability`) when the flip keeps every
  /// surface angle at least 15 degrees and 70% of the smallest angle it replaces:
  /// irregular valences without poor triangles.
  int random_flips(double probability, Rng& rng) {
    int flips = 0;
    for (int f = 0; f < static_cast<int>(F_.size()); ++f) {
      for (int k = 0; k < 3; ++k) {
        const int a = F_[f][k], b = F_[f][(k + 1) % 3];
        if (a > b || rng.uniform() >= probability || !flip_allowed(a, b)) continue;
        const int c = opposite(a, b), d = opposite(b, a);
        const double before = std::min(min_angle(a, b, c), min_angle(b, a, d));
        const double after = std::min(min_angle(c, a, d), min_angle(d, b, c));
        if (after < std::max(M_PI / 12, 0.7 * before)) continue;
        flip(a, b);
        ++flips;
        break;
      }
    }
    return flips;
  }

 private:
  // Moves vertex v to template point u if all its triangles stay fat: det >= 0.2 e^2 for
  // the shortest edge e of each (an equilateral triangle has 0.87 e^2). Merely valid is
  // not enough: a thin triangle would get its long edge bisected onto its apex.
  bool move_vertex(int v, const Vec3& u) {
    const Vec3 old = U_[v];
    U_[v] = u;
    for (const Tri& t : F_) {
      if (t[0] != v && t[1] != v && t[2] != v) continue;
      const double e = std::min({(U_[t[0]] - U_[t[1]]).norm(), (U_[t[1]] - U_[t[2]]).norm(), (U_[t[2]] - U_[t[0]]).norm()});
      if (sphere_orient(U_[t[0]], U_[t[1]], U_[t[2]]) < 0.2 * e * e) {
        U_[v] = old;
        return false;
      }
    }
    X_[v] = surface_(u);
    return true;
  }
  int add_vertex(const Vec3& u) {
    U_.push_back(u);
    X_.push_back(surface_(u));
    return static_cast<int>(U_.size()) - 1;
  }
  void link(int f) {
    const Tri& t = F_[f];
    for (int k = 0; k < 3; ++k) face_of_[edge_key(t[k], t[(k + 1) % 3])] = f;
  }
  void unlink(int f) {
    const Tri& t = F_[f];
    for (int k = 0; k < 3; ++k) {
      auto it = face_of_.find(edge_key(t[k], t[(k + 1) % 3]));
      if (it != face_of_.end() && it->second == f) face_of_.erase(it);
    }
  }
  void set_face(int f, const Tri& t) {
    unlink(f);
    F_[f] = t;
    link(f);
  }
  void add_face(const Tri& t) {
    F_.push_back(t);
    link(static_cast<int>(F_.size()) - 1);
  }
  // The vertex opposite directed edge a->b in its face.
  int opposite(int a, int b) const {
    const Tri& t = F_[face_of_.at(edge_key(a, b))];
    for (int v : t)
      if (v != a && v != b) return v;
    return -1;
  }

  double importance(int a, int b) const {
    double deviation = 0;
    for (double s : {0.25, 0.5, 0.75}) {
      const Vec3 on_surface = surface_(((1 - s) * U_[a] + s * U_[b]).normalized());
      deviation = std::max(deviation, (on_surface - ((1 - s) * X_[a] + s * X_[b])).norm());
    }
    return (X_[a] - X_[b]).norm() + 2 * deviation;
  }

  // Of edge a-b and the other edges of its triangles (a,b,c) and (b,a,d), the longest in
  // the template, as a directed pair; a-b itself on ties. Lengths are compared together
  // with the vertex ids so the order is strict and a propagation path cannot cycle.
  std::pair<int, int> longest_template_edge(int a, int b, int c, int d) const {
    auto key = [&](int p, int q) { return std::make_tuple((U_[p] - U_[q]).squaredNorm(), std::min(p, q), std::max(p, q)); };
    std::pair<int, int> best{a, b};
    auto best_key = key(a, b);
    for (const auto& [p, q] : {std::pair{b, c}, std::pair{c, a}, std::pair{a, d}, std::pair{d, b}}) {
      if (key(p, q) > best_key) {
        best = {p, q};
        best_key = key(p, q);
      }
    }
    return best;
  }

  // Faces (a,b,c) and (b,a,d) become (a,m,c), (m,b,c), (b,m,d), (m,a,d), with m at the
  // middle of the great arc a-b; all four are valid when the two old ones were. (On a
  // limb's wall m can land far from the middle of the surface edge; smoothing evens the
  // distribution out afterwards.)
  int split(int a, int b) { return split(a, b, (U_[a] + U_[b]).normalized()); }
  // The same with m at template point u, which must lie on the arc a-b.
  int split(int a, int b, const Vec3& u) {
    const int fa = face_of_.at(edge_key(a, b)), fb = face_of_.at(edge_key(b, a));
    const int c = opposite(a, b), d = opposite(b, a);
    const int m = add_vertex(u);
    set_face(fa, {a, m, c});
    add_face({m, b, c});
    set_face(fb, {b, m, d});
    add_face({m, a, d});
    return m;
  }

  // Faces (a,b,c) and (b,a,d) become (c,a,d) and (d,b,c).
  void flip(int a, int b) {
    const int fa = face_of_.at(edge_key(a, b)), fb = face_of_.at(edge_key(b, a));
    const int c = opposite(a, b), d = opposite(b, a);
    set_face(fa, {c, a, d});
    set_face(fb, {d, b, c});
  }

  Vec3 area_normal(int a, int b, int c) const { return (X_[b] - X_[a]).cross(X_[c] - X_[a]); }
  double angle(int at, int p, int q) const {
    const Vec3 u = X_[p] - X_[at], v = X_[q] - X_[at];
    return std::atan2(u.cross(v).norm(), u.dot(v));
  }
  double min_angle(int a, int b, int c) const { return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)}); }
  double star_min_angle(const std::vector<int>& faces) const {
    double smallest = M_PI;
    for (int f : faces) smallest = std::min(smallest, min_angle(F_[f][0], F_[f][1], F_[f][2]));
    return smallest;
  }

  // Flipping a->b is allowed when the new edge c-d does not exist yet (it would duplicate
  // an edge), both new template triangles are valid, the new triangles face the way the
  // two old ones did together (within 60 degrees), and the quad is nearly flat, so the
  // flip hardly changes the shape. Flatness is the volume of the tetrahedron abcd, which
  // a flip adds or removes, against the longest quad edge s: at most s^3 / 16, the volume
  // of two equilateral triangles folded by 30 degrees. Unlike a dihedral-angle test it
  // does not trust a sliver's normal, which is mostly rounding noise.
  bool flip_allowed(int a, int b) const {
    if (!template_flip_allowed(a, b)) return false;
    const int c = opposite(a, b), d = opposite(b, a);
    const Vec3 n = (area_normal(a, b, c) + area_normal(b, a, d)).normalized();
    const double kCosTurn = 0.5;
    if (area_normal(c, a, d).normalized().dot(n) < kCosTurn || area_normal(d, b, c).normalized().dot(n) < kCosTurn)
      return false;
    const double s = std::max({(X_[a] - X_[c]).norm(), (X_[c] - X_[b]).norm(), (X_[b] - X_[d]).norm(),
                               (X_[d] - X_[a]).norm(), (X_[a] - X_[b]).norm()});
    const double volume = std::abs((X_[b] - X_[a]).cross(X_[c] - X_[a]).dot(X_[d] - X_[a])) / 6;
    return volume <= s * s * s / 16;
  }

  // A flip keeps the template a valid triangulation when the new edge is new and both
  // new template triangles are positively oriented (the quad is convex on the sphere).
  bool template_flip_allowed(int a, int b) const {
    const int c = opposite(a, b), d = opposite(b, a);
    if (c == d || face_of_.count(edge_key(c, d)) || face_of_.count(edge_key(d, c))) return false;
    return sphere_orient(U_[c], U_[a], U_[d]) > kMinTemplateOrient &&
           sphere_orient(U_[d], U_[b], U_[c]) > kMinTemplateOrient;
  }

  std::vector<Vec3> U_, X_;
  std::vector<Tri> F_;
  std::unordered_map<std::uint64_t, int> face_of_;  // directed edge -> face; lookups only
  SurfaceFn surface_;
};

}  // namespace spherekit::samples::detail
