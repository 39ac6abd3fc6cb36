// SphereLocator: which face of a sphere map contains a direction (see geometry_image.h).
// Index: a uniform G x G grid over the octahedral domain; faces are listed in every cell whose
// spherical bounding cap meets the face's bounding cap (flood fill over cells, across folds).
#include "detail/sphere_locator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "spherekit/geometry_image.h"

namespace spherekit {
namespace {

constexpr double kInsideTolerance = 1e-7;  // smallest barycentric still counted as inside
constexpr double kCapSlack = 1e-7;         // radians added to cap-overlap tests

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  // atan2 form: accurate for small and large angles alike.
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

struct Cap {
  Eigen::Vector3d centre{0, 0, 1};
  double radius = 0;
  bool everywhere = false;  // too large (or degenerate) to be convex: list in every cell
};

}  // namespace

bool gnomonic_barycentrics(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                           const Eigen::Vector3d& p, Eigen::Vector3d& bary) {
  const Eigen::Vector3d e0 = b.cross(c), e1 = c.cross(a), e2 = a.cross(b);
  const double denom = p.dot(e0 + e1 + e2);  // p . ((b-a) x (c-a))
  if (!(denom > 0)) return false;
  bary = Eigen::Vector3d(p.dot(e0), p.dot(e1), p.dot(e2)) / denom;
  return true;
}

struct SphereLocator::Impl {
  RowMat3i F;
  RowMat3d S;
  int G = 2;
  std::vector<int> cell_start;  // CSR over cells (row-major), G*G+1 entries
  std::vector<int> cell_faces;
  // Per face: the edge-plane normals b x c, c x a, a x b (gnomonic barycentrics are
  // p.e_k / p.(e0+e1+e2)).
  std::vector<Eigen::Matrix3d> edges;

  int cell_index(int row, int col) const { return row * G + col; }

  void cell_of(const Eigen::Vector3d& p, int& row, int& col) const {
    const Eigen::Vector2d uv = sphere_to_octahedral(p);
    col = static_cast<int>(std::floor((uv.x() + 1) * 0.5 * G));
    row = static_cast<int>(std::floor((uv.y() + 1) * 0.5 * G));
    col = std::clamp(col, 0, G - 1);
    row = std::clamp(row, 0, G - 1);
  }

  Eigen::Vector3d corner(int f, int k) const { return S.row(F(f, k)).transpose(); }

  // Smallest gnomonic barycentric of p in face f (-inf if the ray misses the face's plane).
  double score(int f, const Eigen::Vector3d& p, Eigen::Vector3d& bary) const {
    const Eigen::Matrix3d& e = edges[static_cast<std::size_t>(f)];
    const Eigen::Vector3d num = e * p;  // rows of e are the edge normals
    const double denom = num.sum();
    if (!(denom > 0)) return -std::numeric_limits<double>::infinity();
    bary = num / denom;
    return bary.minCoeff();
  }

  void build() {
    const int nf = static_cast<int>(F.rows());
    G = 2 * std::clamp(static_cast<int>(std::lround(0.5 * std::sqrt(static_cast<double>(nf)))), 1, 512);
    edges.resize(static_cast<std::size_t>(nf));
    for (int f = 0; f < nf; ++f) {
      const Eigen::Vector3d a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
      Eigen::Matrix3d e;
      e.row(0) = b.cross(c);
      e.row(1) = c.cross(a);
      e.row(2) = a.cross(b);
      edges[static_cast<std::size_t>(f)] = e;
    }
    // Bounding caps of the cells: the image of a cell is a union of spherical polygons whose
    // corners are images of the cell corners (G even: cells never straddle a fold line except
    // along their diagonal), so the cap around the corner images contains it.
    std::vector<Cap> cell_caps(static_cast<std::size_t>(G) * G);
    for (int r = 0; r < G; ++r)
      for (int c = 0; c < G; ++c) {
        Eigen::Vector3d q[4];
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k) {
          const double u = -1 + 2.0 * (c + (k & 1)) / G, v = -1 + 2.0 * (r + (k >> 1)) / G;
          q[k] = octahedral_to_sphere(u, v);
          sum += q[k];
        }
        Cap& cap = cell_caps[static_cast<std::size_t>(cell_index(r, c))];
        cap.centre = sum.normalized();
        for (const auto& x : q) cap.radius = std::max(cap.radius, angle_between(cap.centre, x));
      }

