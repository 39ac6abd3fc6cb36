// Signed shape signal and its agreement through two sphere maps (see landmark_orientation.h).
#include "detail/landmark_orientation.h"

#include <algorithm>
#include <cmath>

#include "spherekit/geometry_image.h"

namespace spherekit::detail {

std::vector<double> smoothed_normal_offset(const TriMesh& mesh, double radius) {
  const int n = static_cast<int>(mesh.V.rows());
  std::vector<std::vector<int>> nbr(n);
  RowMat3d N = RowMat3d::Zero(n, 3);
  double area = 0, edge = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d cr = (b - a).cross(c - a);
    area += 0.5 * cr.norm();
    for (int k = 0; k < 3; ++k) {
      const int u = mesh.F(f, k), w = mesh.F(f, (k + 1) % 3);
      N.row(u) += cr.transpose();
      nbr[u].push_back(w);
      nbr[w].push_back(u);
      edge += (mesh.V.row(u) - mesh.V.row(w)).norm();
    }
  }
  for (auto& l : nbr) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  const double sa = std::sqrt(std::max(area, 1e-300));
  const double mean_edge = edge / std::max<Eigen::Index>(1, 3 * mesh.F.rows()) / sa;
  // A k-step umbrella walk spreads over about sqrt(k) edges.
  const double steps = mean_edge > 0 ? (radius / mean_edge) * (radius / mean_edge) : 1.0;
  const int iters = static_cast<int>(std::clamp(std::round(steps), 1.0, 4000.0));
  RowMat3d P = mesh.V, Q(n, 3);
  for (int it = 0; it < iters; ++it) {
    for (int v = 0; v < n; ++v) {
      if (nbr[v].empty()) {
        Q.row(v) = P.row(v);
        continue;
      }
      Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
      for (int u : nbr[v]) s += P.row(u);
      Q.row(v) = s / static_cast<double>(nbr[v].size());
    }
    P.swap(Q);
  }
  std::vector<double> h(n, 0.0);
  for (int v = 0; v < n; ++v) {
    const double l = N.row(v).norm();
    if (l > 0) h[v] = (P.row(v) - mesh.V.row(v)).dot(N.row(v)) / (l * sa);
  }
  return h;
}

double correspondence_agreement(const TriMesh& ref, const RowMat3d& S_ref, const std::vector<double>& a,
                                const TriMesh& member, const RowMat3d& S_member, const std::vector<double>& b) {
  if (S_ref.rows() != ref.V.rows() || S_member.rows() != member.V.rows() || member.F.rows() == 0) return -2;
  const SphereLocator locator(member.F, S_member);
  const int n = static_cast<int>(ref.V.rows());
  const int stride = std::max(1, n / 4000);
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  int count = 0;
  for (int v = 0; v < n; v += stride) {
    const SphereLocation loc = locator.locate(S_ref.row(v).transpose().normalized());
    if (loc.face < 0) return -2;
    double y = 0;
    for (int c = 0; c < 3; ++c) y += loc.bary[c] * b[member.F(loc.face, c)];
    const double x = a[v];
    sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y;
    ++count;
  }
  if (count < 2) return -2;
  const double cx = sxx - sx * sx / count, cy = syy - sy * sy / count, cxy = sxy - sx * sy / count;
  return cx > 0 && cy > 0 ? cxy / std::sqrt(cx * cy) : 0.0;
}

}  // namespace spherekit::detail

namespace spherekit::detail {

int ambiguous_sphere_choice(const std::vector<std::pair<double, int>>& scored, int turns_pick, double raw_top,
                            double margin, double informative, const std::vector<double>& efficiency,
                            double decisive_ratio) {
  if (scored.empty()) return turns_pick;
  if (raw_top < informative) {
    // The most efficient map, if clearly so (every other scored candidate's efficiency at
    // most 1 / decisive_ratio of it); else the turns' pick.
    int best = -1;
    double first = 0, second = 0;
    for (const auto& sc : scored) {
      const int c = sc.second;
      const bool known = c >= 0 && c < static_cast<int>(efficiency.size());
      const double e = known ? efficiency[static_cast<std::size_t>(c)] : 0.0;
      if (e > first) {
        second = first;
        first = e;
        best = c;
      } else {
        second = std::max(second, e);
      }
    }
    if (decisive_ratio > 0 && best >= 0 && first >= decisive_ratio * second) return best;
    return turns_pick;
  }
  const double top = scored.front().first;
  int cheapest = -1;
  for (const auto& [score, c] : scored) {
    if (top - score >= margin) continue;
    if (c == turns_pick) return turns_pick;
    if (cheapest < 0 || c < cheapest) cheapest = c;
  }
  return cheapest;
}

}  // namespace spherekit::detail
