// Path network construction for the constrained spherical parameterization.
//   Asirvatham, Praun, Hoppe 2005 §4 and §4.1 (greedy insertion of arc/path pairs, swirl
//   avoidance, unswirl operator, edge flips); Praun, Sweldens, Schröder 2001 (spanning tree
//   before cycles, cyclic-order consistency at every feature); Kraevoy & Sheffer 2003
//   (edge-midpoint Steiner vertices, split when a path through them is embedded).
//
// Why the result is a valid pair of triangulations: paths never cross or touch (every
// interior path vertex and every path edge is blocked for later searches), arcs never cross
// (checked on the sphere), and each new path leaves and enters its features inside the
// sector that the new arc occupies among the arcs already there. While the network is a
// forest this keeps the rotation systems at the features equal on both sides; once it is
// connected, every face is a disk, and a chord whose two corners are fixed by the sectors
// splits the corresponding faces on both sides into combinatorially equal halves. So the
// mesh network and the arc network stay isomorphic as embedded graphs, edge by edge.
#include "detail/path_network.h"

#include "detail/split_undo.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <queue>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace spherekit::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

// A search node: a mesh vertex (b < 0) or the midpoint of edge (a, b), a < b.
struct Node {
  int a = -1, b = -1;
  bool vertex() const { return b < 0; }
  bool operator==(const Node& o) const { return a == o.a && b == o.b; }
};

Node mid_node(int p, int q) { return p < q ? Node{p, q} : Node{q, p}; }

// Allowed first/last steps at a feature: ring positions (vertices) and ring faces
// (face i lies between ring[i] and ring[i+1]) inside the sector of the new arc.
struct Sector {
  std::vector<int> ring;
  std::vector<char> vert_ok, face_ok;
};

struct UnionFind {
  std::vector<int> p;
  explicit UnionFind(int n) : p(static_cast<size_t>(n)) { std::iota(p.begin(), p.end(), 0); }
  int find(int x) {
    while (p[static_cast<size_t>(x)] != x) x = p[static_cast<size_t>(x)] = p[static_cast<size_t>(p[static_cast<size_t>(x)])];
    return x;
  }
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    p[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    return true;
  }
};

// Mutable network state (copied to roll back an unswirl or a flip).
struct NetState {
  std::vector<NetworkPath> paths;         // by id; dead ones have a < 0
  std::vector<int> on_path;               // per vertex: id of the path it is interior to, or -1
  std::unordered_set<std::uint64_t> path_edges;
  std::vector<std::vector<int>> at;       // per feature: ids of alive paths
  int alive = 0;
};

class Builder {
 public:
  Builder(const RowMat3d& V, const RowMat3i& F, const std::vector<int>& fv, const std::vector<Eigen::Vector3d>& T,
          const NetworkOptions& opt, const ProgressFn& progress)
      : fv_(fv), T_(T), opt_(opt), progress_(progress) {
    n0_ = static_cast<int>(V.rows());
    X_.resize(static_cast<size_t>(n0_));
    for (int v = 0; v < n0_; ++v) X_[static_cast<size_t>(v)] = V.row(v).transpose();
    F_.resize(static_cast<size_t>(F.rows()));
    face_origin_.resize(F_.size());
    vf_.resize(static_cast<size_t>(n0_));
    for (int f = 0; f < F.rows(); ++f) {
      F_[static_cast<size_t>(f)] = {F(f, 0), F(f, 1), F(f, 2)};
      face_origin_[static_cast<size_t>(f)] = f;
      for (int k = 0; k < 3; ++k) vf_[static_cast<size_t>(F(f, k))].push_back(f);
    }
    k_ = static_cast<int>(fv_.size());
    feat_of_.assign(static_cast<size_t>(n0_), -1);
    for (int i = 0; i < k_; ++i) feat_of_[static_cast<size_t>(fv_[static_cast<size_t>(i)])] = i;
    net_.on_path.assign(static_cast<size_t>(n0_), -1);
    net_.at.resize(static_cast<size_t>(k_));
    for (int i = 0; i < k_; ++i) {
      Eigen::Vector3d e1, e2;
      basis(T_[static_cast<size_t>(i)], e1, e2);
      e1_.push_back(e1);
      e2_.push_back(e2);
    }
  }

  Result<PathNetwork> run() {
    SPHEREKIT_RETURN_IF_ERROR(geodesic_distances());
    find_extremities();
    SPHEREKIT_RETURN_IF_ERROR(greedy());
    if (opt_.unswirl) SPHEREKIT_RETURN_IF_ERROR(unswirl());
    if (opt_.edge_flips) SPHEREKIT_RETURN_IF_ERROR(flip_edges());
    return finish();
  }

 private:
  // ---------------------------------------------------------------- sphere side
  static void basis(const Eigen::Vector3d& n, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
    Eigen::Vector3d a = std::abs(n.x()) < 0.6 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    e1 = (a - a.dot(n) * n).normalized();
    e2 = n.cross(e1);  // e1 x e2 = n: angles grow ccw seen from outside
  }

  // Length (angle) of the minor arc between unit vectors a and b.
  static double arc_length(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::acos(std::clamp(a.dot(b), -1.0, 1.0));
  }

  // Direction angle of the arc from feature i towards feature j, in i's tangent plane.
  double arc_angle(int i, int j) const {
    const Eigen::Vector3d& t = T_[static_cast<size_t>(i)];
    Eigen::Vector3d d = T_[static_cast<size_t>(j)] - T_[static_cast<size_t>(j)].dot(t) * t;
    return std::atan2(d.dot(e2_[static_cast<size_t>(i)]), d.dot(e1_[static_cast<size_t>(i)]));
  }

  static double ccw_delta(double from, double to) {  // in [0, 2 pi)
    double d = std::fmod(to - from, 2 * M_PI);
    if (d < 0) d += 2 * M_PI;
    return d;
  }