    std::vector<std::pair<int, int>> pairs;  // (cell, face)
    pairs.reserve(static_cast<std::size_t>(nf) * 6);
    std::vector<int> stamp(static_cast<std::size_t>(G) * G, -1);
    std::vector<std::pair<int, int>> queue;
    for (int f = 0; f < nf; ++f) {
      const Eigen::Vector3d a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
      Cap cap;
      const Eigen::Vector3d sum = a + b + c;
      if (sum.norm() < 1e-12) {
        cap.everywhere = true;
      } else {
        cap.centre = sum.normalized();
        cap.radius = std::max({angle_between(cap.centre, a), angle_between(cap.centre, b),
                               angle_between(cap.centre, c)});
        if (!(cap.radius < 0.5 * std::numbers::pi - 1e-6)) cap.everywhere = true;
      }
      if (cap.everywhere) {
        for (int k = 0; k < G * G; ++k) pairs.emplace_back(k, f);
        continue;
      }
      int r0, c0;
      cell_of(cap.centre, r0, c0);
      queue.clear();
      queue.emplace_back(r0, c0);
      stamp[static_cast<std::size_t>(cell_index(r0, c0))] = f;
      for (std::size_t head = 0; head < queue.size(); ++head) {
        const auto [r, c] = queue[head];
        const int idx = cell_index(r, c);
        const Cap& cc = cell_caps[static_cast<std::size_t>(idx)];
        const bool meets = angle_between(cap.centre, cc.centre) <= cap.radius + cc.radius + kCapSlack;
        if (!meets && head != 0) continue;
        pairs.emplace_back(idx, f);
        for (int dr = -1; dr <= 1; ++dr)
          for (int dc = -1; dc <= 1; ++dc) {
            if (dr == 0 && dc == 0) continue;
            int rr = r + dr, cc2 = c + dc;
            detail::fold_cell(rr, cc2, G);
            const auto k = static_cast<std::size_t>(cell_index(rr, cc2));
            if (stamp[k] == f) continue;
            stamp[k] = f;
            queue.emplace_back(rr, cc2);
          }
      }
    }
    // Counting sort by cell, stable: faces stay in increasing order within a cell.
    cell_start.assign(static_cast<std::size_t>(G) * G + 1, 0);
    for (const auto& [cell, f] : pairs) ++cell_start[static_cast<std::size_t>(cell) + 1];
    for (std::size_t k = 1; k < cell_start.size(); ++k) cell_start[k] += cell_start[k - 1];
    cell_faces.resize(pairs.size());
    std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
    for (const auto& [cell, f] : pairs) cell_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell)]++)] = f;
  }

  // Nearest face (chord distance from p to the flat triangle) among the faces listed in the
  // cells around p's cell: rings grow until faces were found, then two more rings.
  SphereLocation nearest(const Eigen::Vector3d& p, int row, int col) const {
    SphereLocation loc;
    std::vector<int> candidates;
    int found_ring = -1;
    for (int ring = 0; ring <= G; ++ring) {
      for (int dr = -ring; dr <= ring; ++dr)
        for (int dc = -ring; dc <= ring; ++dc) {
          if (std::max(std::abs(dr), std::abs(dc)) != ring) continue;
          int r = row + dr, c = col + dc;
          detail::fold_cell(r, c, G);
          const int idx = cell_index(r, c);
          for (int k = cell_start[static_cast<std::size_t>(idx)]; k < cell_start[static_cast<std::size_t>(idx) + 1]; ++k)
            candidates.push_back(cell_faces[static_cast<std::size_t>(k)]);
        }
      if (found_ring < 0 && !candidates.empty()) found_ring = ring;
      if (found_ring >= 0 && ring >= found_ring + 2) break;
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    double best = std::numeric_limits<double>::infinity();
    for (int f : candidates) {
      Eigen::Vector3d bary;
      const Eigen::Vector3d q = detail::closest_point_on_triangle(p, corner(f, 0), corner(f, 1), corner(f, 2), bary);
      const double d = (q - p).squaredNorm();
      if (d < best) {
        best = d;
        loc.face = f;
        loc.bary = bary;
      }
    }
    loc.inside = false;
    return loc;
  }

  SphereLocation locate(const Eigen::Vector3d& p) const {
    SphereLocation loc;
    if (F.rows() == 0) return loc;
    int row, col;
    cell_of(p, row, col);
    const int idx = cell_index(row, col);
    double best = -std::numeric_limits<double>::infinity();
    for (int k = cell_start[static_cast<std::size_t>(idx)]; k < cell_start[static_cast<std::size_t>(idx) + 1]; ++k) {
      const int f = cell_faces[static_cast<std::size_t>(k)];
      Eigen::Vector3d bary;
      const double s = score(f, p, bary);
      if (s > best) {
        best = s;
        loc.face = f;
        loc.bary = bary;
      }
    }
    if (best >= -kInsideTolerance) {
      loc.bary = loc.bary.cwiseMax(0.0);
      loc.bary /= loc.bary.sum();
      loc.inside = true;
      return loc;
    }
    return nearest(p, row, col);
  }
};

SphereLocator::SphereLocator(const RowMat3i& F, const RowMat3d& S) : impl_(std::make_unique<Impl>()) {
  impl_->F = F;
  impl_->S = S;
  impl_->build();
}
SphereLocator::~SphereLocator() = default;
SphereLocator::SphereLocator(SphereLocator&&) noexcept = default;
SphereLocator& SphereLocator::operator=(SphereLocator&&) noexcept = default;

SphereLocation SphereLocator::locate(const Eigen::Vector3d& direction) const { return impl_->locate(direction); }
int SphereLocator::grid_size() const { return impl_->G; }

}  // namespace spherekit
