// Correspondence through sphere maps: point transfer, closest points, geodesic error.
#include "spherekit/correspondence.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "detail/sphere_locator.h"
#include "spherekit/geometry_image.h"

namespace spherekit {

Eigen::Vector3d surface_position(const TriMesh& mesh, const SurfacePoint& p) {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int c = 0; c < 3; ++c) x += p.bary[c] * mesh.V.row(mesh.F(p.face, c)).transpose();
  return x;
}

SurfacePoint vertex_surface_point(const TriMesh& mesh, int v) {
  SurfacePoint p;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (mesh.F(f, c) == v) {
        p.face = static_cast<int>(f);
        p.bary = Eigen::Vector3d::Zero();
        p.bary[c] = 1;
        return p;
      }
  return p;
}

// ---------------------------------------------------------------------------------------
// Closest points

struct ClosestPointLocator::Impl {
  const TriMesh* mesh = nullptr;
  Eigen::Vector3d lo, hi;
  double h = 1;        // cell size
  int g[3] = {1, 1, 1};
  std::vector<std::vector<int>> cells;

  int cell_index(int x, int y, int z) const { return (z * g[1] + y) * g[0] + x; }
  int coord(double t, int a) const {
    return std::clamp(static_cast<int>(std::floor((t - lo[a]) / h)), 0, g[a] - 1);
  }
};

ClosestPointLocator::ClosestPointLocator(const TriMesh& mesh) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.mesh = &mesh;
  if (mesh.F.rows() == 0) return;
  m.lo = mesh.V.colwise().minCoeff().transpose();
  m.hi = mesh.V.colwise().maxCoeff().transpose();
  const Eigen::Vector3d ext = (m.hi - m.lo).cwiseMax(1e-300);
  // About two faces per cell along the surface: cells of the mean edge length's scale.
  const double cells_wanted = std::max(1.0, static_cast<double>(mesh.F.rows()) / 2);
  const double vol = ext.prod();
  m.h = vol > 0 ? std::cbrt(vol / cells_wanted) : ext.maxCoeff() / std::sqrt(cells_wanted);
  m.h = std::max(m.h, ext.maxCoeff() / 256);  // bounded grid for flat or elongated meshes
  for (int a = 0; a < 3; ++a) m.g[a] = std::max(1, static_cast<int>(std::ceil(ext[a] / m.h)));
  m.cells.resize(static_cast<size_t>(m.g[0]) * m.g[1] * m.g[2]);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose(), b = a;
    for (int c = 1; c < 3; ++c) {
      a = a.cwiseMin(mesh.V.row(mesh.F(f, c)).transpose());
      b = b.cwiseMax(mesh.V.row(mesh.F(f, c)).transpose());
    }
    for (int z = m.coord(a.z(), 2); z <= m.coord(b.z(), 2); ++z)
      for (int y = m.coord(a.y(), 1); y <= m.coord(b.y(), 1); ++y)
        for (int x = m.coord(a.x(), 0); x <= m.coord(b.x(), 0); ++x)
          m.cells[static_cast<size_t>(m.cell_index(x, y, z))].push_back(static_cast<int>(f));
  }
}

ClosestPointLocator::~ClosestPointLocator() = default;
ClosestPointLocator::ClosestPointLocator(ClosestPointLocator&&) noexcept = default;
ClosestPointLocator& ClosestPointLocator::operator=(ClosestPointLocator&&) noexcept = default;