  // True if the minor arcs (a, b) and (c, d), with no shared end point, cross.
  static bool arcs_cross(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d) {
    Eigen::Vector3d n1 = a.cross(b);
    double sc = n1.dot(c), sd = n1.dot(d);
    if (!(sc * sd < 0)) return false;
    Eigen::Vector3d q = c + (sc / (sc - sd)) * (d - c);  // where chord cd meets plane (0, a, b)
    return a.cross(q).dot(n1) > 0 && q.cross(b).dot(n1) > 0;
  }

  // Angular distance from point p to the minor arc (a, b), and whether its projection on
  // the great circle falls strictly inside the arc (with `margin` of the arc kept free at each end).
  static bool project_on_arc(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& p,
                             double margin, double* dist, int* side) {
    Eigen::Vector3d n = a.cross(b);
    double nn = n.norm();
    if (!(nn > 0)) return false;
    n /= nn;
    double h = n.dot(p);
    Eigen::Vector3d q = p - h * n;
    double ql = q.norm();
    if (!(ql > 0)) return false;
    q /= ql;
    double len = arc_length(a, b);
    double ta = std::atan2(a.cross(q).dot(n), a.dot(q));
    if (!(ta > margin * len && ta < (1 - margin) * len)) return false;
    *dist = std::asin(std::clamp(std::abs(h), 0.0, 1.0));
    *side = h > 0 ? 1 : -1;
    return true;
  }

  // Is the arc (i, j) compatible with the arcs already in `net`? 0 = yes, else the reason.
  bool arc_valid(const NetState& net, int i, int j) const {
    const Eigen::Vector3d& a = T_[static_cast<size_t>(i)];
    const Eigen::Vector3d& b = T_[static_cast<size_t>(j)];
    if (!(a.dot(b) > -1 + 1e-9)) return false;  // antipodal: no unique minor arc
    for (int c = 0; c < k_; ++c) {
      if (c == i || c == j) continue;
      double dist;
      int side;
      if (project_on_arc(a, b, T_[static_cast<size_t>(c)], 0.0, &dist, &side) && dist < 1e-9) return false;
    }
    for (const auto& p : net.paths) {
      if (p.a < 0) continue;
      if (p.a == i || p.a == j || p.b == i || p.b == j) {
        int s = (p.a == i || p.b == i) ? i : j;
        int o = s == i ? j : i;
        int q = p.a == s ? p.b : p.a;
        if (q == o) return false;  // already linked
        double d = ccw_delta(arc_angle(s, q), arc_angle(s, o));
        if (d < 1e-7 || d > 2 * M_PI - 1e-7) return false;  // overlapping arcs
        continue;
      }
      if (arcs_cross(a, b, T_[static_cast<size_t>(p.a)], T_[static_cast<size_t>(p.b)])) return false;
    }
    return true;
  }

  // Smallest angle the new arc (i, j) makes with an arc already at i or at j (radians).
  double min_arc_angle(const NetState& net, int i, int j) const {
    double m = kInf;
    for (int s : {i, j}) {
      int o = s == i ? j : i;
      double th = arc_angle(s, o);
      for (int pid : net.at[static_cast<size_t>(s)]) {
        const auto& p = net.paths[static_cast<size_t>(pid)];
        int q = p.a == s ? p.b : p.a;
        double d = ccw_delta(arc_angle(s, q), th);
        m = std::min(m, std::min(d, 2 * M_PI - d));
      }
    }
    return m;
  }

  // ---------------------------------------------------------------- mesh side
  // Neighbours of v in ccw order seen from outside; face i of the ring is (v, r[i], r[i+1]).
  void ring(int v, std::vector<int>& out) const {
    thread_local std::vector<std::array<int, 2>> pairs;
    pairs.clear();
    for (int f : vf_[static_cast<size_t>(v)]) {
      const auto& c = F_[static_cast<size_t>(f)];
      int k = c[0] == v ? 0 : c[1] == v ? 1 : 2;
      pairs.push_back({c[static_cast<size_t>((k + 1) % 3)], c[static_cast<size_t>((k + 2) % 3)]});
    }
    out.clear();
    if (pairs.empty()) return;
    int start = pairs[0][0], cur = start;
    do {
      out.push_back(cur);
      int next = -1;
      for (const auto& pr : pairs)
        if (pr[0] == cur) {
          next = pr[1];
          break;
        }
      cur = next;
    } while (cur >= 0 && cur != start && out.size() <= pairs.size());
  }

  static int position(const std::vector<int>& r, int w) {
    for (size_t i = 0; i < r.size(); ++i)
      if (r[i] == w) return static_cast<int>(i);
    return -1;
  }

  Eigen::Vector3d pos(const Node& n) const {
    return n.vertex() ? X_[static_cast<size_t>(n.a)] : Eigen::Vector3d(0.5 * (X_[static_cast<size_t>(n.a)] + X_[static_cast<size_t>(n.b)]));
  }

  // First vertex after feature f along path p.
  static int first_step(const NetworkPath& p, int f) {
    return p.a == f ? p.verts[1] : p.verts[p.verts.size() - 2];
  }

  // The sector at feature f for a new arc towards feature o, given the paths in `net`.
  Sector sector(const NetState& net, int f, int o) const {
    Sector s;
    ring(fv_[static_cast<size_t>(f)], s.ring);
    const int m = static_cast<int>(s.ring.size());
    const auto& here = net.at[static_cast<size_t>(f)];
    if (here.empty()) {
      s.vert_ok.assign(static_cast<size_t>(m), 1);
      s.face_ok.assign(static_cast<size_t>(m), 1);
      return s;
    }
    s.vert_ok.assign(static_cast<size_t>(m), 0);
    s.face_ok.assign(static_cast<size_t>(m), 0);
    double th = arc_angle(f, o);
    int prev = -1, next = -1;
    double dmin = kInf, dmax = -1;
    for (int pid : here) {
      const auto& p = net.paths[static_cast<size_t>(pid)];
      int q = p.a == f ? p.b : p.a;
      double d = ccw_delta(arc_angle(f, q), th);  // how far ccw the new arc is past q's arc
      if (d < dmin) { dmin = d; prev = pid; }
      if (d > dmax) { dmax = d; next = pid; }
    }
    int ip = position(s.ring, first_step(net.paths[static_cast<size_t>(prev)], f));
    int iq = position(s.ring, first_step(net.paths[static_cast<size_t>(next)], f));
    if (ip < 0 || iq < 0) return s;  // inconsistent: nothing allowed
    // Faces ip .. iq-1 and vertices strictly between ip and iq, going ccw (all the way
    // round when there is a single path: ip == iq).
    int i = ip;
    do {
      s.face_ok[static_cast<size_t>(i)] = 1;
      i = (i + 1) % m;
      if (i != iq) s.vert_ok[static_cast<size_t>(i)] = 1;
    } while (i != iq);
    return s;
  }

