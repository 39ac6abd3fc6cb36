// Landmark proposal: extremities by average geodesic distance, a combinatorial match of their
// pairwise geodesic distances, orientation of matched triples against mirror flips, further
// points by farthest-point sampling (see propose_landmarks.h for the method and references).
#include "spherekit/propose_landmarks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <string>

namespace spherekit {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Edge graph with Euclidean edge lengths (CSR), the surface's vertex normals and its area.
struct MeshGraph {
  std::vector<int> start, nbr;
  std::vector<double> len;
  RowMat3d N;
  double sqrt_area = 1;
};

Result<MeshGraph> build_graph(const TriMesh& m, int index) {
  const int n = static_cast<int>(m.V.rows());
  const std::string who = "mesh " + std::to_string(index) + ": ";
  if (n < 4 || m.F.rows() < 4) return Result<MeshGraph>(ErrorCode::InvalidInput, who + "fewer than 4 vertices or faces");
  std::vector<std::pair<int, int>> edges;
  edges.reserve(m.F.rows() * 6);
  MeshGraph g;
  g.N = RowMat3d::Zero(n, 3);
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
    for (int c = 0; c < 3; ++c) g.N.row(m.F(f, c)) += cr.transpose();
  }
  if (!(area > 0) || !std::isfinite(area)) return Result<MeshGraph>(ErrorCode::InvalidInput, who + "zero or non-finite area");
  g.sqrt_area = std::sqrt(area);
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
};

