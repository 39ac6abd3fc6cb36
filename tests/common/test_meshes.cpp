#include "test_meshes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <sstream>
#include <vector>

namespace spherekit::test {
namespace {

TriMesh make(const std::vector<Eigen::Vector3d>& V, const std::vector<std::array<int, 3>>& F) {
  TriMesh m;
  m.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (size_t i = 0; i < V.size(); ++i) m.V.row(static_cast<Eigen::Index>(i)) = V[i].transpose();
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (size_t i = 0; i < F.size(); ++i)
    for (int k = 0; k < 3; ++k) m.F(static_cast<Eigen::Index>(i), k) = F[i][k];
  return m;
}

}  // namespace

TriMesh tetrahedron() {
  const double s = 1.0 / std::sqrt(3.0);
  return make({{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}},
              {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}});
}

TriMesh octahedron() {
  return make({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
              {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

TriMesh icosphere(int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> V = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : V) v.normalize();
  std::vector<std::array<int, 3>> F = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      V.push_back((V[a] + V[b]).normalized());
      int id = static_cast<int>(V.size()) - 1;
      mid[key] = id;
      return id;
    };
    std::vector<std::array<int, 3>> G;
    for (auto f : F) {
      int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      G.push_back({f[0], a, c});
      G.push_back({f[1], b, a});
      G.push_back({f[2], c, b});
      G.push_back({a, b, c});
    }
    F = G;
  }
  return make(V, F);
}

TriMesh torus(int n, int m) {
  std::vector<Eigen::Vector3d> V;
  std::vector<std::array<int, 3>> F;
  const double R = 1.0, r = 0.35;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      double u = 2 * M_PI * i / n, v = 2 * M_PI * j / m;
      V.push_back({(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      int a = i * m + j, b = ((i + 1) % n) * m + j, c = ((i + 1) % n) * m + (j + 1) % m, d = i * m + (j + 1) % m;
      F.push_back({a, b, c});
      F.push_back({a, c, d});
    }
  return make(V, F);
}

TriMesh two_tetrahedra() {
  TriMesh a = tetrahedron();
  TriMesh m;
  m.V.resize(8, 3);
  m.V.topRows(4) = a.V;
  m.V.bottomRows(4) = a.V.rowwise() + Eigen::RowVector3d(3, 0, 0);
  m.F.resize(8, 3);
  m.F.topRows(4) = a.F;
  m.F.bottomRows(4) = a.F.array() + 4;
  return m;
}

TriMesh pinched_tetrahedra() {
  // Two tetrahedra touching at vertex 0 (the shared apex):
  //   first  {0,1,2,3}, second {0,4,5,6} mirrored through the apex.
  TriMesh a = tetrahedron();
  TriMesh m;
  m.V.resize(7, 3);
  m.V.topRows(4) = a.V;
  Eigen::RowVector3d apex = a.V.row(0);
  for (int i = 1; i < 4; ++i) m.V.row(3 + i) = 2 * apex - a.V.row(i);
  m.F.resize(8, 3);
  m.F.topRows(4) = a.F;
  // Point reflection keeps orientation (det of -I is -1 in 3D, so flip each face).
  for (int f = 0; f < 4; ++f) {
    auto map = [](int v) { return v == 0 ? 0 : v + 3; };
    m.F.row(4 + f) << map(a.F(f, 0)), map(a.F(f, 2)), map(a.F(f, 1));
  }
  return m;
}

TriMesh sphere_with_holes(int level, int holes) {
  TriMesh s = icosphere(level);
  // Remove the faces around up to three well-separated icosahedron vertices (ids 0, 3, 8:
  // never adjacent), each leaving one boundary loop.
  const int centres[3] = {0, 3, 8};
  std::vector<char> drop(static_cast<size_t>(s.F.rows()), 0);
  for (int h = 0; h < holes && h < 3; ++h)
    for (Eigen::Index f = 0; f < s.F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        if (s.F(f, k) == centres[h]) drop[static_cast<size_t>(f)] = 1;
  std::vector<std::array<int, 3>> F;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    if (!drop[static_cast<size_t>(f)]) F.push_back({s.F(f, 0), s.F(f, 1), s.F(f, 2)});
  // Drop now-unreferenced centre vertices by compaction.
  std::vector<int> used(static_cast<size_t>(s.V.rows()), -1);
  std::vector<Eigen::Vector3d> V;
  for (auto& f : F)
    for (int& v : f) {
      if (used[static_cast<size_t>(v)] < 0) {
        used[static_cast<size_t>(v)] = static_cast<int>(V.size());
        V.push_back(s.V.row(v).transpose());
      }
      v = used[static_cast<size_t>(v)];
    }
  return make(V, F);
}

TriMesh random_blob(int level, std::uint64_t seed) {
  TriMesh m = icosphere(level);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  struct Bump { Eigen::Vector3d c; double h, w; };
  std::vector<Bump> bumps;
  for (int i = 0; i < 6; ++i) {
    Eigen::Vector3d c(U(rng), U(rng), U(rng));
    if (c.norm() < 1e-3) c = Eigen::Vector3d::UnitX();
    bumps.push_back({c.normalized(), 0.6 * (U(rng) + 1.0), 0.3 + 0.2 * (U(rng) + 1.0)});
  }
  Eigen::Vector3d scale(1.0 + 0.5 * (U(rng) + 1), 1.0 + 0.3 * (U(rng) + 1), 1.0);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    Eigen::Vector3d p = m.V.row(i).transpose();
    double r = 1.0;
    for (auto& b : bumps) r += b.h * std::exp(-(p - b.c).squaredNorm() / (b.w * b.w));
    m.V.row(i) = (p * r).cwiseProduct(scale).transpose();
  }
  return m;
}

TriMesh elongated(int level, double aspect) {
  TriMesh m = icosphere(level);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) m.V(i, 0) *= aspect;
  return m;
}

TriMesh six_armed_star(int level) {
  TriMesh m = icosphere(level);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const Eigen::RowVector3d n = m.V.row(v).normalized();
    const double arm = n.cwiseAbs().maxCoeff();  // 1 on an axis, 1/sqrt(3) between
    m.V.row(v) = n * (1.0 + 4.0 * std::pow(std::max(0.0, (arm - 0.8) / 0.2), 2.0));
  }
  return m;
}

PolygonMesh star_prism_polygons() {
  constexpr int kCorners = 12;
  constexpr double kPi = 3.14159265358979323846;
  PolygonMesh m;
  m.V.resize(2 * kCorners + 2, 3);
  // Rings: b_i = i, t_i = kCorners + i; the top ring is turned by 10 degrees (non-planar sides).
  for (int ring = 0; ring < 2; ++ring) {
    for (int i = 0; i < kCorners; ++i) {
      const double r = i % 2 == 0 ? 1.0 : 0.45;
      const double a = 2 * kPi * i / kCorners + (ring == 1 ? 10.0 * kPi / 180 : 0.0);
      m.V.row(ring * kCorners + i) << r * std::cos(a), r * std::sin(a), ring;
    }
  }
  const int mid = 2 * kCorners, apex = 2 * kCorners + 1;
  m.V.row(mid) = 0.5 * (m.V.row(kCorners) + m.V.row(kCorners + 1));  // on the edge t0-t1
  m.V.row(apex) << 0, 0, 1.6;
  auto b = [](int i) { return i % kCorners; };
  auto t = [](int i) { return kCorners + i % kCorners; };
  std::vector<int> base;
  for (int i = kCorners - 1; i >= 0; --i) base.push_back(b(i));  // seen from below
  m.faces.push_back(base);
  m.faces.push_back({b(0), b(1), t(1), mid, t(0)});  // the pentagon
  for (int i = 1; i < kCorners; ++i) m.faces.push_back({b(i), b(i + 1), t(i + 1), t(i)});
  m.faces.push_back({t(0), mid, t(1), apex});
  for (int i = 1; i < kCorners; ++i) m.faces.push_back({t(i), t(i + 1), apex});
  return m;
}

std::string polygon_mesh_text(const PolygonMesh& mesh, const std::string& format) {
  std::ostringstream out;
  out.precision(17);
  const auto nv = mesh.V.rows();
  if (format == "off") out << "OFF\n" << nv << " " << mesh.faces.size() << " 0\n";
  if (format == "ply")
    out << "ply\nformat ascii 1.0\nelement vertex " << nv << "\nproperty double x\nproperty double y\n"
        << "property double z\nelement face " << mesh.faces.size() << "\nproperty list uchar int vertex_indices\n"
        << "end_header\n";
  for (Eigen::Index v = 0; v < nv; ++v)
    out << (format == "obj" ? "v " : "") << mesh.V(v, 0) << " " << mesh.V(v, 1) << " " << mesh.V(v, 2) << "\n";
  for (const std::vector<int>& f : mesh.faces) {
    out << (format == "obj" ? "f" : std::to_string(f.size()));
    for (const int c : f) out << " " << (format == "obj" ? c + 1 : c);
    out << "\n";
  }
  return out.str();
}

}  // namespace spherekit::test