  bool blocked(const NetState& net, int w, int target) const {
    return net.on_path[static_cast<size_t>(w)] >= 0 || (feat_of_[static_cast<size_t>(w)] >= 0 && w != target);
  }

  // A* from feature fa to feature fb over vertices (and edge midpoints if `steiner`),
  // avoiding the network, leaving and entering inside the given sectors.
  bool search(const NetState& net, int fa, int fb, const Sector& sa, const Sector& sb, bool steiner,
              std::vector<Node>* out, double* length) {
    const int va = fv_[static_cast<size_t>(fa)], vb = fv_[static_cast<size_t>(fb)];
    const int nv = static_cast<int>(X_.size());
    if (static_cast<int>(gv_.size()) < nv) {
      gv_.resize(static_cast<size_t>(nv), kInf);
      pv_.resize(static_cast<size_t>(nv));
      stamp_.resize(static_cast<size_t>(nv), 0);
    }
    ++cur_stamp_;
    gm_.clear();
    const Eigen::Vector3d goal = X_[static_cast<size_t>(vb)];
    struct QE {
      double f, g;
      Node n;
      bool operator>(const QE& o) const {
        if (f != o.f) return f > o.f;
        if (n.a != o.n.a) return n.a > o.n.a;
        return n.b > o.n.b;
      }
    };
    std::priority_queue<QE, std::vector<QE>, std::greater<QE>> heap;
    auto g_of = [&](const Node& n) -> double {
      if (n.vertex()) return stamp_[static_cast<size_t>(n.a)] == cur_stamp_ ? gv_[static_cast<size_t>(n.a)] : kInf;
      auto it = gm_.find(edge_key(n.a, n.b));
      return it == gm_.end() ? kInf : it->second.first;
    };
    auto relax = [&](const Node& from, const Node& to, double g) {
      if (!(g < g_of(to))) return;
      if (to.vertex()) {
        stamp_[static_cast<size_t>(to.a)] = cur_stamp_;
        gv_[static_cast<size_t>(to.a)] = g;
        pv_[static_cast<size_t>(to.a)] = from;
      } else {
        gm_[edge_key(to.a, to.b)] = {g, from};
      }
      heap.push({g + (pos(to) - goal).norm(), g, to});
    };
    const double pen = opt_.steiner_penalty;
    Node start{va, -1};
    stamp_[static_cast<size_t>(va)] = cur_stamp_;
    gv_[static_cast<size_t>(va)] = 0;
    pv_[static_cast<size_t>(va)] = Node{};
    heap.push({(X_[static_cast<size_t>(va)] - goal).norm(), 0, start});
    std::vector<int> r;
    std::array<int, 2> third;
    bool found = false;
    while (!heap.empty()) {
      QE e = heap.top();
      heap.pop();
      if (e.g > g_of(e.n)) continue;
      if (e.n.vertex() && e.n.a == vb) {
        found = true;
        break;
      }
      const Eigen::Vector3d here = pos(e.n);
      if (e.n.vertex()) {
        const int v = e.n.a;
        const bool src = v == va;
        if (src) r = sa.ring;
        else ring(v, r);
        const int m = static_cast<int>(r.size());
        for (int i = 0; i < m; ++i) {
          int w = r[static_cast<size_t>(i)];
          if (src && !sa.vert_ok[static_cast<size_t>(i)]) continue;
          if (w == vb) {
            int j = position(sb.ring, v);
            if (j >= 0 && sb.vert_ok[static_cast<size_t>(j)]) relax(e.n, Node{w, -1}, e.g + (X_[static_cast<size_t>(w)] - here).norm());
            continue;
          }
          if (blocked(net, w, vb)) continue;
          relax(e.n, Node{w, -1}, e.g + (X_[static_cast<size_t>(w)] - here).norm());
        }
        if (steiner)
          for (int i = 0; i < m; ++i) {
            if (src && !sa.face_ok[static_cast<size_t>(i)]) continue;
            int p = r[static_cast<size_t>(i)], q = r[static_cast<size_t>((i + 1) % m)];
            if (net.path_edges.count(edge_key(p, q))) continue;
            Node mn = mid_node(p, q);
            relax(e.n, mn, e.g + pen * (pos(mn) - here).norm());
          }
      } else {
        const int p = e.n.a, q = e.n.b;
        int nt = 0;
        for (int f : vf_[static_cast<size_t>(p)]) {
          const auto& c = F_[static_cast<size_t>(f)];
          if (c[0] != q && c[1] != q && c[2] != q) continue;
          for (int x : c)
            if (x != p && x != q && nt < 2) third[static_cast<size_t>(nt++)] = x;
        }
        for (int t = 0; t < nt; ++t) {
          int x = third[static_cast<size_t>(t)];
          if (x == vb) {
            // Entering vb through its ring face (vb, p, q): that face must be in the sector.
            int j = -1;
            const int m = static_cast<int>(sb.ring.size());
            for (int i = 0; i < m; ++i) {
              int u = sb.ring[static_cast<size_t>(i)], w = sb.ring[static_cast<size_t>((i + 1) % m)];
              if ((u == p && w == q) || (u == q && w == p)) j = i;
            }
            if (j >= 0 && sb.face_ok[static_cast<size_t>(j)]) relax(e.n, Node{x, -1}, e.g + pen * (X_[static_cast<size_t>(x)] - here).norm());
          } else if (x != va && !blocked(net, x, vb)) {
            relax(e.n, Node{x, -1}, e.g + pen * (X_[static_cast<size_t>(x)] - here).norm());
          }
          for (int y : {p, q}) {
            if (net.path_edges.count(edge_key(y, x))) continue;
            Node mn = mid_node(y, x);
            relax(e.n, mn, e.g + pen * (pos(mn) - here).norm());
          }
        }
      }
    }
    if (!found) return false;
    out->clear();
    Node n{vb, -1};
    while (true) {
      out->push_back(n);
      if (n == start) break;
      n = n.vertex() ? pv_[static_cast<size_t>(n.a)] : gm_[edge_key(n.a, n.b)].second;
      if (n.a < 0) return false;
    }
    std::reverse(out->begin(), out->end());
    *length = 0;
    for (size_t i = 1; i < out->size(); ++i) *length += (pos((*out)[i]) - pos((*out)[i - 1])).norm();
    return true;
  }

