// Dense landmark sets (see dense_landmarks.h).
#include "dense_landmarks.h"

#include <algorithm>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <queue>

namespace spherekit::test {
namespace {

std::vector<std::vector<int>> neighbours(const TriMesh& m) {
  std::vector<std::vector<int>> adj(static_cast<size_t>(m.V.rows()));
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = m.F(f, c), b = m.F(f, (c + 1) % 3);
      adj[static_cast<size_t>(a)].push_back(b);
      adj[static_cast<size_t>(b)].push_back(a);
    }
  for (auto& l : adj) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  return adj;
}

}  // namespace

std::vector<std::vector<int>> farthest_point_landmarks(const TriMesh& m0, const std::vector<CarryFn>& carry, int k) {
  const auto adj = neighbours(m0);
  const size_t n = static_cast<size_t>(m0.V.rows());
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<char> covered(n, 1), tried(n, 0);
  for (size_t v = 0; v < n; ++v)
    for (const CarryFn& c : carry)
      if (c(static_cast<int>(v)) < 0) covered[v] = 0;
  std::vector<std::vector<int>> out(carry.size() + 1);
  std::vector<std::vector<int>> used(carry.size() + 1);
  int next = 0;
  while (static_cast<int>(out[0].size()) < k && next >= 0) {
    std::vector<int> partner{next};
    for (const CarryFn& c : carry) partner.push_back(c(next));
    bool fresh = covered[static_cast<size_t>(next)] != 0;
    for (size_t m = 0; m < partner.size() && fresh; ++m)
      fresh = std::find(used[m].begin(), used[m].end(), partner[m]) == used[m].end();
    if (fresh)
      for (size_t m = 0; m < partner.size(); ++m) {
        out[m].push_back(partner[m]);
        used[m].push_back(partner[m]);
      }
    tried[static_cast<size_t>(next)] = 1;
    // Dijkstra from the new sample, only where it lowers the distance to the sample set.
    using QE = std::pair<double, int>;
    std::priority_queue<QE, std::vector<QE>, std::greater<QE>> heap;
    dist[static_cast<size_t>(next)] = 0;
    heap.push({0.0, next});
    while (!heap.empty()) {
      const auto [d, v] = heap.top();
      heap.pop();
      if (d > dist[static_cast<size_t>(v)]) continue;
      for (int w : adj[static_cast<size_t>(v)]) {
        const double nd = d + (m0.V.row(v) - m0.V.row(w)).norm();
        if (nd < dist[static_cast<size_t>(w)]) {
          dist[static_cast<size_t>(w)] = nd;
          heap.push({nd, w});
        }
      }
    }
    next = -1;
    double best = -1;
    for (size_t v = 0; v < n; ++v)
      if (!tried[v] && covered[v] && dist[v] > best) {
        best = dist[v];
        next = static_cast<int>(v);
      }
  }
  return out;
}

CarryFn carry_through_samples(const std::vector<int>& corr0, const std::vector<int>& corr1) {
  auto first = std::make_shared<std::map<int, int>>();
  for (size_t s = 0; s < corr0.size() && s < corr1.size(); ++s) first->emplace(corr0[s], corr1[s]);
  return [first](int v) {
    auto it = first->find(v);
    return it == first->end() ? -1 : it->second;
  };
}

std::vector<int> read_int_list(const std::string& path) {
  std::vector<int> r;
  std::ifstream in(path);
  for (int x; in >> x;) r.push_back(x);
  return r;
}

int min_hops_between(const TriMesh& m, const std::vector<int>& verts) {
  if (verts.size() < 2) return 0;
  const auto adj = neighbours(m);
  std::vector<int> hops(static_cast<size_t>(m.V.rows()), -1), source(hops.size(), -1);
  std::queue<int> q;
  for (int v : verts) {
    hops[static_cast<size_t>(v)] = 0;
    source[static_cast<size_t>(v)] = v;
    q.push(v);
  }
  // Multi-source BFS: the first meeting of two sources' fronts gives the fewest edges.
  int best = std::numeric_limits<int>::max();
  while (!q.empty()) {
    const int v = q.front();
    q.pop();
    for (int w : adj[static_cast<size_t>(v)]) {
      if (hops[static_cast<size_t>(w)] < 0) {
        hops[static_cast<size_t>(w)] = hops[static_cast<size_t>(v)] + 1;
        source[static_cast<size_t>(w)] = source[static_cast<size_t>(v)];
        q.push(w);
      } else if (source[static_cast<size_t>(w)] != source[static_cast<size_t>(v)]) {
        best = std::min(best, hops[static_cast<size_t>(v)] + hops[static_cast<size_t>(w)] + 1);
      }
    }
  }
  return best;
}

}  // namespace spherekit::test
