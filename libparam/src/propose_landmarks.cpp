// Landmark proposal: extremities by average geodesic distance, a combinatorial match of their
// pairwise geodesic distances, orientation of matched triples against mirror flips, further
// points by farthest-point sampling (see propose_landmarks.h for the method and references).
#include "spherekit/propose_landmarks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <string>

#include "detail/landmark_orientation.h"
#include "detail/rim_landmarks.h"
#include "spherekit/constrained_param.h"
#include "spherekit/geometry_image.h"
#include "spherekit/sphere_param.h"

namespace spherekit {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// At most this many fine peaks per member (a hand's fingertips, a head's ears and nose, ...).
constexpr int kMaxFinePeaks = 32;
// Rim points judge the extremities (see the rim stage) when there are at least this many; an
// extremity is an outlier beyond this multiple of the rim points' own disagreement, and never
// below the floor: five times the AGD maxima's placement noise between poses (kClose), so on a
// nearly isometric family, where the rim points agree almost exactly, ordinary noise is not
// taken for a misplaced extremity.
constexpr int kMinRimJudges = 4;
constexpr double kRimOutlier = 2.0, kRimOutlierFloor = 0.05;
// At most this many rounds of rim matching (each round may tell apart openings the previous
// ones' points can judge).
constexpr int kRimRounds = 4;

// Edge graph with Euclidean edge lengths (CSR), the surface's vertex normals and its area.
struct MeshGraph {
  std::vector<int> start, nbr;
  std::vector<double> len;
  RowMat3d N;
  double sqrt_area = 1;
  std::vector<double> varea;  // a third of the incident faces' areas, / total area
};

Result<MeshGraph> build_graph(const TriMesh& m, int index) {
  const int n = static_cast<int>(m.V.rows());
  const std::string who = "mesh " + std::to_string(index) + ": ";
  if (n < 4 || m.F.rows() < 4) return Result<MeshGraph>(ErrorCode::InvalidInput, who + "fewer than 4 vertices or faces");
  std::vector<std::pair<int, int>> edges;
  edges.reserve(m.F.rows() * 6);
  MeshGraph g;
  g.N = RowMat3d::Zero(n, 3);
  g.varea.assign(n, 0.0);
  double area = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = m.F(f, c), b = m.F(f, (c + 1) % 3);
      if (a < 0 || a >= n) return Result<MeshGraph>(ErrorCode::InvalidInput, who + "face " + std::to_string(f) + " has a vertex index out of range");
      edges.emplace_back(a, b);
      edges.emplace_back(b, a);
    }
    const Eigen::Vector3d e1 = m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0));
    const Eigen::Vector3d e2 = m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0));
    const Eigen::Vector3d cr = e1.cross(e2);  // area-weighted normal
    area += 0.5 * cr.norm();
    for (int c = 0; c < 3; ++c) {
      g.N.row(m.F(f, c)) += cr.transpose();
      g.varea[m.F(f, c)] += cr.norm() / 6;
    }
  }
  if (!(area > 0) || !std::isfinite(area)) return Result<MeshGraph>(ErrorCode::InvalidInput, who + "zero or non-finite area");
  g.sqrt_area = std::sqrt(area);
  for (double& a : g.varea) a /= area;
  for (int v = 0; v < n; ++v) {
    const double l = g.N.row(v).norm();
    if (l > 0) g.N.row(v) /= l;
  }
  // Shortcuts across each pair of adjacent faces (the two vertices opposite an edge): an edge
  // graph alone overestimates geodesics by up to ~8% depending on the connectivity, which
  // differs between members; the extra chords cut that metrication error severalfold.
  {
    std::vector<std::array<int, 3>> half;  // (min, max, opposite) per face corner's opposite edge
    half.reserve(m.F.rows() * 3);
    for (Eigen::Index f = 0; f < m.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) {
        const int a = m.F(f, (c + 1) % 3), b = m.F(f, (c + 2) % 3);
        half.push_back({std::min(a, b), std::max(a, b), m.F(f, c)});
      }
    std::sort(half.begin(), half.end());
    for (std::size_t i = 0; i + 1 < half.size(); ++i)
      if (half[i][0] == half[i + 1][0] && half[i][1] == half[i + 1][1] && half[i][2] != half[i + 1][2]) {
        edges.emplace_back(half[i][2], half[i + 1][2]);
        edges.emplace_back(half[i + 1][2], half[i][2]);
      }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  g.start.assign(n + 1, 0);
  for (const auto& e : edges) ++g.start[e.first + 1];
  for (int v = 0; v < n; ++v) g.start[v + 1] += g.start[v];
  g.nbr.resize(edges.size());
  g.len.resize(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    g.nbr[i] = edges[i].second;
    g.len[i] = (m.V.row(edges[i].first) - m.V.row(edges[i].second)).norm() / g.sqrt_area;  // normalised units
  }
  return g;
}