SurfacePoint ClosestPointLocator::closest(const Eigen::Vector3d& q) const {
  const Impl& m = *impl_;
  SurfacePoint best;
  if (m.cells.empty()) return best;
  double best_d = std::numeric_limits<double>::infinity();
  const int c[3] = {m.coord(q.x(), 0), m.coord(q.y(), 1), m.coord(q.z(), 2)};
  const int rmax = std::max({m.g[0], m.g[1], m.g[2]});
  auto visit = [&](int x, int y, int z) {
    for (int f : m.cells[static_cast<size_t>(m.cell_index(x, y, z))]) {
      Eigen::Vector3d bary;
      const Eigen::Vector3d p = detail::closest_point_on_triangle(q, m.mesh->V.row(m.mesh->F(f, 0)).transpose(),
                                                                  m.mesh->V.row(m.mesh->F(f, 1)).transpose(),
                                                                  m.mesh->V.row(m.mesh->F(f, 2)).transpose(), bary);
      const double d = (p - q).squaredNorm();
      // Ties go to the lower face id: the answer does not depend on the visiting order.
      if (d < best_d || (d == best_d && f < best.face)) best_d = d, best.face = f, best.bary = bary;
    }
  };
  for (int r = 0; r <= rmax; ++r) {
    // The shell of cells at Chebyshev distance r from c.
    for (int z = c[2] - r; z <= c[2] + r; ++z)
      for (int y = c[1] - r; y <= c[1] + r; ++y)
        for (int x = c[0] - r; x <= c[0] + r; ++x) {
          if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
          if (x < 0 || y < 0 || z < 0 || x >= m.g[0] || y >= m.g[1] || z >= m.g[2]) continue;
          visit(x, y, z);
        }
    // Every face not yet seen lies beyond a side of the visited box that has cells behind
    // it; q (clamped into the grid) is inside the box, so `margin` >= 0 bounds their distance.
    double margin = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (c[a] - r > 0) margin = std::min(margin, q[a] - (m.lo[a] + (c[a] - r) * m.h));
      if (c[a] + r + 1 < m.g[a]) margin = std::min(margin, m.lo[a] + (c[a] + r + 1) * m.h - q[a]);
    }
    if (margin == std::numeric_limits<double>::infinity()) break;  // the whole grid was visited
    if (best.face >= 0 && best_d <= margin * margin) break;
  }
  return best;
}

// ---------------------------------------------------------------------------------------
// Transfer