  // Splits edge (p, q) at its midpoint; returns the new vertex.
  int split_edge(NetState& net, int p, int q) {
    const int s = static_cast<int>(X_.size());
    X_.push_back(0.5 * (X_[static_cast<size_t>(p)] + X_[static_cast<size_t>(q)]));
    vf_.emplace_back();
    net.on_path.resize(X_.size(), -1);
    feat_of_.push_back(-1);
    steiner_parent_.push_back({p, q});
    std::vector<int> faces;
    for (int f : vf_[static_cast<size_t>(p)]) {
      const auto& c = F_[static_cast<size_t>(f)];
      if (c[0] == q || c[1] == q || c[2] == q) faces.push_back(f);
    }
    PathNetwork::Split rec;
    int slot = 0;
    for (int f : faces) {
      auto c = F_[static_cast<size_t>(f)];
      if (slot < 2) {
        rec.f[static_cast<size_t>(slot)] = f;
        rec.old[static_cast<size_t>(slot)] = c;
        rec.g[static_cast<size_t>(slot)] = static_cast<int>(F_.size());
        ++slot;
      }
      // Rotate so that the edge is (c[0], c[1]) in the face's direction.
      while (!((c[0] == p && c[1] == q) || (c[0] == q && c[1] == p))) c = {c[1], c[2], c[0]};
      const int u = c[0], w = c[1], x = c[2];
      const int g = static_cast<int>(F_.size());
      F_[static_cast<size_t>(f)] = {u, s, x};
      F_.push_back({s, w, x});
      face_origin_.push_back(face_origin_[static_cast<size_t>(f)]);
      auto& lw = vf_[static_cast<size_t>(w)];
      lw.erase(std::find(lw.begin(), lw.end(), f));
      lw.push_back(g);
      vf_[static_cast<size_t>(x)].push_back(g);
      vf_[static_cast<size_t>(s)].push_back(f);
      vf_[static_cast<size_t>(s)].push_back(g);
    }
    splits_.push_back(rec);
    return s;
  }

  bool adjacent(int u, int w) const {
    for (int f : vf_[static_cast<size_t>(u)]) {
      const auto& c = F_[static_cast<size_t>(f)];
      if (c[0] == w || c[1] == w || c[2] == w) return true;
    }
    return false;
  }

  // Turns a search result into mesh vertices (splitting the edges of midpoint nodes) and
  // records the path in the network state.
  bool embed(NetState& net, int fa, int fb, const std::vector<Node>& nodes, double length, double geodesic) {
    std::vector<int> verts;
    verts.reserve(nodes.size());
    for (const Node& n : nodes) verts.push_back(n.vertex() ? n.a : split_edge(net, n.a, n.b));
    for (size_t i = 1; i < verts.size(); ++i)
      if (!adjacent(verts[i - 1], verts[i])) return false;
    const int id = static_cast<int>(net.paths.size());
    NetworkPath p;
    p.a = fa;
    p.b = fb;
    p.verts = std::move(verts);
    p.length = length;
    p.geodesic = geodesic;
    for (size_t i = 1; i + 1 < p.verts.size(); ++i) net.on_path[static_cast<size_t>(p.verts[i])] = id;
    for (size_t i = 1; i < p.verts.size(); ++i) net.path_edges.insert(edge_key(p.verts[i - 1], p.verts[i]));
    net.at[static_cast<size_t>(fa)].push_back(id);
    net.at[static_cast<size_t>(fb)].push_back(id);
    net.paths.push_back(std::move(p));
    ++net.alive;
    return true;
  }

  // Rolls the mesh back to when `mark` splits existed (a discarded trial's Steiner vertices
  // go with it, see detail/split_undo.h); `net` must not use any of them.
  void undo_splits_to(NetState& net, size_t mark) {
    undo_splits({&X_, &F_, &vf_, &face_origin_, &steiner_parent_, &splits_}, mark);
    feat_of_.resize(X_.size());
    net.on_path.resize(X_.size(), -1);
  }

  void remove_path(NetState& net, int id) {
    NetworkPath& p = net.paths[static_cast<size_t>(id)];
    for (size_t i = 1; i + 1 < p.verts.size(); ++i) net.on_path[static_cast<size_t>(p.verts[i])] = -1;
    for (size_t i = 1; i < p.verts.size(); ++i) net.path_edges.erase(edge_key(p.verts[i - 1], p.verts[i]));
    for (int f : {p.a, p.b}) {
      auto& l = net.at[static_cast<size_t>(f)];
      l.erase(std::find(l.begin(), l.end(), id));
    }
    p.a = p.b = -1;
    --net.alive;
  }

  // Traces (without embedding) the path for arc (i, j) in the current network.
  bool trace(const NetState& net, int i, int j, std::vector<Node>* nodes, double* length) {
    Sector si = sector(net, i, j), sj = sector(net, j, i);
    // Vertex-only paths first: Steiner vertices only where they are needed or clearly shorter.
    std::vector<Node> plain;
    double lp = kInf;
    bool okp = search(net, i, j, si, sj, false, &plain, &lp);
    std::vector<Node> st;
    double ls = kInf;
    bool oks = opt_.steiner && search(net, i, j, si, sj, true, &st, &ls);
    if (!okp && !oks) return false;
    if (okp && (!oks || lp <= ls * 1.0000001)) {
      *nodes = std::move(plain);
      *length = lp;
    } else {
      *nodes = std::move(st);
      // Report the true length (the search weighs midpoint steps with the penalty).
      double l = 0;
      for (size_t k = 1; k < nodes->size(); ++k) l += (pos((*nodes)[k]) - pos((*nodes)[k - 1])).norm();
      *length = l;
    }
    return true;
  }