// Dijkstra from `src` in units of sqrt(area), stopping beyond `radius`; parents optional.
void dijkstra(const MeshGraph& g, int src, std::vector<double>& dist, std::vector<int>* parent = nullptr,
              double radius = kInf) {
  const int n = static_cast<int>(g.start.size()) - 1;
  dist.assign(n, kInf);
  if (parent) parent->assign(n, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  dist[src] = 0;
  heap.emplace(0.0, src);
  while (!heap.empty()) {
    const auto [d, v] = heap.top();
    heap.pop();
    if (d > dist[v]) continue;
    if (d > radius) break;
    for (int i = g.start[v]; i < g.start[v + 1]; ++i) {
      const int u = g.nbr[i];
      const double du = d + g.len[i];
      if (du < dist[u]) {
        dist[u] = du;
        if (parent) (*parent)[u] = v;
        heap.emplace(du, u);
      }
    }
  }
}

// One member's extremities with full distance fields and shortest-path trees from each.
struct Member {
  MeshGraph g;
  std::vector<double> agd;
  std::vector<int> ext;                        // extremity vertices, by decreasing AGD
  std::vector<std::vector<double>> dist;       // dist[i][v] from point i (extremities, then extras)
  std::vector<std::vector<int>> parent;
  std::vector<int> fine;        // AGD maxima of the finer discs (fine_radius), by decreasing AGD
  // Per extremity: another peak beyond its tip region (extremity_radius .. twice that) rises
  // within tip_drop of its AGD. Which of the two is the disc's maximum then changes with the
  // pose: a cat's head peaks at the nose on one member and at an ear tip on another (TOSCA cats,
  // 0.11-0.16 sqrt(area) apart), and no tip centre can reconcile points that far apart.
  std::vector<char> unstable;
};

void add_field(Member& m, int v) {
  m.dist.emplace_back();
  m.parent.emplace_back();
  dijkstra(m.g, v, m.dist.back(), &m.parent.back());
}

// Local maxima of the AGD, by decreasing AGD: 1-ring maxima kept when no vertex of their
// geodesic disc of `radius` has a larger AGD and no kept one lies in it (one point per limb
// tip, not one per bump); at most `max_count`, only those `accept` takes (if given).
std::vector<int> agd_peaks(const Member& m, double radius, int max_count,
                           const std::function<bool(int)>& accept = nullptr) {
  const int n = static_cast<int>(m.agd.size());
  std::vector<int> cand, out;
  for (int v = 0; v < n; ++v) {
    bool top = true;
    for (int i = m.g.start[v]; i < m.g.start[v + 1] && top; ++i) top = m.agd[m.g.nbr[i]] <= m.agd[v];
    if (top && (!accept || accept(v))) cand.push_back(v);
  }
  std::sort(cand.begin(), cand.end(), [&](int a, int b) { return m.agd[a] != m.agd[b] ? m.agd[a] > m.agd[b] : a < b; });
  std::vector<double> d;
  for (int v : cand) {
    if (static_cast<int>(out.size()) >= max_count) break;
    dijkstra(m.g, v, d, nullptr, radius);
    bool ok = true;
    for (int u = 0; u < n && ok; ++u)
      if (d[u] <= radius) ok = m.agd[u] <= m.agd[v];
    for (int e : out) ok = ok && !(d[e] <= radius);
    if (ok) out.push_back(v);
  }
  return out;
}

Status find_extremities(const TriMesh& mesh, int index, const ProposeLandmarksOptions& o, Member& m) {
  const int n = static_cast<int>(mesh.V.rows());
  // Farthest-point sources (deterministic start: the vertex farthest from vertex 0), AGD as
  // the mean distance to them: the sources cover the surface evenly, so the mean approximates
  // the surface integral of the distance (the AGD of Hilaga et al. 2001 / Kim et al. 2011).
  std::vector<double> d, mind(n, kInf);
  dijkstra(m.g, 0, d);
  int s = static_cast<int>(std::max_element(d.begin(), d.end()) - d.begin());
  if (!std::isfinite(*std::max_element(d.begin(), d.end())))
    return Status(ErrorCode::InvalidInput, "mesh " + std::to_string(index) + ": not one connected component");
  m.agd.assign(n, 0.0);
  for (int k = 0; k < o.agd_sources; ++k) {
    dijkstra(m.g, s, d);
    for (int v = 0; v < n; ++v) {
      m.agd[v] += d[v] / o.agd_sources;
      mind[v] = std::min(mind[v], d[v]);
    }
    s = static_cast<int>(std::max_element(mind.begin(), mind.end()) - mind.begin());
  }
  m.ext = agd_peaks(m, o.extremity_radius, o.max_extremities);
  for (int e : m.ext) add_field(m, e);
  // Rival peaks (see `unstable`): every AGD maximum of a disc of fine_radius.
  if (o.fine_radius > 0) {
    m.fine = agd_peaks(m, o.fine_radius, kMaxFinePeaks);
    m.unstable.assign(m.ext.size(), 0);
    for (std::size_t j = 0; j < m.ext.size(); ++j)
      for (int p : m.fine) {
        if (std::find(m.ext.begin(), m.ext.end(), p) != m.ext.end()) continue;  // an extremity of its own
        const double d = m.dist[j][p];
        if (d > o.extremity_radius && d <= 2 * o.extremity_radius && m.agd[p] >= m.agd[m.ext[j]] - o.tip_drop)
          m.unstable[j] = 1;
      }
  }
  return Status::ok_status();
}

// The centre of an extremity's tip region: the vertices within `radius` of it whose AGD is
// within `drop` of its own (a hand's fingertips: nearly equal peaks whose order changes from
// pose to pose, FAUST 027 and 041 peak at the little finger, 000 and 013 at the middle one).
// The region's centroid, each vertex weighted by its area and by how far its AGD rises above
// the region's floor (so the centre moves smoothly as the AGD estimate's noise moves the
// floor), and the region's vertex nearest to it.
int tip_centre(const TriMesh& mesh, const Member& m, int e, const std::vector<double>& dist, double radius,
               double drop) {
  const double floor = m.agd[e] - drop;
  std::vector<int> region;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double wsum = 0;
  for (int v = 0; v < static_cast<int>(m.agd.size()); ++v)
    if (dist[v] < radius && m.agd[v] > floor) {
      const double w = m.g.varea[v] * (m.agd[v] - floor);
      c += w * mesh.V.row(v).transpose();
      wsum += w;
      region.push_back(v);
    }
  if (!(wsum > 0)) return e;
  c /= wsum;
  int best = e;
  double best_d = kInf;
  for (int v : region) {
    const double d = (mesh.V.row(v).transpose() - c).squaredNorm();
    if (d < best_d) best_d = d, best = v;
  }
  return best;
}

// Orientation of every triple (i<j<k) of a member's points: seen from a centre vertex c, the
// directions towards the three points turn counter-clockwise about the outward
// normal (> 0) or clockwise (< 0). The value is the signed area of the triangle of the three
// unit directions, so nearly coincident directions weigh little. Directions are taken where
// the shortest path from the centre leaves a disc of radius 0.1 sqrt(area) (beyond the edge
// graph's zig-zag, well inside a limb's length). Turning at the points themselves fails: every
// path from a limb tip leaves along the limb. The centre must be the same surface point on
// every member (seen from the antipode of a point, every cyclic order reverses): the
// reference's AGD minimum, located on a member through the assignment being judged.
std::vector<double> triple_turns(const TriMesh& mesh, const Member& m, const std::vector<int>& pts, int c) {
  constexpr double r = 0.1;
  std::vector<double> d;
  std::vector<int> parent;
  dijkstra(m.g, c, d, &parent);
  const Eigen::Vector3d p = mesh.V.row(c), n = m.g.N.row(c);
  const int k = static_cast<int>(pts.size());
  std::vector<Eigen::Vector3d> dir(k);
  for (int i = 0; i < k; ++i) {
    int v = pts[i];
    while (parent[v] >= 0 && d[v] > r) v = parent[v];
    Eigen::Vector3d t = mesh.V.row(v).transpose() - p;
    t -= n * n.dot(t);
    dir[i] = t.norm() > 0 ? Eigen::Vector3d(t.normalized()) : Eigen::Vector3d::Zero();
  }
  std::vector<double> t(static_cast<std::size_t>(k) * k * k, 0.0);
  for (int i = 0; i < k; ++i)
    for (int j = i + 1; j < k; ++j)
      for (int l = j + 1; l < k; ++l)
        t[(static_cast<std::size_t>(i) * k + j) * k + l] = 0.5 * (dir[j] - dir[i]).cross(dir[l] - dir[i]).dot(n);
  return t;
}

struct Assignment {
  double cost = 0;
  std::vector<int> to;  // reference extremity -> member extremity index or -1
};

// |log ratio| beyond this (a factor 1.5) a pair of distances is simply "wrong".
constexpr double kPairCap = 0.4;
// Weight of the disc-area profile in a point's unary cost, and what an unmatched point pays
// instead (the most a matched one can: the profile's and the AGD's caps).
constexpr double kProfileWeight = 2.0;
constexpr double kUnaryMiss = (kProfileWeight + 1.0) * kPairCap;

// Branch and bound over partial injective assignments. A pair of matched points costs the
// relative difference of their distances, min(|log(d_ref / d_member)|, cap): the poses of a
// family are only nearly isometric, and a limb that is bent or stretched changes its long
// distances by more than its short ones in absolute terms but by about the same factor
// (FAUST bodies: hand-to-hand geodesics differ by 40 % between poses of one family). A pair
// with an unmatched point costs cap, so leaving a point out is never cheaper than a bad match
// and a missing extremity (an ear too small to be one on some member) does not force a wrong
// one. Each matched point also pays its unary cost U[i][j] (its own isometry-invariant
// description; an unmatched one pays kUnaryMiss). Keeps the `keep` cheapest complete assignments.
class Matcher {
 public:
  Matcher(const std::vector<std::vector<double>>& R, const std::vector<std::vector<double>>& M,
          const std::vector<std::vector<double>>& U, int keep)
      : R_(R), M_(M), U_(U), keep_(keep), kr_(static_cast<int>(R.size())), km_(static_cast<int>(M.size())) {}
  std::vector<Assignment> run() {
    cur_.assign(kr_, -1);
    used_.assign(km_, false);
    recurse(0, 0.0);
    std::sort(best_.begin(), best_.end(), [](const Assignment& a, const Assignment& b) {
      return a.cost != b.cost ? a.cost < b.cost : a.to < b.to;
    });
    return best_;
  }
  static constexpr double kCap = kPairCap;
  static double pair_cost(double a, double b) {
    return a > 0 && b > 0 ? std::min(std::abs(std::log(a / b)), kCap) : kCap;
  }

 private:
  double bound() const { return static_cast<int>(best_.size()) < keep_ ? kInf : best_.back().cost; }
  void recurse(int i, double cost) {
    if (cost >= bound() || ++nodes_ > 2000000) return;  // node cap: enough for 16 x 16 with pruning
    if (i == kr_) {
      best_.push_back({cost, cur_});
      std::sort(best_.begin(), best_.end(), [](const Assignment& a, const Assignment& b) { return a.cost < b.cost; });
      if (static_cast<int>(best_.size()) > keep_) best_.pop_back();
      return;
    }
    // Options ordered by their added cost, so good assignments come first and prune the rest.
    std::vector<std::pair<double, int>> opts;
    for (int j = -1; j < km_; ++j) {
      if (j >= 0 && used_[j]) continue;
      double add = j < 0 ? kUnaryMiss : U_[i][j];
      for (int p = 0; p < i; ++p) add += (j < 0 || cur_[p] < 0) ? kCap : pair_cost(R_[i][p], M_[j][cur_[p]]);
      opts.emplace_back(add, j);
    }
    std::sort(opts.begin(), opts.end());
    for (const auto& [add, j] : opts) {
      cur_[i] = j;
      if (j >= 0) used_[j] = true;
      recurse(i + 1, cost + add);
      if (j >= 0) used_[j] = false;
      cur_[i] = -1;
    }
  }
  const std::vector<std::vector<double>>& R_;
  const std::vector<std::vector<double>>& M_;
  const std::vector<std::vector<double>>& U_;
  int keep_, kr_, km_;
  long nodes_ = 0;
  std::vector<int> cur_;
  std::vector<bool> used_;
  std::vector<Assignment> best_;
};

std::vector<std::vector<double>> pair_distances(const Member& m) {
  const int k = static_cast<int>(m.ext.size());
  std::vector<std::vector<double>> D(k, std::vector<double>(k, 0.0));
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) D[i][j] = m.dist[i][m.ext[j]];
  return D;
}

// Per extremity: the share of the surface within geodesic radius r of it, for a few radii: a
// thin limb tip, a paw and a head differ in how fast their discs fill even where their
// distances to the other extremities agree (a cat's head and front paws form a near
// equilateral triangle). Isometry invariant, like the distances.
std::vector<std::vector<double>> disc_profiles(const Member& m) {
  static constexpr double kRadii[] = {0.05, 0.1, 0.15, 0.2, 0.3, 0.4};  // x sqrt(area)
  std::vector<std::vector<double>> out;
  for (std::size_t e = 0; e < m.ext.size(); ++e) {
    std::vector<double> a(std::size(kRadii), 0.0);
    for (std::size_t v = 0; v < m.g.varea.size(); ++v)
      for (std::size_t r = 0; r < std::size(kRadii); ++r)
        if (m.dist[e][v] < kRadii[r]) a[r] += m.g.varea[v];
    out.push_back(a);
  }
  return out;
}

// Unary costs U[i][j] of matching the reference's extremity i to the member's j: relative
// differences of the disc profiles and of the AGD values, each capped like a pair.
std::vector<std::vector<double>> unary_costs(const Member& r, const Member& m) {
  const auto pr = disc_profiles(r), pm = disc_profiles(m);
  std::vector<std::vector<double>> U(r.ext.size(), std::vector<double>(m.ext.size(), 0.0));
  for (std::size_t i = 0; i < r.ext.size(); ++i)
    for (std::size_t j = 0; j < m.ext.size(); ++j) {
      double d = 0;
      for (std::size_t k = 0; k < pr[i].size(); ++k) d += Matcher::pair_cost(pr[i][k], pm[j][k]);
      U[i][j] = kProfileWeight * d / static_cast<double>(pr[i].size()) + Matcher::pair_cost(r.agd[r.ext[i]], m.agd[m.ext[j]]);
    }
  return U;
}

// Agreement -1..1 of the turns of the matched triples of the reference and the member.
double orientation_agreement(const std::vector<double>& tr, const std::vector<double>& tm, int kr, int km,
                             const std::vector<int>& to) {
  double num = 0, den = 0;
  for (int i = 0; i < kr; ++i)
    for (int j = i + 1; j < kr; ++j)
      for (int l = j + 1; l < kr; ++l) {
        if (to[i] < 0 || to[j] < 0 || to[l] < 0) continue;
        // The member's triple in the reference's cyclic order: sort its indices, count the parity.
        int a[3] = {to[i], to[j], to[l]};
        int swaps = 0;
        for (int x = 0; x < 3; ++x)
          for (int y = 0; y < 2 - x; ++y)
            if (a[y] > a[y + 1]) std::swap(a[y], a[y + 1]), ++swaps;
        const double wm = tm[(static_cast<std::size_t>(a[0]) * km + a[1]) * km + a[2]] * (swaps % 2 ? -1 : 1);
        const double wr = tr[(static_cast<std::size_t>(i) * kr + j) * kr + l];
        num += wr * wm;
        den += std::abs(wr * wm);
      }
  return den > 0 ? num / den : 0.0;
}

