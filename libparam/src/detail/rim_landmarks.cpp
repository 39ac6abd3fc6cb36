// Rim points of corresponding openings (see rim_landmarks.h).
#include "detail/rim_landmarks.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "detail/check_topology.h"

namespace spherekit::detail {
namespace {

// Relative differences are capped like the extremity match's pairs: beyond a factor 1.5 a
// distance is simply "wrong".
constexpr double kCap = 0.4;
// Distances to a landmark on or next to the rim are offset by this (x sqrt(area)) before their
// ratio is taken, so 0.001 against 0.002 does not count as a factor 2.
constexpr double kNear = 0.02;
// Openings with fewer rim vertices are scan noise, not features; with more, a scan's outer
// border, whose diameter (a search over all pairs) would cost more than the rest of the proposal.
constexpr int kMinRim = 6, kMaxRim = 3000;
// A side's middle is a point only where that side bulges by this share of the rim's diameter:
// the two lips of a closed slit lie on top of each other.
constexpr double kMinBulge = 0.1;
// A point is kept only where the rim's extremum is sharp: the rim vertices within kFlat of the
// extreme value (the other end's distance, or the side's distance from the chord) span at
// most kMaxWindow (x sqrt(area)) of rim. An eye's or a mouth's corners and middles span
// 0.004-0.021 on the ICT heads; a neck's cut, a wide gentle curve, 0.08-0.2: its "ends" move
// with any change of shape.
constexpr double kFlat = 0.02, kMaxWindow = 0.04;

double rel(double a, double b) { return std::min(std::abs(std::log((a + kNear) / (b + kNear))), kCap); }

Rim describe(const TriMesh& mesh, double sqrt_area, std::vector<int> loop) {
  const RowMat3d& V = mesh.V;
  Rim r;
  r.v = std::move(loop);
  const int n = static_cast<int>(r.v.size());
  for (int k = 0; k < n; ++k) r.perimeter += (V.row(r.v[k]) - V.row(r.v[(k + 1) % n])).norm() / sqrt_area;
  double diam = -1;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      if (const double d = (V.row(r.v[a]) - V.row(r.v[b])).squaredNorm(); d > diam) diam = d, r.i = a, r.j = b;
  diam = std::sqrt(diam);
  const Eigen::Vector3d p = V.row(r.v[r.i]), u = (Eigen::Vector3d(V.row(r.v[r.j])) - p) / diam;
  auto farthest = [&](int from, int to, int& at) {  // positions from .. to, going forward
    double w = -1;
    for (int k = from; k != to; k = (k + 1) % n) {
      const Eigen::Vector3d x = Eigen::Vector3d(V.row(r.v[k])) - p;
      if (const double d = (x - x.dot(u) * u).norm(); d > w) w = d, at = k;
    }
    return w;
  };
  const double wa = farthest(r.i, r.j, r.mid_ij), wb = farthest(r.j, r.i, r.mid_ji);
  r.elongation = diam / std::max(wa + wb, 1e-300);
  r.bulge = std::min(wa, wb) / diam;
  // Rim length around each vertex (half of each adjacent segment), then the windows.
  std::vector<double> len(n);
  for (int k = 0; k < n; ++k)
    len[k] = 0.5 * ((V.row(r.v[k]) - V.row(r.v[(k + 1) % n])).norm() + (V.row(r.v[k]) - V.row(r.v[(k + n - 1) % n])).norm()) /
             sqrt_area;
  auto window = [&](auto value, int from, int count) {  // `count` positions from `from`, forward
    double top = 0, w = 0;
    for (int c = 0; c < count; ++c) top = std::max(top, value((from + c) % n));
    for (int c = 0; c < count; ++c)
      if (value((from + c) % n) >= (1 - kFlat) * top) w += len[(from + c) % n];
    return w;
  };
  auto from_end = [&](int e) { return [&, e](int k) { return (V.row(r.v[k]) - V.row(r.v[e])).norm(); }; };
  auto off_chord = [&](int k) {
    const Eigen::Vector3d x = Eigen::Vector3d(V.row(r.v[k])) - p;
    return (x - x.dot(u) * u).norm();
  };
  r.sharp[0] = window(from_end(r.j), 0, n) <= kMaxWindow;
  r.sharp[1] = window(from_end(r.i), 0, n) <= kMaxWindow;
  r.sharp[2] = window(off_chord, r.i, r.j - r.i) <= kMaxWindow;
  r.sharp[3] = window(off_chord, r.j, n - (r.j - r.i)) <= kMaxWindow;
  return r;
}

std::vector<Rim> rims_of(const TriMesh& mesh, double sqrt_area) {
  const MeshTopology topo = build_topology(mesh);
  bool ok = false;
  std::vector<Rim> rims;
  for (const std::vector<int>& hl : trace_boundary_loops(mesh, topo, &ok)) {
    if (static_cast<int>(hl.size()) < kMinRim || static_cast<int>(hl.size()) > kMaxRim) continue;
    std::vector<int> loop;
    for (int h : hl) loop.push_back(he_from(mesh, h));
    rims.push_back(describe(mesh, sqrt_area, std::move(loop)));
  }
  return ok ? rims : std::vector<Rim>{};
}

// Per landmark: the geodesic distance from the rim (its nearest vertex).
std::vector<double> rim_to_landmarks(const Rim& r, const std::vector<const std::vector<double>*>& landmark_dist) {
  std::vector<double> out;
  for (const std::vector<double>* d : landmark_dist) {
    double best = std::numeric_limits<double>::infinity();
    for (int v : r.v) best = std::min(best, (*d)[v]);
    out.push_back(best);
  }
  return out;
}

// Mean relative difference of two openings' distances to the landmarks and of their perimeters.
double rim_cost(const Rim& a, const std::vector<double>& a_lm, const Rim& b, const std::vector<double>& b_lm) {
  double s = std::min(std::abs(std::log(a.perimeter / b.perimeter)), kCap);
  for (std::size_t l = 0; l < a_lm.size(); ++l) s += rel(a_lm[l], b_lm[l]);
  return s / static_cast<double>(a_lm.size() + 1);
}

// The same for two rim vertices (their distances to every landmark).
double point_cost(const std::vector<const std::vector<double>*>& a, int va, const std::vector<const std::vector<double>*>& b,
                  int vb) {
  double s = 0;
  for (std::size_t l = 0; l < a.size(); ++l) s += rel((*a[l])[va], (*b[l])[vb]);
  return s / static_cast<double>(a.size());
}

// The vertex next to rim vertex v that lies on no rim, nearest to it (v itself if none): a
// feature on a rim makes the consistent method's final maps fail (ICT heads, 12 such features:
// "a face stays flipped after removing the path network's Steiner vertices" in step 6 after 574
// s; one ring in, step 6 completes in 13 s).
int step_inside(const TriMesh& mesh, const std::vector<char>& on_rim, int v) {
  int best = v;
  double best_d = std::numeric_limits<double>::infinity();
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (mesh.F(f, c) == v)
        for (int k = 1; k < 3; ++k) {
          const int u = mesh.F(f, (c + k) % 3);
          const double d = (mesh.V.row(u) - mesh.V.row(v)).squaredNorm();
          if (!on_rim[u] && (d < best_d || (d == best_d && u < best))) best_d = d, best = u;
        }
  return best;
}

}  // namespace

RimMatcher::RimMatcher(const std::vector<const TriMesh*>& meshes, const std::vector<double>& sqrt_area, RimOptions options)
    : meshes_(meshes), sqrt_area_(sqrt_area), o_(options) {
  const int nm = static_cast<int>(meshes_.size());
  for (int i = 0; i < nm; ++i) {
    rims_.push_back(rims_of(*meshes_[i], sqrt_area_[i]));
    on_rim_.emplace_back(meshes_[i]->V.rows(), 0);
    for (const Rim& r : rims_.back())
      for (int v : r.v) on_rim_.back()[v] = 1;
  }
}

std::vector<RimPoint> RimMatcher::match(const std::vector<std::vector<const std::vector<double>*>>& landmark_dist, int ref) {
  const int nm = static_cast<int>(meshes_.size());
  std::vector<RimPoint> out;
  if (nm < 1 || landmark_dist[ref].empty()) return out;
  for (int i = 0; i < nm; ++i)
    if (rims_[i].empty()) return out;
  std::vector<std::vector<std::vector<double>>> to_lm(nm);  // per member and opening
  for (int i = 0; i < nm; ++i)
    for (const Rim& r : rims_[i]) to_lm[i].push_back(rim_to_landmarks(r, landmark_dist[i]));
  const std::vector<Rim>& rr = rims_[ref];
  done_.resize(rr.size(), 0);
  for (std::size_t a = 0; a < rr.size(); ++a) {
    if (done_[a] || rr[a].elongation < o_.min_elongation) continue;
    // Per member: the matched opening and whether its ends run the other way.
    std::vector<int> match(nm, -1);
    std::vector<char> swapped(nm, 0);
    bool all = true;
    for (int i = 0; i < nm && all; ++i) {
      if (i == ref) {
        match[i] = static_cast<int>(a);
        continue;
      }
      const std::vector<Rim>& mr = rims_[i];
      int best = -1;
      double c1 = std::numeric_limits<double>::infinity(), c2 = c1;
      for (std::size_t b = 0; b < mr.size(); ++b) {
        const double c = rim_cost(rr[a], to_lm[ref][a], mr[b], to_lm[i][b]);
        if (c < c1) c2 = c1, c1 = c, best = static_cast<int>(b);
        else if (c < c2) c2 = c;
      }
      // Mutual: no other reference opening fits the member's better.
      bool mutual = best >= 0;
      for (std::size_t a2 = 0; a2 < rr.size() && mutual; ++a2)
        mutual = a2 == a || rim_cost(rr[a2], to_lm[ref][a2], mr[best], to_lm[i][best]) > c1;
      all = mutual && c1 <= o_.max_cost && c1 <= o_.margin * c2 && mr[best].elongation >= o_.min_elongation;
      if (!all) break;
      match[i] = best;
      const Rim& m = mr[best];
      const auto &R = landmark_dist[ref], &M = landmark_dist[i];
      const double same = point_cost(R, rr[a].v[rr[a].i], M, m.v[m.i]) + point_cost(R, rr[a].v[rr[a].j], M, m.v[m.j]);
      const double swap = point_cost(R, rr[a].v[rr[a].i], M, m.v[m.j]) + point_cost(R, rr[a].v[rr[a].j], M, m.v[m.i]);
      all = std::min(same, swap) <= o_.margin * std::max(same, swap);
      swapped[i] = swap < same;
    }
    if (!all) continue;
    done_[a] = 1;
    // Ends, then the middles of the side from the first end to the second and of the other side
    // (a swapped member's sides swap with its ends: the rim runs the same way round, so point k
    // of the reference is the member's point k ^ 1).
    bool middles = true;
    for (int i = 0; i < nm; ++i) middles = middles && rims_[i][match[i]].bulge >= kMinBulge;
    for (int k = 0; k < (middles ? 4 : 2); ++k) {
      RimPoint pt;
      pt.vertex.resize(nm);
      bool ok = true;
      for (int i = 0; i < nm; ++i) {
        const Rim& m = rims_[i][match[i]];
        const int at = swapped[i] ? k ^ 1 : k;
        const int pos[4] = {m.i, m.j, m.mid_ij, m.mid_ji};
        ok = ok && m.sharp[at];
        const int v = step_inside(*meshes_[i], on_rim_[i], m.v[pos[at]]);
        pt.vertex[i] = v;
        for (const std::vector<double>* d : landmark_dist[i]) ok = ok && (*d)[v] >= o_.min_separation;
        // Crowded: as close to a point taken before it (straight distance: the consistent
        // method fills the opening, so its paths may cross it). Four features around a small
        // eye, 0.03-0.04 sqrt(area) apart, made step 6 of a 3-head collection run for more than
        // 5 min (stopped); without the eyes' middles it took 3.3 s.
        const RowMat3d& V = meshes_[i]->V;
        for (const RimPoint& q : out) {
          ok = ok && q.vertex[i] != v;
          if (!q.crowded && (V.row(q.vertex[i]) - V.row(v)).norm() < o_.min_separation * sqrt_area_[i]) pt.crowded = true;
        }
      }
      if (ok) out.push_back(std::move(pt));
    }
  }
  return out;
}

}  // namespace spherekit::detail