  // ---------------------------------------------------------------- heuristics
  Status geodesic_distances() {
    D_.assign(static_cast<size_t>(k_) * static_cast<size_t>(k_), kInf);
    std::vector<double> dist(static_cast<size_t>(n0_));
    std::vector<int> r;
    for (int i = 0; i < k_; ++i) {
      std::fill(dist.begin(), dist.end(), kInf);
      using QE = std::pair<double, int>;
      std::priority_queue<QE, std::vector<QE>, std::greater<QE>> heap;
      const int s = fv_[static_cast<size_t>(i)];
      dist[static_cast<size_t>(s)] = 0;
      heap.push({0, s});
      int found = 0;
      while (!heap.empty() && found < k_) {
        auto [d, v] = heap.top();
        heap.pop();
        if (d > dist[static_cast<size_t>(v)]) continue;
        if (feat_of_[static_cast<size_t>(v)] >= 0) {
          D_[static_cast<size_t>(i) * static_cast<size_t>(k_) + static_cast<size_t>(feat_of_[static_cast<size_t>(v)])] = d;
          ++found;
        }
        ring(v, r);
        for (int w : r) {
          double nd = d + (X_[static_cast<size_t>(w)] - X_[static_cast<size_t>(v)]).norm();
          if (nd < dist[static_cast<size_t>(w)]) {
            dist[static_cast<size_t>(w)] = nd;
            heap.push({nd, w});
          }
        }
      }
      if (found < k_) return Status(ErrorCode::InvalidInput, "mesh is not connected: a feature cannot reach the others");
      if (!report_progress(progress_, "network", 0, -1.0)) return Status(ErrorCode::Cancelled, "cancelled while building the path network");
    }
    return Status();
  }

  double D(int i, int j) const { return D_[static_cast<size_t>(i) * static_cast<size_t>(k_) + static_cast<size_t>(j)]; }