// An assignment with the orientation agreement of its matched triples.
struct Candidate {
  Assignment a;
  double turn = 0;
};

struct MatchAll {
  std::vector<LandmarkMemberMatch> members;
  std::vector<std::vector<int>> to;  // per member: reference extremity -> member extremity (-1: none)
  std::vector<std::vector<Candidate>> cands;  // per member: the cheapest assignments, by cost
  double total = 0;                  // sum of the members' mean costs
  // Per reference extremity: unstable (see unstable_extremities; empty when not looked for).
  std::vector<char> unstable;
  // Set by the sphere test: per member, the sphere map of its chosen assignment (the
  // reference's own unconstrained map; empty where none was made), made with the stable
  // extremities only where some are unstable.
  std::vector<RowMat3d> maps;
};

// Two assignments are "about as good" when their mean pair error differs by less than this
// (relative distance error, the size of the AGD maxima's placement noise between poses).
constexpr double kClose = 0.01;
// The assignments the sphere test compares: within this mean pair error of the cheapest (the
// mirror twins of a near-symmetric shape and their variants; on TOSCA cats with six
// extremities the right one was the 8th cheapest, 0.032 above the cheapest), at most
// kSphereCandidates of them (each costs one constrained map of the member).
constexpr double kSphereWindow = 0.05;
constexpr int kSphereCandidates = 8;
// Weight of the log efficiency ratio beside the signal correlation. The decisions on the
// shared cats and FAUST bodies were the same for every weight from 0.2 to 0.5 (at 1 the
// efficiency overrules the signal on FAUST, where a turned-round body costs little stretch).
constexpr double kEfficiencyWeight = 0.35;
// Weight of the mean pair error above the cheapest candidate's: 0.05 (the window's edge)
// costs 0.15 of correlation.
constexpr double kCostWeight = 3.0;
// Where the signal is too weak to decide between its best two (best raw correlation below
// kSphereInformative), a candidate whose constrained map is at least this many times as
// efficient as every other candidate's is kept instead of the turns' pick: the swapped limbs
// of a near-symmetric body twist the member's map. TOSCA cat2 (reference cat9, six
// extremities): best correlations 0.25 (swapped limbs) and 0.15 (right), efficiencies 0.286
// and 0.361, the right one 1.15x every other; the turns had picked the swap, and with its
// ears matched right in the fine stage that member's map was twisted (correspondence 0.127
// against 0.039 with the given files). Where the signal is strong it is not consulted: on
// FAUST a turned-round body costs little stretch (0.182 against the right 0.164 on one
// member), and on generated hands five close fingertips scatter the efficiencies.
constexpr double kEfficiencyDecisive = 1.1;
// Agreements (correlations) closer than this do not decide.
constexpr double kSphereMargin = 0.05;
// A best raw correlation below this says the constrained maps do not carry the shape at all
// (the 1.5x-stretched biped below: 0.08-0.2 for every candidate), so the test rules nothing
// out; the signed signal agrees 0.3-0.9 where it works (cats, FAUST, ICT, warped quadrupeds).
constexpr double kSphereInformative = 0.3;
// Below this best raw correlation the signal carries no shape at all, and even a clear winner
// decides nothing (warped woody, a flat figure: 0.00 and -0.43). A weak but real signal still
// decides where one candidate stands out (TOSCA cat2: 0.22, right where the turns were wrong).
constexpr double kSphereSignal = 0.1;
// A member whose left/right the sphere test settled against the intrinsically cheapest
// assignment is flagged when the winner agrees less than this: the test then overrules the
// distances on a signal that is not carried well. Right overrulings agreed 0.61-0.88 (FAUST,
// ICT heads, generated creatures); the one wrong among 20 generated families (two limbs
// swapped, 1.29 sqrt(area) off) agreed 0.38 where its siblings agreed 0.73-0.79, as a
// right TOSCA cat overruled at 0.37 (flagged anyway, by the margin).
constexpr double kSphereConfident = 0.5;
// Further points (trilateration): looked for among this many of the fit's best local minima;
// relative distance differences log((d + s) / (t + s)) with s = kRelativeSoftening (x
// sqrt(area): distances much shorter than that are as uncertain as the landmarks' placement);
// the fit's noise floor per distance (5%: the departure from isometry of posed families), and
// the weight of a candidate's log fit ratio (above that floor) against its turns' projection
// (the turns of at most kTurnLandmarks landmarks, the nearest).
constexpr std::size_t kTrilaterationCandidates = 8;
constexpr std::size_t kTurnLandmarks = 12;
constexpr double kRelativeSoftening = 0.05;
constexpr double kRelativeNoise = 0.05;
constexpr double kFitWeight = 0.5;

// Every member matched to the reference `ref` (which has at least 3 extremities).
MatchAll match_all(const std::vector<TriMesh>& meshes, const std::vector<Member>& mem, int ref) {
  const int nm = static_cast<int>(meshes.size());
  const Member& rm = mem[ref];
  const int kr = static_cast<int>(rm.ext.size());
  std::vector<int> ref_fields(kr);
  std::iota(ref_fields.begin(), ref_fields.end(), 0);
  const auto Rd = pair_distances(rm);
  const int rc = static_cast<int>(std::min_element(rm.agd.begin(), rm.agd.end()) - rm.agd.begin());
  const auto Rt = triple_turns(meshes[ref], rm, rm.ext, rc);
  const double pairs = kr * (kr + 1) / 2.0;  // the pairs and the unary terms

  MatchAll ma;
  ma.members.resize(nm);
  ma.to.assign(nm, {});
  ma.cands.assign(nm, {});
  ma.to[ref] = ref_fields;
  for (int i = 0; i < nm; ++i) {
    if (i == ref) continue;
    const Member& m = mem[i];
    const int km = static_cast<int>(m.ext.size());
    const auto Md = pair_distances(m);
    const auto U = unary_costs(rm, m);
    const auto found = Matcher(Rd, Md, U, 64).run();
    // The orientation of each assignment's matched triples (seen from the reference's centre
    // located on the member through that assignment), for the assignments the choice below
    // reads: those in the sphere test's window and the cheapest of each orientation.
    std::vector<Candidate>& cands = ma.cands[i];
    std::vector<std::pair<int, std::vector<double>>> turns_by_centre;  // a centre's turns, computed once
    bool seen_pos = false, seen_neg = false;
    for (const auto& a : found) {
      if (seen_pos && seen_neg && a.cost > found.front().cost + kSphereWindow * pairs) break;
      // The reference's centre on this member: the vertex whose distances to the assigned
      // extremities best fit the reference centre's (geodesic trilateration).
      int c = 0;
      double best = kInf;
      for (int v = 0; v < static_cast<int>(m.agd.size()); ++v) {
        double e = 0;
        for (int q = 0; q < kr && e < best; ++q)
          if (a.to[q] >= 0) e += std::pow(m.dist[a.to[q]][v] - rm.dist[q][rc], 2);
        if (e < best) best = e, c = v;
      }
      auto it = std::find_if(turns_by_centre.begin(), turns_by_centre.end(), [&](const auto& t) { return t.first == c; });
      if (it == turns_by_centre.end()) {
        turns_by_centre.emplace_back(c, triple_turns(meshes[i], m, m.ext, c));
        it = turns_by_centre.end() - 1;
      }
      const double ag = orientation_agreement(Rt, it->second, kr, km, a.to);
      (ag >= 0 ? seen_pos : seen_neg) = true;
      cands.push_back({a, ag});
    }
    // The choice by turns (kept where no sphere maps can be made): the cheapest assignment
    // turning each way; a shape and its mirror image have the same distances, so for a
    // (near-)symmetric shape both are among the cheapest.
    const Candidate* pos = nullptr;
    const Candidate* neg = nullptr;
    for (const auto& c : cands) {
      if (c.turn >= 0 && !pos) pos = &c;
      if (c.turn < 0 && !neg) neg = &c;
    }
    LandmarkMemberMatch& mm = ma.members[i];
    const double close = kClose * pairs;
    const Candidate* pick = pos ? pos : neg;
    if (pos && neg) {
      if (pos->a.cost <= neg->a.cost + close) {
        pick = pos;
        mm.mirror_resolved = neg->a.cost < pos->a.cost;
      } else {
        pick = neg;  // intrinsically clearly best, but it turns the other way: a mirrored member
        mm.mirrored = true;
      }
      mm.mirrored_cost = (pick == pos ? neg->a.cost : pos->a.cost) / pairs;
    } else if (neg) {
      mm.mirrored = true;
    }
    mm.cost = pick->a.cost / pairs;
    mm.orientation_agreement = pick->turn;
    // Orientation too weak to decide (flat or degenerate triples), with a near-equal rival.
    const double other = pick == pos ? (neg ? neg->a.cost : kInf) : (pos ? pos->a.cost : kInf);
    if (std::abs(mm.orientation_agreement) < 0.3 && other - pick->a.cost < close) mm.mirror_ambiguous = true;
    if (mm.mirrored && other - pick->a.cost < close) mm.mirror_ambiguous = true;
    ma.to[i] = pick->a.to;
    ma.total += mm.cost;
  }
  return ma;
}

// The reference extremities whose position is unstable (Member::unstable) on the reference or
// on any member they are assigned to by a candidate within the sphere test's window: such a
// point sits at a nose on one member and at an ear tip on another. They are neither proposed
// nor pinned in the maps the finer peaks are carried through (one pinned at a nose on the
// reference and at an ear tip on a member drags the whole head round). None are marked when
// fewer than 3 stable ones would remain.
void unstable_extremities(const std::vector<Member>& mem, int ref, MatchAll& ma) {
  const int nm = static_cast<int>(mem.size());
  const Member& rm = mem[ref];
  const int kr = static_cast<int>(rm.ext.size());
  const double pairs = kr * (kr + 1) / 2.0;
  ma.unstable.assign(kr, 0);
  if (rm.unstable.empty()) return;
  for (int q = 0; q < kr; ++q) ma.unstable[q] = rm.unstable[q];
  for (int i = 0; i < nm; ++i) {
    if (i == ref || ma.cands[i].empty()) continue;
    const double limit = ma.cands[i].front().a.cost + kSphereWindow * pairs;
    for (const Candidate& c : ma.cands[i]) {
      if (c.a.cost > limit) break;
      for (int q = 0; q < kr; ++q)
        if (c.a.to[q] >= 0 && mem[i].unstable[c.a.to[q]]) ma.unstable[q] = 1;
    }
  }
  int stable = 0;
  for (int q = 0; q < kr; ++q) {
    bool everywhere = !ma.unstable[q];
    for (int i = 0; i < nm; ++i) everywhere = everywhere && ma.to[i][q] >= 0;
    stable += everywhere;
  }
  if (stable < 3) ma.unstable.assign(kr, 0);
}