Result<std::vector<TransferredPoint>> transfer_points(const TriMesh& from, const RowMat3d& S_from,
                                                      const std::vector<SurfacePoint>& points, const TriMesh& to,
                                                      const RowMat3d& S_to) {
  if (S_from.rows() != from.V.rows())
    return Status(ErrorCode::InvalidInput, "source map has " + std::to_string(S_from.rows()) + " points, mesh has " +
                                               std::to_string(from.V.rows()) + " vertices");
  if (S_to.rows() != to.V.rows())
    return Status(ErrorCode::InvalidInput, "target map has " + std::to_string(S_to.rows()) + " points, mesh has " +
                                               std::to_string(to.V.rows()) + " vertices");
  const SphereLocator locator(to.F, S_to);
  std::vector<TransferredPoint> out(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const SurfacePoint& p = points[i];
    if (p.face < 0 || p.face >= from.F.rows())
      return Status(ErrorCode::InvalidInput, "point " + std::to_string(i) + " names face " + std::to_string(p.face) +
                                                 ", out of range");
    // The chord-triangle point with these barycentrics, projected centrally: the exact
    // inverse of the gnomonic barycentrics the locator computes.
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int c = 0; c < 3; ++c) s += p.bary[c] * S_from.row(from.F(p.face, c)).transpose();
    if (!(s.norm() > 0)) s = S_from.row(from.F(p.face, 0)).transpose();
    const SphereLocation loc = locator.locate(s.normalized());
    out[i].point.face = loc.face;
    out[i].point.bary = loc.bary;
    out[i].in_hole = !loc.inside;
    if (loc.face < 0) return Status(ErrorCode::InvalidInput, "target map has no usable face");
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Geodesic error

Result<CorrespondenceError> correspondence_error(const TriMesh& to, const std::vector<SurfacePoint>& predicted,
                                                 const std::vector<int>& truth) {
  if (predicted.size() != truth.size())
    return Status(ErrorCode::InvalidInput, "need one true vertex per predicted point");
  if (predicted.empty()) return Status(ErrorCode::InvalidArgument, "no correspondence pairs");
  const int nv = static_cast<int>(to.V.rows());
  for (size_t i = 0; i < truth.size(); ++i) {
    if (truth[i] < 0 || truth[i] >= nv)
      return Status(ErrorCode::InvalidInput, "true vertex " + std::to_string(truth[i]) + " out of range");
    if (predicted[i].face < 0 || predicted[i].face >= to.F.rows())
      return Status(ErrorCode::InvalidInput, "predicted face " + std::to_string(predicted[i].face) + " out of range");
  }
  // Edge graph.
  std::vector<std::vector<std::pair<int, double>>> adj(static_cast<size_t>(nv));
  double area = 0;
  for (Eigen::Index f = 0; f < to.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = to.F(f, c), b = to.F(f, (c + 1) % 3);
      const double w = (to.V.row(a) - to.V.row(b)).norm();
      adj[static_cast<size_t>(a)].push_back({b, w});
      adj[static_cast<size_t>(b)].push_back({a, w});
    }
    area += 0.5 * (to.V.row(to.F(f, 1)) - to.V.row(to.F(f, 0))).cross(to.V.row(to.F(f, 2)) - to.V.row(to.F(f, 0))).norm();
  }
  if (!(area > 0)) return Status(ErrorCode::InvalidInput, "target mesh has zero area");
  // One Dijkstra per distinct true vertex (pairs sorted by it so each runs once).
  std::vector<size_t> order(truth.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return truth[a] < truth[b]; });
  std::vector<double> err(truth.size());
  std::vector<double> dist(static_cast<size_t>(nv));
  using Item = std::pair<double, int>;
  for (size_t k = 0; k < order.size();) {
    const int src = truth[order[k]];
    std::fill(dist.begin(), dist.end(), std::numeric_limits<double>::infinity());
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    dist[static_cast<size_t>(src)] = 0;
    heap.push({0, src});
    while (!heap.empty()) {
      auto [d, v] = heap.top();
      heap.pop();
      if (d > dist[static_cast<size_t>(v)]) continue;
      for (auto [w, len] : adj[static_cast<size_t>(v)])
        if (d + len < dist[static_cast<size_t>(w)]) {
          dist[static_cast<size_t>(w)] = d + len;
          heap.push({d + len, w});
        }
    }
    for (; k < order.size() && truth[order[k]] == src; ++k) {
      const size_t i = order[k];
      const Eigen::Vector3d x = surface_position(to, predicted[i]);
      double e = std::numeric_limits<double>::infinity();
      for (int c = 0; c < 3; ++c) {
        const int v = to.F(predicted[i].face, c);
        e = std::min(e, dist[static_cast<size_t>(v)] + (to.V.row(v).transpose() - x).norm());
      }
      err[i] = e / std::sqrt(area);
    }
  }
  CorrespondenceError r;
  r.pairs = static_cast<int>(err.size());
  std::vector<double> sorted = err;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  int u1 = 0, u2 = 0, u3 = 0;
  for (double e : err) {
    sum += e;
    u1 += e < 0.025;
    u2 += e < 0.05;
    u3 += e < 0.1;
  }
  const double np = static_cast<double>(err.size());
  r.mean = sum / np;
  // Quantiles with linear interpolation (numpy's default), as evalcorr.py reports them.
  auto quantile = [&](double q) {
    const double pos = q * (np - 1);
    const size_t i = static_cast<size_t>(std::floor(pos));
    const size_t j = std::min(i + 1, sorted.size() - 1);
    return sorted[i] + (pos - static_cast<double>(i)) * (sorted[j] - sorted[i]);
  };
  r.median = quantile(0.5);
  r.p90 = quantile(0.9);
  r.max = sorted.back();
  r.under_0025 = u1 / np;
  r.under_005 = u2 / np;
  r.under_01 = u3 / np;
  return r;
}

}  // namespace spherekit