  void find_extremities() {
    // Extremities: largest mean distance to the 3 nearest other features (§4.1).
    std::vector<double> score(static_cast<size_t>(k_));
    for (int i = 0; i < k_; ++i) {
      std::vector<double> d;
      for (int j = 0; j < k_; ++j)
        if (j != i) d.push_back(D(i, j));
      std::sort(d.begin(), d.end());
      size_t n = std::min<size_t>(3, d.size());
      double s = 0;
      for (size_t t = 0; t < n; ++t) s += d[t];
      score[static_cast<size_t>(i)] = n ? s / static_cast<double>(n) : 0;
    }
    std::vector<int> order(static_cast<size_t>(k_));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return score[static_cast<size_t>(a)] > score[static_cast<size_t>(b)]; });
    int n_ext = static_cast<int>(std::ceil(opt_.extremity_fraction * k_));
    extremity_.assign(static_cast<size_t>(k_), 0);
    for (int t = 0; t < n_ext && t < k_; ++t) extremity_[static_cast<size_t>(order[static_cast<size_t>(t)])] = 1;
  }

  // Number of features near arc (i, j) that the traced path leaves on the other side than
  // the arc does (§4.1 sidedness test). The mesh side of a feature is found by a bounded
  // Dijkstra seeded from both sides of the path's interior vertices.
  int sidedness_mismatches(const std::vector<int>& verts, int i, int j) {
    const Eigen::Vector3d& a = T_[static_cast<size_t>(i)];
    const Eigen::Vector3d& b = T_[static_cast<size_t>(j)];
    double arc = arc_length(a, b);
    std::vector<std::pair<int, int>> wanted;  // (vertex, sphere side)
    for (int c = 0; c < k_; ++c) {
      if (c == i || c == j) continue;
      double dist;
      int side;
      if (project_on_arc(a, b, T_[static_cast<size_t>(c)], 0.1, &dist, &side) && dist < 0.5 * arc)
        wanted.push_back({fv_[static_cast<size_t>(c)], side});
    }
    if (wanted.empty() || verts.size() < 3) return 0;
    double len = 0;
    for (size_t t = 1; t < verts.size(); ++t) len += (X_[static_cast<size_t>(verts[t])] - X_[static_cast<size_t>(verts[t - 1])]).norm();
    std::unordered_map<int, std::pair<double, int>> lab;  // vertex -> (dist, side)
    std::unordered_set<int> on(verts.begin(), verts.end());
    using QE = std::tuple<double, int, int>;
    std::priority_queue<QE, std::vector<QE>, std::greater<QE>> heap;
    std::vector<int> r;
    for (size_t t = 1; t + 1 < verts.size(); ++t) {
      int q = verts[t];
      ring(q, r);
      int ip = position(r, verts[t - 1]), in = position(r, verts[t + 1]);
      if (ip < 0 || in < 0) continue;
      const int m = static_cast<int>(r.size());
      // Left of the walk (seen from outside): ccw from the next vertex round to the previous.
      for (int s = (in + 1) % m; s != ip; s = (s + 1) % m) heap.push({(X_[static_cast<size_t>(r[static_cast<size_t>(s)])] - X_[static_cast<size_t>(q)]).norm(), r[static_cast<size_t>(s)], 1});
      for (int s = (ip + 1) % m; s != in; s = (s + 1) % m) heap.push({(X_[static_cast<size_t>(r[static_cast<size_t>(s)])] - X_[static_cast<size_t>(q)]).norm(), r[static_cast<size_t>(s)], -1});
    }
    // The end points seed a neutral label: a feature whose nearest path point is an end
    // point is not beside the path, and has no side.
    for (int e : {verts.front(), verts.back()}) {
      ring(e, r);
      for (int w : r) heap.push({(X_[static_cast<size_t>(w)] - X_[static_cast<size_t>(e)]).norm(), w, 0});
    }
    size_t reached = 0;
    while (!heap.empty() && reached < wanted.size()) {
      auto [d, v, side] = heap.top();
      heap.pop();
      if (on.count(v) || lab.count(v)) continue;
      if (d > 0.5 * len) break;
      lab[v] = {d, side};
      for (const auto& w : wanted)
        if (w.first == v) ++reached;
      ring(v, r);
      for (int w : r)
        if (!on.count(w) && !lab.count(w)) heap.push({d + (X_[static_cast<size_t>(w)] - X_[static_cast<size_t>(v)]).norm(), w, side});
    }
    int bad = 0;
    for (const auto& w : wanted) {
      auto it = lab.find(w.first);
      if (it != lab.end() && it->second.second != 0 && it->second.second != w.second) ++bad;
    }
    return bad;
  }

  // ---------------------------------------------------------------- greedy insertion
  bool any_lonely_extremity() const {
    for (int e = 0; e < k_; ++e)
      if (extremity_[static_cast<size_t>(e)] && net_.at[static_cast<size_t>(e)].empty()) return true;
    return false;
  }

  // The key that ranks candidates: the path's surface length, or (arc_ranking) the
  // geometric mean of it and the arc's angle, so that a pair must be close in both
  // embeddings to go early. By surface length alone, a pair that the surface brings close but
  // the targets put far apart (a warped member: 0.62 of its bounding-box diagonal on the
  // surface, 1.78 rad on the sphere, where its siblings' paths were 0.42-0.51 to another
  // feature) joined the spanning tree early; its long arc then blocked the arcs the other
  // members' networks have, and the member's paths had to wind round (2.17x their shortest
  // route, a map of 0.05 stretch efficiency).
  // The product is scale-free: neither embedding's size changes the order.
  double rank_cost(int i, int j, double surface_length) const {
    if (!opt_.arc_ranking) return surface_length;
    return std::sqrt(surface_length * arc_length(T_[static_cast<size_t>(i)], T_[static_cast<size_t>(j)]));
  }

  Status greedy() {
    // Candidates are ranked by (number of penalties, rank_cost) (§4.1: penalized paths
    // go to the end of the queue). The extremity and angle penalties depend on the network
    // and are re-evaluated whenever a candidate is popped; the sidedness penalty, once
    // incurred, stays.
    struct Cand {
      int cls;
      double cost;
      int i, j;
      bool sided;
      bool operator>(const Cand& o) const {
        if (cls != o.cls) return cls > o.cls;
        if (cost != o.cost) return cost > o.cost;
        if (i != o.i) return i > o.i;
        return j > o.j;
      }
    };
    std::priority_queue<Cand, std::vector<Cand>, std::greater<Cand>> pool;
    for (int i = 0; i < k_; ++i)
      for (int j = i + 1; j < k_; ++j)
        if (D(i, j) < kInf) pool.push({0, rank_cost(i, j, D(i, j)), i, j, false});
    const int needed = 3 * k_ - 6;
    UnionFind uf(k_);
    int components = k_;
    std::vector<Cand> deferred;
    const double min_angle = opt_.min_angle_deg * M_PI / 180.0;
    std::vector<Node> nodes;
    bool lonely_extremity = any_lonely_extremity();
    while (net_.alive < needed && !pool.empty()) {
      Cand c = pool.top();
      pool.pop();
      const int i = c.i, j = c.j;
      if (!arc_valid(net_, i, j)) continue;  // arcs only accumulate: invalid for good
      const bool tree = components == 1;
      if (!tree && uf.find(i) == uf.find(j)) {
        deferred.push_back(c);  // closes a cycle: only after the spanning tree
        continue;
      }
      int cls = c.sided ? 1 : 0;
      if (!tree && lonely_extremity && !extremity_[static_cast<size_t>(i)] && !extremity_[static_cast<size_t>(j)]) ++cls;
      if (min_arc_angle(net_, i, j) < min_angle) ++cls;
      if (cls != c.cls) {
        if (cls > c.cls) ++stats_deferred_;
        c.cls = cls;
        pool.push(c);
        continue;
      }
      double len;
      if (!trace(net_, i, j, &nodes, &len)) continue;  // the network only grows: no path for good
      if (rank_cost(i, j, len) > c.cost * (1 + 1e-9)) {
        c.cost = rank_cost(i, j, len);  // lazy re-evaluation: costs only grow
        pool.push(c);
        continue;
      }
      if (opt_.sidedness && !c.sided) {
        std::vector<int> vs;
        for (const Node& n : nodes) vs.push_back(n.vertex() ? n.a : -1);
        // Midpoint nodes have no vertex yet: judge only vertex paths.
        bool plain = std::find(vs.begin(), vs.end(), -1) == vs.end();
        if (plain && sidedness_mismatches(vs, i, j) > 0) {
          ++stats_deferred_;
          ++stats_sided_;
          c.sided = true;
          ++c.cls;
          pool.push(c);
          continue;
        }
      }
      const size_t mark = splits_.size();
      if (!embed(net_, i, j, nodes, len, D(i, j))) {
        undo_splits_to(net_, mark);
        continue;
      }
      if (uf.unite(i, j)) {
        --components;
        if (components == 1) {
          for (const auto& d : deferred) pool.push(d);
          deferred.clear();
        }
      }
      // Once the last extremity is linked, the candidates deferred for not touching one
      // are ranked by length again.
      if (lonely_extremity && !any_lonely_extremity()) {
        lonely_extremity = false;
        std::vector<Cand> all;
        while (!pool.empty()) {
          all.push_back(pool.top());
          pool.pop();
        }
        for (Cand& x : all) {
          x.cls = x.sided ? 1 : 0;
          pool.push(x);
        }
      }
      if (!report_progress(progress_, "network", net_.alive, static_cast<double>(net_.alive) / needed))
        return Status(ErrorCode::Cancelled, "cancelled while building the path network");
    }
    if (net_.alive < needed)
      return Status(ErrorCode::SolverFailed,
                    "could not complete the feature triangulation (" + std::to_string(net_.alive) + " of " +
                        std::to_string(needed) +
                        " paths): features too close for the mesh resolution, or targets incompatible with the surface");
    return Status();
  }

  // ---------------------------------------------------------------- repair operators
  double ratio(const NetworkPath& p) const { return p.geodesic > 0 ? p.length / p.geodesic : 1.0; }

  // Re-inserts the given arcs (all valid on the sphere together with the rest) in order.
  bool reinsert(NetState& net, const std::vector<std::array<int, 2>>& arcs) {
    std::vector<Node> nodes;
    for (const auto& e : arcs) {
      double len;
      if (!trace(net, e[0], e[1], &nodes, &len)) return false;
      if (!embed(net, e[0], e[1], nodes, len, D(e[0], e[1]))) return false;
    }
    return true;
  }

  Status unswirl() {
    // §4.1: an edge whose end points carry many long paths is likely the centre of a swirl;
    // remove every path at both ends and re-insert them, the previously bad ones first.
    std::unordered_set<std::uint64_t> tried;
    for (int round = 0; round < 4 * k_; ++round) {
      int best = -1, best_score = 1;
      for (size_t id = 0; id < net_.paths.size(); ++id) {
        const auto& p = net_.paths[id];
        if (p.a < 0 || tried.count(edge_key(p.a, p.b))) continue;
        int score = 0;
        for (int f : {p.a, p.b})
          for (int q : net_.at[static_cast<size_t>(f)])
            if (ratio(net_.paths[static_cast<size_t>(q)]) > opt_.long_path_ratio) ++score;
        if (score > best_score) {
          best_score = score;
          best = static_cast<int>(id);
        }
      }
      if (best < 0) break;
      const int fa = net_.paths[static_cast<size_t>(best)].a, fb = net_.paths[static_cast<size_t>(best)].b;
      tried.insert(edge_key(fa, fb));
      NetState trial = net_;
      const size_t mark = splits_.size();
      std::vector<int> ids;
      for (int f : {fa, fb})
        for (int q : trial.at[static_cast<size_t>(f)])
          if (std::find(ids.begin(), ids.end(), q) == ids.end()) ids.push_back(q);
      double before = 0;
      std::vector<std::pair<double, std::array<int, 2>>> arcs;
      for (int q : ids) {
        const auto& p = trial.paths[static_cast<size_t>(q)];
        before += std::max(0.0, ratio(p) - 1);
        arcs.push_back({-ratio(p), {p.a, p.b}});
      }
      std::stable_sort(arcs.begin(), arcs.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      for (int q : ids) remove_path(trial, q);
      std::vector<std::array<int, 2>> order;
      for (const auto& a : arcs) order.push_back(a.second);
      if (!reinsert(trial, order)) {
        undo_splits_to(net_, mark);
        continue;
      }
      double after = 0;
      for (size_t q = static_cast<size_t>(net_.paths.size()); q < trial.paths.size(); ++q)
        if (trial.paths[q].a >= 0) after += std::max(0.0, ratio(trial.paths[q]) - 1);
      if (after < before * 0.9) {
        net_ = std::move(trial);
        ++swirls_fixed_;
      } else {
        undo_splits_to(net_, mark);
      }
      if (!report_progress(progress_, "network", net_.alive, -1.0))
        return Status(ErrorCode::Cancelled, "cancelled while building the path network");
    }
    return Status();
  }

  // The two features opposite path (a, b): c with (a, b, c) ccw and d with (b, a, d) ccw.
  bool opposite(const NetState& net, int a, int b, int* c, int* d) const {
    *c = ccw_pred(net, b, a);  // face left of a->b continues b->c with c = ccw predecessor of a at b
    *d = ccw_pred(net, a, b);
    return *c >= 0 && *d >= 0 && *c != *d;
  }

  // The neighbour of feature f that precedes neighbour g in ccw order around f.
  int ccw_pred(const NetState& net, int f, int g) const {
    double tg = arc_angle(f, g);
    int best = -1;
    double bd = kInf;
    for (int pid : net.at[static_cast<size_t>(f)]) {
      const auto& p = net.paths[static_cast<size_t>(pid)];
      int q = p.a == f ? p.b : p.a;
      if (q == g) continue;
      double d = ccw_delta(arc_angle(f, q), tg);
      if (d < bd) {
        bd = d;
        best = q;
      }
    }
    return best;
  }

  Status flip_edges() {
    for (int pass = 0; pass < 8; ++pass) {
      int flips = 0;
      for (size_t id = 0; id < net_.paths.size(); ++id) {
        const auto p = net_.paths[id];
        if (p.a < 0) continue;
        int c, d;
        if (!opposite(net_, p.a, p.b, &c, &d)) continue;
        const auto& tc = T_[static_cast<size_t>(c)];
        const auto& td = T_[static_cast<size_t>(d)];
        // The new triangles (c, a, d) and (d, b, c) must be ccw on the sphere.
        if (!(tc.cross(T_[static_cast<size_t>(p.a)]).dot(td) > 0)) continue;
        if (!(td.cross(T_[static_cast<size_t>(p.b)]).dot(tc) > 0)) continue;
        NetState trial = net_;
        remove_path(trial, static_cast<int>(id));
        if (!arc_valid(trial, c, d)) continue;
        if (min_arc_angle(trial, c, d) < opt_.min_angle_deg * M_PI / 180.0 && min_arc_angle(trial, c, d) < min_arc_angle(net_, p.a, p.b)) continue;
        std::vector<Node> nodes;
        double len;
        if (!trace(trial, c, d, &nodes, &len)) continue;
        // Shorter by the insertion's ranking (rank_cost), or the flip would undo it: a pair
        // close on the surface but far apart among the targets came back as the diagonal.
        if (!(rank_cost(c, d, len) < rank_cost(p.a, p.b, p.length) * 0.999)) continue;
        const size_t mark = splits_.size();
        if (!embed(trial, c, d, nodes, len, D(c, d))) {
          undo_splits_to(net_, mark);
          continue;
        }
        net_ = std::move(trial);
        ++flips;
        ++flips_;
      }
      if (!report_progress(progress_, "network", net_.alive, -1.0))
        return Status(ErrorCode::Cancelled, "cancelled while building the path network");
      if (flips == 0) break;
    }
    return Status();
  }

  // ---------------------------------------------------------------- output
  Result<PathNetwork> finish() {
    PathNetwork out;
    // Faces of the arc network: walking a->b, the face on the left continues with b->c
    // where c precedes a in ccw order around b.
    std::unordered_set<std::uint64_t> seen;  // directed edges (a,b) as a*k+b
    for (const auto& p : net_.paths) {
      if (p.a < 0) continue;
      for (int dir = 0; dir < 2; ++dir) {
        int a = dir ? p.b : p.a, b = dir ? p.a : p.b;
        std::uint64_t key = static_cast<std::uint64_t>(a) * static_cast<std::uint64_t>(k_) + static_cast<std::uint64_t>(b);
        if (seen.count(key)) continue;
        std::vector<int> face;
        int x = a, y = b;
        for (int guard = 0; guard < 3 * k_; ++guard) {
          seen.insert(static_cast<std::uint64_t>(x) * static_cast<std::uint64_t>(k_) + static_cast<std::uint64_t>(y));
          face.push_back(x);
          int z = ccw_pred(net_, y, x);
          x = y;
          y = z;
          if (x == a && y == b) break;
          if (z < 0) break;
        }
        if (face.size() != 3)
          return Status(ErrorCode::Internal, "path network has a face with " + std::to_string(face.size()) + " sides");
        const auto& t0 = T_[static_cast<size_t>(face[0])];
        const auto& t1 = T_[static_cast<size_t>(face[1])];
        const auto& t2 = T_[static_cast<size_t>(face[2])];
        if (!(t0.cross(t1).dot(t2) > 0))
          return Status(ErrorCode::SolverFailed,
                        "the feature triangulation has a spherical triangle larger than a hemisphere "
                        "(targets too concentrated on one side of the sphere)");
        out.triangles.push_back({face[0], face[1], face[2]});
      }
    }
    if (static_cast<int>(out.triangles.size()) != 2 * k_ - 4)
      return Status(ErrorCode::Internal, "path network does not triangulate the sphere");
    for (auto& p : net_.paths)
      if (p.a >= 0) {
        out.total_length += p.length;
        out.max_ratio = std::max(out.max_ratio, ratio(p));
        out.paths.push_back(p);
      }
    out.X = std::move(X_);
    out.F = std::move(F_);
    out.face_origin = std::move(face_origin_);
    out.steiner_parent = std::move(steiner_parent_);
    out.splits = std::move(splits_);
    out.feature_vertex = fv_;
    out.swirls_fixed = swirls_fixed_;
    out.edge_flips = flips_;
    out.deferred = stats_deferred_;
    out.sidedness_deferred = stats_sided_;
    return out;
  }

  // Mesh (grows with Steiner splits).
  std::vector<Eigen::Vector3d> X_;
  std::vector<std::array<int, 3>> F_;
  std::vector<int> face_origin_;
  std::vector<std::vector<int>> vf_;
  std::vector<std::array<int, 2>> steiner_parent_;
  std::vector<PathNetwork::Split> splits_;
  int n0_ = 0;
  // Features.
  std::vector<int> fv_;
  std::vector<Eigen::Vector3d> T_, e1_, e2_;
  int k_ = 0;
  std::vector<int> feat_of_;
  std::vector<double> D_;
  std::vector<char> extremity_;
  const NetworkOptions& opt_;
  const ProgressFn& progress_;
  NetState net_;
  int swirls_fixed_ = 0, flips_ = 0, stats_deferred_ = 0, stats_sided_ = 0;
  // Search scratch.
  std::vector<double> gv_;
  std::vector<Node> pv_;
  std::vector<std::uint32_t> stamp_;
  std::uint32_t cur_stamp_ = 0;
  std::unordered_map<std::uint64_t, std::pair<double, Node>> gm_;
};

}  // namespace