// A member's constrained map with its assigned extremities (reference extremity q -> member
// extremity to[q]) where the reference's map S_ref puts the reference's, except those marked
// in `skip` (empty: none).
Result<ConstrainedParamResult> pinned_sphere_map(const TriMesh& mesh, const Member& m, const Member& rm,
                                            const RowMat3d& S_ref, const std::vector<int>& to,
                                            const std::vector<char>& skip, const SphereParamOptions& so) {
  std::vector<int> fv;
  std::vector<Eigen::Vector3d> targets;
  for (std::size_t q = 0; q < to.size(); ++q)
    if (to[q] >= 0 && (skip.empty() || !skip[q])) {
      fv.push_back(m.ext[to[q]]);
      targets.push_back(S_ref.row(rm.ext[q]).transpose());
    }
  ConstrainedParamOptions co;
  co.sphere = so;
  return parameterize_sphere_constrained(mesh, fv, targets, co);
}

// The sphere test (detail/landmark_orientation.h): the reference's unconstrained map places
// its extremities; every assignment in a member's window becomes a constrained map of the
// member with its matched extremities there, and the one whose correspondence carries the
// reference's signed shape signal best onto the member's is kept. Members whose maps cannot
// be made (not genus 0, a failed network) keep the choice by turns. Returns false when
// cancelled.
bool resolve_by_sphere(const std::vector<TriMesh>& meshes, const std::vector<Member>& mem, int ref,
                       const ProposeLandmarksOptions& o, MatchAll& ma, const ProgressFn& progress) {
  constexpr double kSignalRadius = 0.15;  // x sqrt(area): face vs back of a head, toes vs heels
  const int nm = static_cast<int>(meshes.size());
  const Member& rm = mem[ref];
  const int kr = static_cast<int>(rm.ext.size());
  const double pairs = kr * (kr + 1) / 2.0;
  SphereParamOptions so = collection_sphere_options();
  so.effort = o.sphere_effort;
  so.threads = o.threads;
  auto base = parameterize_sphere(meshes[ref], so);
  if (!base.ok() || base->flipped_faces != 0) return true;
  const RowMat3d& S_ref = base->map.S;
  const std::vector<double> h_ref = detail::smoothed_normal_offset(meshes[ref], kSignalRadius);
  auto pinned_map = [&](int i, const std::vector<int>& to) {
    return pinned_sphere_map(meshes[i], mem[i], rm, S_ref, to, {}, so);
  };
  ma.maps.assign(nm, RowMat3d());
  ma.maps[ref] = S_ref;
  for (int i = 0; i < nm; ++i) {
    if (i == ref || ma.cands[i].empty()) continue;
    const std::vector<Candidate>& cands = ma.cands[i];
    const std::vector<double> h = detail::smoothed_normal_offset(meshes[i], kSignalRadius);
    const double limit = cands.front().a.cost + kSphereWindow * pairs;
    std::vector<std::pair<double, int>> scored;  // (agreement, candidate)
    std::vector<double> effs;
    std::vector<RowMat3d> maps;
    for (int c = 0; c < static_cast<int>(cands.size()) && static_cast<int>(scored.size()) < kSphereCandidates; ++c) {
      if (cands[c].a.cost > limit) break;
      auto map = pinned_map(i, cands[c].a.to);
      double agree = -2, eff = 0;
      if (map.ok() && map->flipped_faces == 0) {
        agree = detail::correspondence_agreement(meshes[ref], S_ref, h_ref, meshes[i], map->map.S, h);
        eff = map->efficiency;
        maps.push_back(std::move(map->map.S));
      } else {
        maps.emplace_back();
      }
      scored.emplace_back(agree, c);
      effs.push_back(eff);
      if (!report_progress(progress, "landmarks", i, 0.9)) return false;
    }
    // A swapped assignment also costs the member's map stretch: the constraints lay the limbs
    // out the other way round from where the member's own shape puts them (as the reference's
    // unconstrained map does for the reference). Both signals add: the correlation, and half
    // the log of the efficiency relative to the best candidate's.
    // The efficiency term is bounded (a map at 60 % of the best candidate's efficiency is
    // simply "worse"): with many features close together (a hand's five fingertips) the
    // constrained maps' efficiencies scatter over orders of magnitude and would overrule
    // everything else. The intrinsic cost keeps its say too: a candidate pays for how much
    // its distances disagree beyond the cheapest's.
    const double best_eff = *std::max_element(effs.begin(), effs.end());
    double raw_top = -2;
    for (const auto& sc : scored) raw_top = std::max(raw_top, sc.first);
    for (std::size_t k = 0; k < scored.size(); ++k)
      if (scored[k].first > -2)
        scored[k].first += kEfficiencyWeight * std::max(std::log(std::max(effs[k], 1e-12) / best_eff), -0.5) -
                           kCostWeight * (cands[scored[k].second].a.cost - cands.front().a.cost) / pairs;
    std::sort(scored.begin(), scored.end(), [](const auto& x, const auto& y) {
      return x.first != y.first ? x.first > y.first : x.second < y.second;
    });
    // The map of the assignment finally chosen (the turns' pick where the test cannot decide).
    auto keep_map = [&] {
      for (std::size_t k = 0; k < maps.size(); ++k)
        if (cands[k].a.to == ma.to[i]) ma.maps[i] = std::move(maps[k]);
    };
    // The member takes candidate `pick` instead of the choice by turns.
    auto adopt = [&](const Candidate& pick) {
      LandmarkMemberMatch& mm = ma.members[i];
      ma.total += pick.a.cost / pairs - mm.cost;
      mm.cost = pick.a.cost / pairs;
      mm.orientation_agreement = pick.turn;
      // If the cheapest assignment turns the other way from the pick (a turned-round body) and
      // is clearly cheaper, the member is a mirror image (intrinsically best only reflected);
      // if not, the shape is (nearly) symmetric and its left/right was settled by the sphere
      // test. A cheapest assignment turning the same way is simply another match the test
      // ruled out (TOSCA cat2 was called mirrored for one).
      mm.mirrored = pick.a.cost - cands.front().a.cost > kClose * pairs && (cands.front().turn < 0) != (pick.turn < 0);
      ma.to[i] = pick.a.to;
    };
    if (scored.empty() || scored.front().first <= -2) continue;  // no map: the choice by turns stands
    // Two candidates the signal cannot tell apart: flagged, not guessed. The choice by turns
    // stands (a generated biped warped by a 1.5x anisotropic stretch: correlations 0.08 and
    // 0.07, where the turns had it right) unless the test clearly ruled it out, and then the
    // cheapest of the test's best few is kept (warped quadruped with holes: the turns' pick
    // agreed 0.43, the best two 0.64 and 0.60; per detail::ambiguous_sphere_choice).
    if (scored.size() > 1 && scored.front().first - scored[1].first < kSphereMargin) {
      LandmarkMemberMatch& mm = ma.members[i];
      mm.sphere_checked = true;
      mm.sphere_agreement = scored.front().first;
      mm.sphere_runner_up = scored[1].first;
      mm.mirror_ambiguous = true;
      int turns_c = -1;
      for (const auto& sc : scored)
        if (cands[sc.second].a.to == ma.to[i]) turns_c = sc.second;
      const int keep = detail::ambiguous_sphere_choice(scored, turns_c, raw_top, kSphereMargin, kSphereInformative,
                                                       effs, kEfficiencyDecisive);
      if (keep >= 0 && keep != turns_c) {
        adopt(cands[keep]);
        mm.mirror_resolved = false;
      }
      keep_map();
      continue;
    }
    // A clear winner of a signal that carries no shape at all (its best raw correlation below
    // kSphereSignal) is no decision either: on a flat figure (woody, warped) the signal is the
    // warp's own bending, and best correlations of 0.00 and -0.43 had overruled turns that were
    // right. The choice by turns stands (flagged by match_all where the turns are weak too).
    if (raw_top < kSphereSignal) {
      LandmarkMemberMatch& mm = ma.members[i];
      mm.sphere_agreement = scored.front().first;
      mm.sphere_runner_up = scored.size() > 1 ? scored[1].first : -2;
      keep_map();
      continue;
    }
    adopt(cands[scored.front().second]);
    LandmarkMemberMatch& mm = ma.members[i];
    mm.sphere_checked = true;
    mm.sphere_agreement = scored.front().first;
    mm.sphere_runner_up = scored.size() > 1 ? scored[1].first : -2;
    mm.mirror_resolved = !mm.mirrored && scored.front().second != 0;
    mm.mirrored_cost = scored.size() > 1 ? cands[scored[1].second].a.cost / pairs : -1;
    // The pick stands (the weak signal still chose it), but it is a guess: flagged.
    mm.mirror_ambiguous = mm.mirror_resolved && mm.sphere_agreement < kSphereConfident;
    keep_map();
  }
  return true;
}