void add_field(Member& m, int v) {
  m.dist.emplace_back();
  m.parent.emplace_back();
  dijkstra(m.g, v, m.dist.back(), &m.parent.back());
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
  // Candidates: 1-ring maxima by decreasing AGD; kept when no vertex of the geodesic disc has
  // a larger AGD and no kept extremity lies in it (one point per limb tip, not one per bump).
  std::vector<int> cand;
  for (int v = 0; v < n; ++v) {
    bool top = true;
    for (int i = m.g.start[v]; i < m.g.start[v + 1] && top; ++i) top = m.agd[m.g.nbr[i]] <= m.agd[v];
    if (top) cand.push_back(v);
  }
  std::sort(cand.begin(), cand.end(), [&](int a, int b) { return m.agd[a] != m.agd[b] ? m.agd[a] > m.agd[b] : a < b; });
  for (int v : cand) {
    if (static_cast<int>(m.ext.size()) >= o.max_extremities) break;
    dijkstra(m.g, v, d, nullptr, o.extremity_radius);
    bool ok = true;
    for (int u = 0; u < n && ok; ++u)
      if (d[u] <= o.extremity_radius) ok = m.agd[u] <= m.agd[v];
    for (int e : m.ext) ok = ok && !(d[e] <= o.extremity_radius);
    if (ok) m.ext.push_back(v);
  }
  for (int e : m.ext) add_field(m, e);
  return Status::ok_status();
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

// Branch and bound over partial injective assignments. A pair of matched points costs
// min(|d_ref - d_member|, cap); a pair with an unmatched point costs cap, so leaving a point
// out is never cheaper than a bad match and a missing extremity (an ear too small to be one on
// some member) does not force a wrong one. Keeps the `keep` cheapest complete assignments.
class Matcher {
 public:
  Matcher(const std::vector<std::vector<double>>& R, const std::vector<std::vector<double>>& M,
          const std::vector<double>& agd_r, const std::vector<double>& agd_m, int keep)
      : R_(R), M_(M), agd_r_(agd_r), agd_m_(agd_m), keep_(keep), kr_(static_cast<int>(R.size())), km_(static_cast<int>(M.size())) {}
  std::vector<Assignment> run() {
    cur_.assign(kr_, -1);
    used_.assign(km_, false);
    recurse(0, 0.0);
    std::sort(best_.begin(), best_.end(), [](const Assignment& a, const Assignment& b) {
      return a.cost != b.cost ? a.cost < b.cost : a.to < b.to;
    });
    return best_;
  }
  static constexpr double kCap = 0.25;  // x sqrt(area): beyond this a pair is simply "wrong"

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
      // The point's own AGD (isometry-invariant like the distances) tells a head from a limb tip
      // at similar distances; weighted as one more pair.
      double add = j < 0 ? kCap : std::min(std::abs(agd_r_[i] - agd_m_[j]), kCap);
      for (int p = 0; p < i; ++p)
        add += (j < 0 || cur_[p] < 0) ? kCap : std::min(std::abs(R_[i][p] - M_[j][cur_[p]]), kCap);
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
  const std::vector<double>& agd_r_;
  const std::vector<double>& agd_m_;
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

std::vector<double> ext_agd(const Member& m) {
  std::vector<double> a;
  for (int e : m.ext) a.push_back(m.agd[e]);
  return a;
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

struct MatchAll {
  std::vector<LandmarkMemberMatch> members;
  std::vector<std::vector<int>> to;  // per member: reference extremity -> member extremity (-1: none)
  double total = 0;                  // sum of the members' mean costs
};

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

  MatchAll ma;
  ma.members.resize(nm);
  ma.to.assign(nm, {});
  ma.to[ref] = ref_fields;
  for (int i = 0; i < nm; ++i) {
    if (i == ref) continue;
    const Member& m = mem[i];
    const int km = static_cast<int>(m.ext.size());
    auto cands = Matcher(Rd, pair_distances(m), ext_agd(rm), ext_agd(m), 64).run();
    const double pairs = kr * (kr + 1) / 2.0;  // the pairs and the unary AGD terms
    // The cheapest assignment turning each way; a shape and its mirror image have the same
    // distances, so for a (near-)symmetric shape both are among the cheapest.
    const Assignment* pos = nullptr;
    const Assignment* neg = nullptr;
    double opos = 0, oneg = 0;
    std::vector<std::pair<int, std::vector<double>>> turns_by_centre;  // a centre's turns, computed once
    for (const auto& a : cands) {
      if (pos && neg) break;  // only the cheapest of each orientation is used
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
      if (ag >= 0 && !pos) pos = &a, opos = ag;
      if (ag < 0 && !neg) neg = &a, oneg = ag;
    }
    LandmarkMemberMatch& mm = ma.members[i];
    // Two assignments are "about as good" when their mean pair error differs by less than
    // 0.01 sqrt(area): the size of the AGD maxima's placement noise between poses.
    const double close = 0.01 * pairs;
    const Assignment* pick = pos ? pos : neg;
    if (pos && neg) {
      if (pos->cost <= neg->cost + close) {
        pick = pos;
        mm.mirror_resolved = neg->cost < pos->cost;
      } else {
        pick = neg;  // intrinsically clearly best, but it turns the other way: a mirrored member
        mm.mirrored = true;
      }
      mm.mirrored_cost = (pick == pos ? neg->cost : pos->cost) / pairs;
    } else if (neg) {
      mm.mirrored = true;
    }
    mm.cost = pick->cost / pairs;
    mm.orientation_agreement = pick == pos ? opos : oneg;
    // Orientation too weak to decide (flat or degenerate triples), with a near-equal rival.
    const double other = pick == pos ? (neg ? neg->cost : kInf) : (pos ? pos->cost : kInf);
    if (std::abs(mm.orientation_agreement) < 0.3 && other - pick->cost < close) mm.mirror_ambiguous = true;
    if (mm.mirrored && other - pick->cost < close) mm.mirror_ambiguous = true;
    ma.to[i] = pick->to;
    ma.total += mm.cost;
  }
  return ma;
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
  if (o.extra_points < 0 || o.extra_points > 1000) return R(ErrorCode::InvalidArgument, "extra_points must be 0..1000");
  if (o.reference < -1 || o.reference >= nm) return R(ErrorCode::InvalidArgument, "reference out of range");

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
  Member& rm = mem[ref];
  const int kr = static_cast<int>(rm.ext.size());
  ProposeLandmarksResult out;
  out.reference = ref;
  out.members = ma.members;
  for (int i = 0; i < nm; ++i) out.extremities_found.push_back(static_cast<int>(mem[i].ext.size()));
  const std::vector<std::vector<int>>& to = ma.to;

  // Names: the reference's extremities matched on every member, in decreasing AGD.
  std::vector<int> keep;
  for (int e = 0; e < kr; ++e) {
    bool all = true;
    for (int i = 0; i < nm; ++i) all = all && to[i][e] >= 0;
    if (all) keep.push_back(e);
  }
  if (keep.size() < 3) return R(ErrorCode::InvalidInput, "fewer than 3 extremities correspond across all members");
  out.landmarks.assign(nm, {});
  out.confidence.assign(nm, {});
  // anchors[i]: per landmark, the index of its distance field in mem[i].dist.
  std::vector<std::vector<int>> anchors(nm);
  for (std::size_t q = 0; q < keep.size(); ++q) {
    const std::string name = "lm" + std::to_string(q);
    out.names.push_back(name);
    for (int i = 0; i < nm; ++i) {
      const int f = to[i][keep[q]];
      anchors[i].push_back(f);
      out.landmarks[i].push_back({name, mem[i].ext[f]});
    }
  }
  out.extremities = static_cast<int>(keep.size());
  // Confidence of an extremity's match: the mean |distance difference| to the other landmarks,
  // 1 at 0 and 1/2 at 0.02 sqrt(area) (the AGD maxima's own placement noise), halved when the
  // member's mirror is ambiguous.
  auto conf = [](double err) { return 1.0 / (1.0 + (err / 0.02) * (err / 0.02)); };
  for (int i = 0; i < nm; ++i)
    for (std::size_t q = 0; q < keep.size(); ++q) {
      double err = 0;
      for (std::size_t p = 0; p < keep.size(); ++p)
        if (p != q) err += std::abs(rm.dist[anchors[ref][q]][rm.ext[keep[p]]] - mem[i].dist[anchors[i][q]][mem[i].ext[anchors[i][p]]]);
      err /= static_cast<double>(keep.size() - 1);
      out.confidence[i].push_back(i == ref ? 1.0 : conf(err) * (out.members[i].mirror_ambiguous ? 0.5 : 1.0));
    }

  // Further points: farthest-point sampling on the reference from the landmarks so far; on each
  // member the vertex whose distances to the matched landmarks best fit the reference's
  // (least squares), i.e. geodesic trilateration.
  const int nr = static_cast<int>(meshes[ref].V.rows());
  std::vector<double> mind(nr, kInf);
  for (int f : anchors[ref])
    for (int v = 0; v < nr; ++v) mind[v] = std::min(mind[v], rm.dist[f][v]);
  for (int e = 0; e < o.extra_points; ++e) {
    const int pv = static_cast<int>(std::max_element(mind.begin(), mind.end()) - mind.begin());
    const std::string name = "lm" + std::to_string(out.names.size());
    out.names.push_back(name);
    std::vector<double> target;
    for (int f : anchors[ref]) target.push_back(rm.dist[f][pv]);
    for (int i = 0; i < nm; ++i) {
      Member& m = mem[i];
      int best = pv;
      double best_err = 0;
      if (i != ref) {
        best_err = kInf;
        const int n = static_cast<int>(meshes[i].V.rows());
        for (int v = 0; v < n; ++v) {
          double s = 0;
          for (std::size_t a = 0; a < target.size() && s < best_err; ++a) {
            const double dd = m.dist[anchors[i][a]][v] - target[a];
            s += dd * dd;
          }
          if (s < best_err) best_err = s, best = v;
        }
        best_err = std::sqrt(best_err / target.size());
      }
      out.landmarks[i].push_back({name, best});
      out.confidence[i].push_back(i == ref ? 1.0 : conf(best_err) * (out.members[i].mirror_ambiguous ? 0.5 : 1.0));
      add_field(m, best);
      anchors[i].push_back(static_cast<int>(m.dist.size()) - 1);
    }
    for (int v = 0; v < nr; ++v) mind[v] = std::min(mind[v], rm.dist.back()[v]);
    if (!report_progress(progress, "landmarks", e, 0.9 + 0.1 * (e + 1) / o.extra_points))
      return R(ErrorCode::Cancelled, "cancelled");
  }
  return out;
}

}  // namespace spherekit