bool targets_surround_origin(const std::vector<Eigen::Vector3d>& targets, double margin) {
  // The points surround the origin iff no direction x has x . t >= -margin for all t. Maximize
  // min_t x . t over unit x by projected subgradient ascent from several starts.
  if (targets.size() < 4) return false;
  const Eigen::Vector3d starts[] = {
      {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  double best = -kInf;
  auto eval = [&](const Eigen::Vector3d& x, int* arg) {
    double m = kInf;
    for (size_t i = 0; i < targets.size(); ++i) {
      double s = x.dot(targets[i]);
      if (s < m) {
        m = s;
        *arg = static_cast<int>(i);
      }
    }
    return m;
  };
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& t : targets) mean += t;
  std::vector<Eigen::Vector3d> init(std::begin(starts), std::end(starts));
  if (mean.norm() > 0) init.push_back(mean.normalized());
  for (const auto& s0 : init) {
    Eigen::Vector3d x = s0;
    double step = 0.5;
    for (int it = 0; it < 300; ++it) {
      int arg = 0;
      double m = eval(x, &arg);
      best = std::max(best, m);
      x = (x + step * targets[static_cast<size_t>(arg)]).normalized();
      step *= 0.98;
    }
  }
  return best < -margin;
}

Result<PathNetwork> build_path_network(const RowMat3d& V, const RowMat3i& F, const std::vector<int>& feature_vertex,
                                       const std::vector<Eigen::Vector3d>& targets, const NetworkOptions& options,
                                       const ProgressFn& progress) {
  if (feature_vertex.size() != targets.size())
    return Status(ErrorCode::InvalidArgument, "one target per feature is required");
  if (feature_vertex.size() < 4)
    return Status(ErrorCode::InvalidArgument, "a path network needs at least 4 features");
  std::vector<int> sorted = feature_vertex;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    return Status(ErrorCode::InvalidInput, "two features are on the same vertex");
  for (int v : feature_vertex)
    if (v < 0 || v >= V.rows()) return Status(ErrorCode::InvalidInput, "feature vertex index out of range");
  Builder b(V, F, feature_vertex, targets, options, progress);
  return b.run();
}

}  // namespace spherekit::detail