// The maps the fine stage carries points through, made again without the extremities in
// `unpinned` (unstable or mismatched ones; the sphere test keeps all pins: without the head, a
// cat's left/right is no longer seen by the signal, but one pinned at a nose on the reference
// and at an ear tip on a member drags the whole head round). Returns false when cancelled.
bool repin_maps(const std::vector<TriMesh>& meshes, const std::vector<Member>& mem, int ref,
                const ProposeLandmarksOptions& o, const std::vector<char>& unpinned, MatchAll& ma,
                const ProgressFn& progress) {
  if (std::find(unpinned.begin(), unpinned.end(), 1) == unpinned.end()) return true;
  if (ma.maps.size() != meshes.size() || ma.maps[ref].rows() == 0) return true;
  SphereParamOptions so = collection_sphere_options();
  so.effort = o.sphere_effort;
  so.threads = o.threads;
  const RowMat3d& S_ref = ma.maps[ref];
  for (int i = 0; i < static_cast<int>(meshes.size()); ++i) {
    if (i == ref || ma.maps[i].rows() == 0) continue;
    auto map = pinned_sphere_map(meshes[i], mem[i], mem[ref], S_ref, ma.to[i], unpinned, so);
    if (map.ok() && map->flipped_faces == 0)
      ma.maps[i] = std::move(map->map.S);
    else
      ma.maps[i] = RowMat3d();
    if (!report_progress(progress, "landmarks", i, 0.9)) return false;
  }
  return true;
}

// The upper median of a non-empty list (the mismatch rules below).
double median(std::vector<double> v) {
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// An extremity whose distances to the other kept ones are wrong on some member far beyond
// that member's other extremities' (the median |log(d_ref / d_member)| of its pairs above
// kMismatchFactor times the median over all the member's pairs, and above kMismatchFloor) was
// matched to another feature: the branch and bound matches a point rather than leave it out
// when every pair of it costs about the cap either way and its disc profile fits (a warped
// cow whose tail is no extremity on one member: its tail went to a peak beside a front leg,
// 1.04 against a member median of 0.16). It is left out on every member, worst first, while
// more than 3 remain (marked in `dropped`). Returns how many were left out.
// Right matches measured (generated families of 11 shapes, FAUST, TOSCA cats, ICT heads; also
// after a mismatch was left out, when the member's median drops): at most 4.2 times the
// member's median; the mismatches 6.4 (the cow) and 11 times (the test's moved tail).
constexpr double kMismatchFactor = 5.0;
constexpr double kMismatchFloor = 0.2;  // a factor 1.22: below it, distances are only posed

int drop_mismatched(const std::vector<Member>& mem, int ref, const std::vector<std::vector<int>>& to,
                    std::vector<int>& keep, std::vector<char>& dropped) {
  const Member& rm = mem[ref];
  int count = 0;
  while (keep.size() > 3) {
    int worst = -1;
    double worst_err = 0;
    for (int i = 0; i < static_cast<int>(mem.size()); ++i) {
      if (i == ref) continue;
      const Member& m = mem[i];
      std::vector<double> all, per(keep.size());
      for (std::size_t a = 0; a < keep.size(); ++a) {
        std::vector<double> row;
        for (std::size_t b = 0; b < keep.size(); ++b) {
          if (a == b) continue;
          const double dr = rm.dist[keep[a]][rm.ext[keep[b]]];
          const double dm = m.dist[to[i][keep[a]]][m.ext[to[i][keep[b]]]];
          const double e = std::abs(std::log(std::max(dr, 1e-9) / std::max(dm, 1e-9)));
          row.push_back(e);
          if (a < b) all.push_back(e);
        }
        per[a] = median(std::move(row));
      }
      const double typical = median(std::move(all));
      for (std::size_t a = 0; a < keep.size(); ++a)
        if (per[a] > kMismatchFloor && per[a] > kMismatchFactor * typical && per[a] > worst_err)
          worst_err = per[a], worst = static_cast<int>(a);
    }
    if (worst < 0) break;
    dropped[keep[worst]] = 1;
    keep.erase(keep.begin() + worst);
    ++count;
  }
  return count;
}

// A vertex carried from one member to another through their sphere maps: the corner of the
// face holding the same sphere point with the largest barycentric weight (-1: no face).
struct Carrier {
  const std::vector<TriMesh>& meshes;
  const std::vector<RowMat3d>& maps;
  const std::vector<SphereLocator>& locators;
  int operator()(int from, int v, int to) const {
    const SphereLocation l = locators[to].locate(maps[from].row(v).transpose().normalized());
    if (l.face < 0) return -1;
    int c = 0;
    for (int k = 1; k < 3; ++k)
      if (l.bary[k] > l.bary[c]) c = k;
    return meshes[to].F(l.face, c);
  }
};

// The finer AGD peaks matched through the sphere maps: a reference peak is carried to each
// member and snapped to the member's nearest peak within fine_radius (peaks are at least that
// far apart); kept when that holds on every member and each member's peak, carried back,
// snaps to the same reference peak. Peaks inside a landmark's tip region (a hand's fingertips)
// belong to that landmark and are not candidates. Returns per match the vertex on each member.
std::vector<std::vector<int>> match_fine_peaks(const std::vector<Member>& mem, int ref, const ProposeLandmarksOptions& o,
                                               const Carrier& carry, const std::vector<std::vector<int>>& anchors) {
  const int nm = static_cast<int>(mem.size());
  std::vector<std::vector<int>> cand(nm);
  for (int i = 0; i < nm; ++i)
    for (int p : mem[i].fine) {
      bool free = true;
      for (int f : anchors[i]) free = free && mem[i].dist[f][p] > o.extremity_radius;
      if (free) cand[i].push_back(p);
    }
  std::vector<double> d;
  auto snap = [&](int i, int v) {
    if (v < 0) return -1;
    dijkstra(mem[i].g, v, d, nullptr, o.fine_radius);
    int best = -1;
    for (int p : cand[i])
      if (d[p] <= o.fine_radius && (best < 0 || d[p] < d[best])) best = p;
    return best;
  };
  std::vector<std::vector<int>> out;
  for (int p : cand[ref]) {
    std::vector<int> at(nm, -1);
    at[ref] = p;
    bool ok = true;
    for (int i = 0; i < nm && ok; ++i) {
      if (i == ref) continue;
      at[i] = snap(i, carry(ref, p, i));
      ok = at[i] >= 0 && snap(ref, carry(i, at[i], ref)) == p;
    }
    if (ok) out.push_back(std::move(at));
  }
  return out;
}

// The finer peaks of an extremity's region matched among themselves, like the extremities
// (step 2 of propose_landmarks.h) but within the region. Two kinds of region:
// - An unstable extremity's (a cat's head, peaking at the nose on one member and at an ear
//   tip on another): the fine discs' maxima within twice extremity_radius of the extremity the
//   member's assignment gives, none inside a stable landmark's tip region; every peak matched
//   on all members is added (the cats' two ear tips). Carried through sphere maps pinned
//   only at the stable extremities, they landed 0.1-0.2 sqrt(area) off (TOSCA cats: none came
//   back to itself, the head was left without a landmark).
// - A stable extremity's tip (a hand): the limb tips within extremity_radius of its landmark
//   (see tip_peaks: a hand's fingertips); only the matched one farthest from the landmarks is
//   added. One point off the limb's axis fixes the limb's twist about it, which the tip's
//   centre alone leaves free (FAUST: arms turned by up to 0.16 sqrt(area) of correspondence
//   error); that is the thumb, the most isolated fingertip. All four fingertips of each hand,
//   each placed to 0.002-0.006, made `consistent` worse (0.077/0.085/0.051 against
//   0.060/0.076/0.046 without any), the thumbs alone better (0.042/0.065/0.038).
// An assignment (partial, injective) costs the relative differences of its peaks' distances
// to the stable landmarks (which put them in the region) and to each other (which tell an
// ear from the rest); a peak left out costs kRegionMiss per term, half the cap: the head's
// other peaks (a broad snout or cheek peaking 0.06-0.17 from the nose tip, at different
// places on different members) are left out rather than matched at a distance factor beyond
// 1.2. Distances cannot tell the left ear from the right, so among the kSphereCandidates
// cheapest within kSphereWindow, the turns of the matched peaks and the stable landmarks, seen
// from the peaks' geodesic centre (between the ears), decide, weighed against the cost as in
// the sphere test (kCostWeight). The maps' orientation decided the shared cats alike; the
// turns need no map. Returns, per reference peak to add, its vertex on each member.
constexpr int kRegionPeaks = 6;
constexpr double kRegionMiss = 0.5 * kPairCap;
// Limb tips (x sqrt(area)): an AGD maximum over a disc of kTipSeparation, that far from every
// landmark, whose AGD falls by at least kTipSharpness times the distance in every direction
// (measured kSharpRadius away): along a finger the AGD falls at about the rate of distance
// (FAUST fingertips 0.56-0.77), on a bump it hardly falls (FAUST toes and heels: 0.00).
constexpr double kTipSeparation = 0.02, kSharpRadius = 0.03, kTipSharpness = 0.3;

struct RegionPeaks {
  std::vector<int> v;
  std::vector<std::vector<double>> dist;
};

RegionPeaks region_peaks(const Member& m, int centre_field, const std::vector<int>& stable_fields,
                         const ProposeLandmarksOptions& o) {
  RegionPeaks r;
  for (int p : m.fine) {
    if (static_cast<int>(r.v.size()) >= kRegionPeaks) break;
    if (!(m.dist[centre_field][p] <= 2 * o.extremity_radius)) continue;
    bool free = true;
    for (int f : stable_fields) free = free && m.dist[f][p] > o.extremity_radius;
    if (!free) continue;
    r.v.push_back(p);
    r.dist.emplace_back();
    dijkstra(m.g, p, r.dist.back());
  }
  return r;
}

// How fast the AGD falls around v: (AGD(v) - the largest AGD between 0.75 r and 1.25 r from
// v) / r; about 1 at a limb tip, 0 on a bump or a flat.
double tip_sharpness(const Member& m, int v, double r) {
  std::vector<double> d;
  dijkstra(m.g, v, d, nullptr, 1.25 * r);
  double top = -kInf;
  for (std::size_t u = 0; u < d.size(); ++u)
    if (d[u] >= 0.75 * r && d[u] <= 1.25 * r) top = std::max(top, m.agd[u]);
  return top > -kInf ? (m.agd[v] - top) / r : 0.0;
}

// The limb tips (see kTipSharpness) within extremity_radius of a stable extremity's landmark
// (field `centre_field`), by decreasing AGD, at most kRegionPeaks.
RegionPeaks tip_peaks(const Member& m, int centre_field, const std::vector<int>& fields,
                      const ProposeLandmarksOptions& o) {
  const std::vector<double>& dc = m.dist[centre_field];
  auto is_tip = [&](int v) {
    if (!(dc[v] <= o.extremity_radius)) return false;
    for (int f : fields)
      if (!(m.dist[f][v] > kTipSeparation)) return false;
    return tip_sharpness(m, v, kSharpRadius) >= kTipSharpness;
  };
  RegionPeaks r;
  for (int v : agd_peaks(m, kTipSeparation, kRegionPeaks, is_tip)) {
    r.v.push_back(v);
    r.dist.emplace_back();
    dijkstra(m.g, v, r.dist.back());
  }
  return r;
}

// The vertex with the least sum of squared distances to the chosen peaks (with plain
// distances, every vertex on the path between two peaks would tie, the peaks included).
int geodesic_centre(const RegionPeaks& r, const std::vector<int>& chosen) {
  const std::size_t n = r.dist.front().size();
  int best = 0;
  double best_s = kInf;
  for (std::size_t v = 0; v < n; ++v) {
    double s = 0;
    for (int p : chosen) s += r.dist[p][v] * r.dist[p][v];
    if (s < best_s) best_s = s, best = static_cast<int>(v);
  }
  return best;
}

std::vector<std::vector<int>> match_region_peaks(const std::vector<TriMesh>& meshes, const std::vector<Member>& mem,
                                                 int ref, const MatchAll& ma, const ProposeLandmarksOptions& o,
                                                 const std::vector<std::vector<int>>& anchors,
                                                 const std::vector<std::vector<int>>& at) {
  const int nm = static_cast<int>(mem.size());
  const int na = static_cast<int>(anchors[ref].size());
  auto rel = [](double a, double b) {
    return std::min(std::abs(std::log((a + kRelativeSoftening) / (b + kRelativeSoftening))), kPairCap);
  };
  std::vector<std::vector<int>> out;
  const int kr_all = static_cast<int>(ma.to[ref].size());
  for (int q = 0; q < kr_all; ++q) {
    bool everywhere = true;
    for (int i = 0; i < nm; ++i) everywhere = everywhere && ma.to[i][q] >= 0;
    if (!everywhere) continue;
    const bool unstable = q < static_cast<int>(ma.unstable.size()) && ma.unstable[q];
    std::vector<RegionPeaks> reg(nm);
    for (int i = 0; i < nm; ++i)
      reg[i] = unstable ? region_peaks(mem[i], ma.to[i][q], anchors[i], o) : tip_peaks(mem[i], ma.to[i][q], anchors[i], o);
    const RegionPeaks& R = reg[ref];
    const int kr = static_cast<int>(R.v.size());
    if (kr == 0) continue;
    const double terms = kr + kr * (kr - 1) / 2.0;
    // The turns of the chosen peaks and the stable landmarks seen from the peaks' geodesic
    // centre; triples of stable landmarks alone say nothing about the region and are left out.
    auto turns = [&](int i, const RegionPeaks& P, const std::vector<int>& chosen) {
      std::vector<int> pts;
      for (int p : chosen) pts.push_back(P.v[p]);
      const std::size_t peaks = pts.size();
      pts.insert(pts.end(), at[i].begin(), at[i].end());
      std::vector<double> t = triple_turns(meshes[i], mem[i], pts, geodesic_centre(P, chosen));
      const std::size_t k = pts.size();
      for (std::size_t a = 0; a < k; ++a)
        for (std::size_t b = std::max(a + 1, peaks); b < k; ++b)
          for (std::size_t c = b + 1; c < k; ++c) t[(a * k + b) * k + c] = 0;
      return t;
    };
    std::vector<std::vector<int>> to(nm);  // per member: reference peak -> member peak or -1
    to[ref].resize(kr);
    std::iota(to[ref].begin(), to[ref].end(), 0);
    for (int i = 0; i < nm; ++i) {
      if (i == ref) continue;
      const RegionPeaks& M = reg[i];
      const int km = static_cast<int>(M.v.size());
      std::vector<std::vector<double>> U(kr, std::vector<double>(km, 0.0));
      for (int p = 0; p < kr; ++p)
        for (int j = 0; j < km; ++j) {
          for (int a = 0; a < na; ++a)
            U[p][j] += rel(mem[i].dist[anchors[i][a]][M.v[j]], mem[ref].dist[anchors[ref][a]][R.v[p]]);
          U[p][j] /= std::max(na, 1);
        }
      // Every partial injective assignment (at most kRegionPeaks points: 13327 of them).
      std::vector<std::pair<double, std::vector<int>>> all;
      std::vector<int> cur(kr, -1);
      std::vector<char> used(km, 0);
      auto recurse = [&](auto&& self, int p, double cost) -> void {
        if (p == kr) {
          all.emplace_back(cost / terms, cur);
          return;
        }
        for (int j = -1; j < km; ++j) {
          if (j >= 0 && used[j]) continue;
          double add = j < 0 ? kRegionMiss : U[p][j];
          for (int s = 0; s < p; ++s)
            add += (j < 0 || cur[s] < 0) ? kRegionMiss : rel(M.dist[j][M.v[cur[s]]], R.dist[p][R.v[s]]);
          cur[p] = j;
          if (j >= 0) used[j] = 1;
          self(self, p + 1, cost + add);
          if (j >= 0) used[j] = 0;
          cur[p] = -1;
        }
      };
      recurse(recurse, 0, 0.0);
      std::stable_sort(all.begin(), all.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      double best_score = -kInf;
      for (std::size_t c = 0; c < all.size() && c < static_cast<std::size_t>(kSphereCandidates); ++c) {
        const auto& [cost, a] = all[c];
        if (cost > all.front().first + kSphereWindow) break;
        std::vector<int> rc, mc;
        for (int p = 0; p < kr; ++p)
          if (a[p] >= 0) rc.push_back(p), mc.push_back(a[p]);
        double proj = 0;
        if (!rc.empty()) {
          const std::vector<double> tr = turns(ref, R, rc), tm = turns(i, M, mc);
          double norm = 0;
          for (std::size_t x = 0; x < tr.size(); ++x) proj += tr[x] * tm[x], norm += tr[x] * tr[x];
          proj = norm > 0 ? std::clamp(proj / norm, -1.0, 1.0) : 0.0;
        }
        const double score = proj - kCostWeight * (cost - all.front().first);
        if (score > best_score) best_score = score, to[i] = a;
      }
    }
    std::vector<int> farthest;  // a stable extremity's: the tip farthest from the landmarks
    double farthest_d = -1;
    for (int p = 0; p < kr; ++p) {
      std::vector<int> v(nm);
      bool ok = true;
      for (int i = 0; i < nm && ok; ++i) {
        ok = to[i][p] >= 0;
        if (ok) v[i] = reg[i].v[to[i][p]];
      }
      if (!ok) continue;
      if (unstable) {
        out.push_back(std::move(v));
        continue;
      }
      double d = kInf;
      for (int f : anchors[ref]) d = std::min(d, mem[ref].dist[f][R.v[p]]);
      if (d > farthest_d) farthest_d = d, farthest = std::move(v);
    }
    if (!farthest.empty()) out.push_back(std::move(farthest));
  }
  return out;
}

}  // namespace

Result<ProposeLandmarksResult> propose_landmarks(const std::vector<TriMesh>& meshes, const ProposeLandmarksOptions& o,
                                                 const ProgressFn& progress) {
  using R = Result<ProposeLandmarksResult>;
  const int nm = static_cast<int>(meshes.size());
  if (nm < 1) return R(ErrorCode::InvalidArgument, "propose_landmarks: no meshes");
  if (o.agd_sources < 4 || o.agd_sources > 1000) return R(ErrorCode::InvalidArgument, "agd_sources must be 4..1000");
  if (o.max_extremities < 3 || o.max_extremities > 16) return R(ErrorCode::InvalidArgument, "max_extremities must be 3..16");
  if (!(o.extremity_radius > 0 && o.extremity_radius < 1)) return R(ErrorCode::InvalidArgument, "extremity_radius must be in (0, 1)");
  if (!(o.tip_drop >= 0 && o.tip_drop < 1)) return R(ErrorCode::InvalidArgument, "tip_drop must be in [0, 1)");
  if (!(o.fine_radius >= 0 && o.fine_radius < 1)) return R(ErrorCode::InvalidArgument, "fine_radius must be in [0, 1)");
  if (o.extra_points < 0 || o.extra_points > 1000) return R(ErrorCode::InvalidArgument, "extra_points must be 0..1000");
  if (o.reference < -1 || o.reference >= nm) return R(ErrorCode::InvalidArgument, "reference out of range");
  if (o.sphere_effort < 0 || o.sphere_effort > 5) return R(ErrorCode::InvalidArgument, "sphere_effort must be 0..5");
  if (o.threads < 0) return R(ErrorCode::InvalidArgument, "threads must be >= 0");

  std::vector<Member> mem(nm);
  for (int i = 0; i < nm; ++i) {
    auto g = build_graph(meshes[i], i);
    if (!g.ok()) return g.status();
    mem[i].g = std::move(*g);
    if (Status s = find_extremities(meshes[i], i, o, mem[i]); !s.ok()) return s;
    if (!report_progress(progress, "landmarks", i, 0.5 * (i + 1) / nm)) return R(ErrorCode::Cancelled, "cancelled");
  }
  // The reference: given, or the member that matches the others best (a member that is an
  // outlier of the family, e.g. in a different body shape, makes every match worse).
  int ref = o.reference;
  MatchAll ma;
  if (ref >= 0) {
    if (mem[ref].ext.size() < 3) return R(ErrorCode::InvalidInput, "mesh " + std::to_string(ref) + ": fewer than 3 extremities found");
    ma = match_all(meshes, mem, ref);
  } else {
    for (int r = 0; r < std::min(nm, 8); ++r) {  // 8 candidates bound the cost at 8 n matches
      if (mem[r].ext.size() < 3) continue;
      MatchAll c = match_all(meshes, mem, r);
      if (ref < 0 || c.total < ma.total) ma = std::move(c), ref = r;
      if (!report_progress(progress, "landmarks", r, 0.5 + 0.4 * (r + 1) / std::min(nm, 8))) return R(ErrorCode::Cancelled, "cancelled");
    }
    if (ref < 0) return R(ErrorCode::InvalidInput, "no mesh has 3 extremities");
  }
  if (o.fine_radius > 0) unstable_extremities(mem, ref, ma);
  if (o.sphere_orientation && !resolve_by_sphere(meshes, mem, ref, o, ma, progress))
    return R(ErrorCode::Cancelled, "cancelled");
  Member& rm = mem[ref];
  const int kr = static_cast<int>(rm.ext.size());
  ProposeLandmarksResult out;
  out.reference = ref;
  out.members = ma.members;
  for (int i = 0; i < nm; ++i) out.extremities_found.push_back(static_cast<int>(mem[i].ext.size()));
  const std::vector<std::vector<int>>& to = ma.to;

  // Names: the reference's extremities matched on every member, in decreasing AGD, without
  // the unstable ones (see unstable_extremities): where the maps allow, their region's finer
  // peaks (a cat's ear tips) are matched through the maps instead.
  const bool fine_stage = o.fine_radius > 0 && static_cast<int>(ma.maps.size()) == nm &&
                          std::all_of(ma.maps.begin(), ma.maps.end(), [](const RowMat3d& S) { return S.rows() > 0; });
  std::vector<int> keep;
  for (int e = 0; e < kr; ++e) {
    bool all = true;
    for (int i = 0; i < nm; ++i) all = all && to[i][e] >= 0;
    if (all) keep.push_back(e);
  }
  if (!ma.unstable.empty()) {
    std::vector<int> stable;
    for (int e : keep)
      if (!ma.unstable[e]) stable.push_back(e);
    if (stable.size() >= 3) {
      out.unstable_dropped = static_cast<int>(keep.size() - stable.size());
      keep = std::move(stable);
    }
  }
  std::vector<char> unpinned = ma.unstable;
  unpinned.resize(kr, 0);
  out.mismatch_dropped = drop_mismatched(mem, ref, to, keep, unpinned);
  if (!repin_maps(meshes, mem, ref, o, unpinned, ma, progress)) return R(ErrorCode::Cancelled, "cancelled");
  if (keep.size() < 3) return R(ErrorCode::InvalidInput, "fewer than 3 extremities correspond across all members");
  // Each kept extremity moved to the centre of its tip region (see tip_centre), on every member
  // alike, and its distance field recomputed.
  if (o.tip_drop > 0)
    for (int i = 0; i < nm; ++i)
      for (int e : keep) {
        const int f = to[i][e];
        const int c = tip_centre(meshes[i], mem[i], mem[i].ext[f], mem[i].dist[f], o.extremity_radius, o.tip_drop);
        if (c != mem[i].ext[f]) {
          mem[i].ext[f] = c;
          dijkstra(mem[i].g, c, mem[i].dist[f], &mem[i].parent[f]);
        }
      }
  out.landmarks.assign(nm, {});
  out.confidence.assign(nm, {});
  // Per member and landmark: the index of its distance field in mem[i].dist, and its vertex.
  std::vector<std::vector<int>> anchors(nm), at(nm);
  auto add_landmark = [&](int i, int field, int vertex) {
    if (static_cast<int>(out.names.size()) == static_cast<int>(out.landmarks[i].size()))
      out.names.push_back("lm" + std::to_string(out.names.size()));
    anchors[i].push_back(field);
    at[i].push_back(vertex);
    out.landmarks[i].push_back({out.names.back(), vertex});
  };
  for (int e : keep)
    for (int i = 0; i < nm; ++i) add_landmark(i, to[i][e], mem[i].ext[to[i][e]]);

  std::vector<SphereLocator> locators;
  if (fine_stage)
    for (int i = 0; i < nm; ++i) locators.emplace_back(meshes[i].F, ma.maps[i]);
  const Carrier carry{meshes, ma.maps, locators};
  // A finer peak matched on every member, kept only where it is a vertex no landmark holds yet
  // on any member (two features on one vertex cannot be mapped apart). It stays where it
  // is: moved to the centre of its tip region (AGD within tip_drop inside fine_radius), a
  // fingertip was drawn towards the hand's middle.
  auto add_peak = [&](const std::vector<int>& peak) {
    for (int i = 0; i < nm; ++i)
      if (std::find(at[i].begin(), at[i].end(), peak[i]) != at[i].end()) return;
    for (int i = 0; i < nm; ++i) {
      add_field(mem[i], peak[i]);
      add_landmark(i, static_cast<int>(mem[i].dist.size()) - 1, peak[i]);
    }
    ++out.fine_matched;
  };
  // Peaks matched within a region (by distances and turns only) are the least sure landmarks:
  // the openings below are matched without them (landmarks region_begin .. region_end - 1).
  const std::size_t region_begin = out.names.size();
  if (o.fine_radius > 0)
    for (const std::vector<int>& peak : match_region_peaks(meshes, mem, ref, ma, o, anchors, at)) add_peak(peak);
  const std::size_t region_end = out.names.size();
  if (fine_stage)
    for (const std::vector<int>& peak : match_fine_peaks(mem, ref, o, carry, anchors)) add_peak(peak);
  out.extremities = static_cast<int>(out.names.size());

  // Rim points of corresponding openings (detail/rim_landmarks.h), told apart by their
  // distances to the landmarks so far, those matched within a region left out: on ICT heads
  // with decimated members two tips of the nose's extremity matched 0.13-0.15 off, no opening
  // matched after them, and the heads had 6 landmarks (79% within 0.05) instead of 9 (97%).
  // They are judged with the extremities below.
  if (o.rim_points) {
    // Rounds: an opening whose ends the extremities cannot tell apart (a coarse member's eye) may
    // be told apart by the precise points of the openings matched before it (the mouth's).
    std::vector<const TriMesh*> mesh_ptrs;
    std::vector<double> sqrt_area;
    for (int i = 0; i < nm; ++i) mesh_ptrs.push_back(&meshes[i]), sqrt_area.push_back(mem[i].g.sqrt_area);
    detail::RimMatcher matcher(mesh_ptrs, sqrt_area);
    std::vector<char> crowded;  // per rim point (detail::RimPoint)
    for (int round = 0; round < kRimRounds; ++round) {
      std::vector<std::vector<const std::vector<double>*>> fields(nm);
      for (int i = 0; i < nm; ++i)
        for (std::size_t k = 0; k < anchors[i].size(); ++k)
          if (k < region_begin || k >= region_end) fields[i].push_back(&mem[i].dist[anchors[i][k]]);
      const std::vector<detail::RimPoint> rim = matcher.match(fields, ref);
      for (const detail::RimPoint& pt : rim) {
        for (int i = 0; i < nm; ++i) {
          add_field(mem[i], pt.vertex[i]);
          add_landmark(i, static_cast<int>(mem[i].dist.size()) - 1, pt.vertex[i]);
        }
        crowded.push_back(pt.crowded);
      }
      if (rim.empty()) break;
    }
    // Rim points are placed to within a few edges (ICT heads: 0.000-0.005 sqrt(area)), the
    // extremities of a flat distance field (a nose on a head) to within its tip region. So the
    // rim points, once there are enough of them, judge the extremities: on each member, how far
    // the rim points' distances to each other differ from the reference's is the family's own
    // departure from isometry; an extremity whose distances to the rim points differ by more
    // than kRimOutlier times that on some member is misplaced there, and is left out (ICT: the
    // nose tip, 0.13 against the rim points' 0.044 on one head).
    // Every rim point judges, crowded ones too; only the others stay landmarks.
    const int n_rim = static_cast<int>(crowded.size()), n_ext = out.extremities;
    std::vector<char> drop(n_ext, 0);
    if (n_rim >= kMinRimJudges) {
      auto rel = [](double a, double b) { return std::abs(std::log((a + 0.02) / (b + 0.02))); };
      auto d = [&](int i, int p, int q) { return mem[i].dist[anchors[i][p]][at[i][q]]; };
      for (int i = 0; i < nm; ++i) {
        if (i == ref) continue;
        double base = 0;
        for (int p = n_ext; p < n_ext + n_rim; ++p)
          for (int q = n_ext; q < n_ext + n_rim; ++q)
            if (p != q) base += rel(d(ref, p, q), d(i, p, q));
        base /= n_rim * (n_rim - 1);
        for (int e = 0; e < n_ext; ++e) {
          double dev = 0;
          for (int q = n_ext; q < n_ext + n_rim; ++q) dev += rel(d(ref, e, q), d(i, e, q));
          if (dev / n_rim > std::max(kRimOutlier * base, kRimOutlierFloor)) drop[e] = 1;
        }
      }
    }
    // Left out in every member's list alike; the names stay in order (lm0, lm1, ...).
    if (n_rim > 0) {
      int kept = 0;
      for (int k = 0; k < n_ext + n_rim; ++k)
        if (k < n_ext ? !drop[k] : !crowded[k - n_ext]) {
          for (int i = 0; i < nm; ++i) {
            anchors[i][kept] = anchors[i][k];
            at[i][kept] = at[i][k];
            out.landmarks[i][kept] = {"lm" + std::to_string(kept), at[i][k]};
          }
          ++kept;
        }
      for (int i = 0; i < nm; ++i) anchors[i].resize(kept), at[i].resize(kept), out.landmarks[i].resize(kept);
      out.names.resize(kept);
      for (int k = 0; k < kept; ++k) out.names[k] = "lm" + std::to_string(k);
      out.rim_outliers_dropped = static_cast<int>(std::count(drop.begin(), drop.end(), 1));
      out.extremities -= out.rim_outliers_dropped;
      out.rim_matched = kept - out.extremities;
    }
  }

  // Confidence of an extremity's match: the mean |distance difference| to the other landmarks,
  // 1 at 0 and 1/2 at 0.02 sqrt(area) (the AGD maxima's own placement noise), halved when the
  // member's mirror is ambiguous.
  auto conf = [&](int i, double err) {
    return i == ref ? 1.0 : (1.0 / (1.0 + (err / 0.02) * (err / 0.02))) * (out.members[i].mirror_ambiguous ? 0.5 : 1.0);
  };
  const int ne = static_cast<int>(out.names.size());
  for (int i = 0; i < nm; ++i)
    for (int q = 0; q < ne; ++q) {
      double err = 0;
      for (int p = 0; p < ne; ++p)
        if (p != q) err += std::abs(rm.dist[anchors[ref][q]][at[ref][p]] - mem[i].dist[anchors[i][q]][at[i][p]]);
      out.confidence[i].push_back(conf(i, err / (ne - 1)));
    }

  // Further points: farthest-point sampling on the reference from the landmarks so far; on each
  // member, geodesic trilateration: a vertex whose distances to the matched landmarks fit the
  // reference's, in relative terms (|log|, softened by kRelativeSoftening: the members of a
  // family are only nearly isometric, a long distance changes by more than a short one, and the
  // near landmarks place a point best). Distances alone cannot tell a point from its mirror
  // image across the landmarks (a torso's front from its back: both are local minima of the
  // fit, and the wrong one may fit ten times better), but the turns of the landmarks seen from
  // the point can (the test the extremities' mirror uses, here about one point): each of the
  // fit's best local minima scores how its turns project on the reference's (1: the same, -1:
  // mirrored, ~0: degenerate, as on a limb, where every path leaves along its axis) less
  // kFitWeight times how much worse it fits than the best one (log ratio above the noise
  // floor). Before, the minimum nearest the point the sphere maps carry it to was taken; the
  // maps, with a handful of constraints, are off by 0.1-0.3 sqrt(area) far from them: with 8
  // further points, 59% (FAUST) and 41% (TOSCA cats) of the landmarks were within 0.05
  // sqrt(area) of their true partners, now 80% and 54% (absolute instead of relative
  // differences: 74% and 49%).
  const int nr = static_cast<int>(meshes[ref].V.rows());
  std::vector<double> mind(nr, kInf);
  for (int f : anchors[ref])
    for (int v = 0; v < nr; ++v) mind[v] = std::min(mind[v], rm.dist[f][v]);
  for (int e = 0; e < o.extra_points; ++e) {
    const int pv = static_cast<int>(std::max_element(mind.begin(), mind.end()) - mind.begin());
    const int na = static_cast<int>(anchors[ref].size());
    std::vector<double> target;
    for (int f : anchors[ref]) target.push_back(rm.dist[f][pv]);
    // The turns of the kTurnLandmarks landmarks nearest the point (their paths are the
    // shortest; and the turns of k landmarks cost k^3).
    std::vector<int> near_lm(na);
    std::iota(near_lm.begin(), near_lm.end(), 0);
    std::stable_sort(near_lm.begin(), near_lm.end(), [&](int a, int b) { return target[a] < target[b]; });
    if (near_lm.size() > kTurnLandmarks) near_lm.resize(kTurnLandmarks);
    auto turn_points = [&](int i) {
      std::vector<int> pts;
      for (int a : near_lm) pts.push_back(at[i][a]);
      return pts;
    };
    const std::vector<double> ref_turns = triple_turns(meshes[ref], rm, turn_points(ref), pv);
    double ref_norm = 0;
    for (double t : ref_turns) ref_norm += t * t;
    for (int i = 0; i < nm; ++i) {
      Member& m = mem[i];
      auto fit = [&](int v) {
        double s = 0;
        for (int a = 0; a < na; ++a) {
          const double r = std::log((m.dist[anchors[i][a]][v] + kRelativeSoftening) / (target[a] + kRelativeSoftening));
          s += r * r;
        }
        return s;
      };
      int best = pv;
      if (i != ref) {
        const int n = static_cast<int>(meshes[i].V.rows());
        std::vector<double> fv(n);
        for (int v = 0; v < n; ++v) fv[v] = fit(v);
        std::vector<int> minima;  // over the 1-ring, ties to the lower index
        for (int v = 0; v < n; ++v) {
          bool lowest = true;
          for (int k = m.g.start[v]; k < m.g.start[v + 1] && lowest; ++k) {
            const int u = m.g.nbr[k];
            lowest = fv[v] < fv[u] || (fv[v] == fv[u] && v < u);
          }
          if (lowest) minima.push_back(v);
        }
        std::sort(minima.begin(), minima.end(), [&](int a, int b) { return fv[a] < fv[b] || (fv[a] == fv[b] && a < b); });
        if (minima.size() > kTrilaterationCandidates) minima.resize(kTrilaterationCandidates);
        const double floor = na * kRelativeNoise * kRelativeNoise;
        const std::vector<int> pts = turn_points(i);
        double best_score = -kInf;
        for (int c : minima) {
          double proj = 0;
          if (ref_norm > 0) {
            const std::vector<double> turns = triple_turns(meshes[i], m, pts, c);
            for (std::size_t q = 0; q < turns.size(); ++q) proj += ref_turns[q] * turns[q];
            proj = std::clamp(proj / ref_norm, -1.0, 1.0);
          }
          const double score = proj - kFitWeight * std::log((fv[c] + floor) / (fv[minima.front()] + floor));
          if (score > best_score) best_score = score, best = c;
        }
      }
      add_field(m, best);
      add_landmark(i, static_cast<int>(m.dist.size()) - 1, best);
      // Confidence from the plain distance differences, as for the other landmarks.
      double sq = 0;
      for (int a = 0; a < na; ++a) {
        const double dd = m.dist[anchors[i][a]][best] - target[a];
        sq += dd * dd;
      }
      out.confidence[i].push_back(conf(i, std::sqrt(sq / na)));
    }
    for (int v = 0; v < nr; ++v) mind[v] = std::min(mind[v], rm.dist.back()[v]);
    if (!report_progress(progress, "landmarks", e, 0.9 + 0.1 * (e + 1) / o.extra_points))
      return R(ErrorCode::Cancelled, "cancelled");
  }
  return out;
}

Result<std::vector<SuspectLandmark>> suspect_landmarks(const std::vector<TriMesh>& meshes,
                                                       const std::vector<std::vector<int>>& landmarks, int reference) {
  using R = Result<std::vector<SuspectLandmark>>;
  const int nm = static_cast<int>(meshes.size());
  if (landmarks.size() != meshes.size()) return R(ErrorCode::InvalidArgument, "suspect_landmarks: one landmark list per mesh");
  if (reference < 0 || reference >= nm) return R(ErrorCode::InvalidArgument, "suspect_landmarks: reference out of range");
  const std::size_t k = landmarks[static_cast<std::size_t>(reference)].size();
  std::vector<SuspectLandmark> out;
  // Dense sets (more than kMaxChecked) are left unchecked: the leave-one-out medians cost k^3
  // per member and round, and such sets come from tools, not from hands.
  constexpr std::size_t kMaxChecked = 64;
  if (k < 4 || k > kMaxChecked) return out;
  // Per member: the distances between its landmarks (k x k, sqrt(area) units).
  std::vector<std::vector<double>> D(static_cast<std::size_t>(nm));
  for (int i = 0; i < nm; ++i) {
    const std::vector<int>& lm = landmarks[static_cast<std::size_t>(i)];
    if (lm.size() != k) return R(ErrorCode::InvalidArgument, "mesh " + std::to_string(i) + ": a different number of landmarks");
    auto g = build_graph(meshes[static_cast<std::size_t>(i)], i);
    if (!g.ok()) return g.status();
    for (int v : lm)
      if (v < 0 || v >= static_cast<int>(meshes[static_cast<std::size_t>(i)].V.rows()))
        return R(ErrorCode::InvalidInput, "mesh " + std::to_string(i) + ": landmark vertex " + std::to_string(v) + " out of range");
    std::vector<double>& Di = D[static_cast<std::size_t>(i)];
    Di.assign(k * k, kInf);
    std::vector<double> d;
    for (std::size_t a = 0; a < k; ++a) {
      dijkstra(*g, lm[a], d);
      for (std::size_t b = 0; b < k; ++b) Di[a * k + b] = d[static_cast<std::size_t>(lm[b])];
    }
  }
  // Per member, worst first while more than 3 remain: a landmark whose pairs disagree far beyond
  // the pairs among the others. Leaving the landmark itself out of the comparison matters: two
  // names swapped spoil 13 of a cat's 28 pairs (the median of all pairs 0.17 where the right
  // members have 0.035), and the swapped tail, 0.78, was then only 4.7 times that.
  const std::vector<double>& Dr = D[static_cast<std::size_t>(reference)];
  for (int i = 0; i < nm; ++i) {
    if (i == reference) continue;
    const std::vector<double>& Dm = D[static_cast<std::size_t>(i)];
    // |log ratio| per pair; NaN where either member has them apart (separate components).
    std::vector<double> E(k * k, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t a = 0; a < k; ++a)
      for (std::size_t b = 0; b < k; ++b)
        if (a != b && std::isfinite(Dr[a * k + b]) && std::isfinite(Dm[a * k + b]))
          E[a * k + b] = std::abs(std::log(std::max(Dr[a * k + b], 1e-9) / std::max(Dm[a * k + b], 1e-9)));
    std::vector<std::size_t> keep(k);
    std::iota(keep.begin(), keep.end(), std::size_t{0});
    while (keep.size() > 3) {
      std::size_t worst = k;
      double worst_per = 0, worst_typical = 0;
      for (std::size_t a : keep) {
        std::vector<double> row, others;
        for (std::size_t b : keep) {
          if (b == a) continue;
          if (!std::isnan(E[a * k + b])) row.push_back(E[a * k + b]);
          for (std::size_t c : keep)
            if (c > b && c != a && !std::isnan(E[b * k + c])) others.push_back(E[b * k + c]);
        }
        if (row.empty() || others.empty()) continue;
        const double per = median(std::move(row)), typical = median(std::move(others));
        // The floor is the matching's cap (a factor 1.5: a pair simply wrong), not the
        // proposal's 0.2: a user's file is only questioned where the landmark is clearly
        // elsewhere (a warped gargoyle's right landmark differed by 1.25 against 1.04).
        if (per > kPairCap && per > kMismatchFactor * typical && per > worst_per)
          worst = a, worst_per = per, worst_typical = typical;
      }
      if (worst == k) break;
      out.push_back({i, static_cast<int>(worst), worst_per, worst_typical});
      keep.erase(std::find(keep.begin(), keep.end(), worst));
    }
  }
  return out;
}

}  // namespace spherekit
