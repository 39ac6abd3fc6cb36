// Structural checks of triangle meshes (counts in the style of shared/tools/meshcheck.py,
// the project's independent checker) and the genus-0 admission test of every stage.
//
// Design: one pass over the faces for index/degeneracy problems, then an edge table built
// by bucketing half-edges by their smaller endpoint (O(F), see build_topology), then
// union-find passes for fans and components. Everything is O(V + F); nothing is hashed or
// globally sorted, so igea (270k faces) takes a few tens of milliseconds.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "detail/check_topology.h"
#include "spherekit/check_mesh.h"

namespace spherekit {
namespace detail {
namespace {

// Union-find with path halving; union by smaller index keeps results deterministic.
class DisjointSets {
 public:
  explicit DisjointSets(int n) : parent_(static_cast<size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    parent_[a] = b;
  }

 private:
  std::vector<int> parent_;
};

bool face_usable(const TriMesh& m, Eigen::Index f) {
  const int nv = static_cast<int>(m.V.rows());
  const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
  if (a < 0 || b < 0 || c < 0 || a >= nv || b >= nv || c >= nv) return false;
  return a != b && b != c && a != c;
}

}  // namespace

MeshTopology build_topology(const TriMesh& mesh) {
  MeshTopology t;
  t.num_vertices = static_cast<int>(mesh.V.rows());
  t.num_faces = static_cast<int>(mesh.F.rows());
  const int nh = 3 * t.num_faces;
  t.usable.assign(static_cast<size_t>(t.num_faces), 0);
  for (int f = 0; f < t.num_faces; ++f) t.usable[f] = face_usable(mesh, f) ? 1 : 0;

  // Bucket half-edges by their smaller endpoint (counting sort), then group each bucket
  // by the larger endpoint. Buckets hold about six half-edges, so sorting them is cheap.
  std::vector<int> start(static_cast<size_t>(t.num_vertices) + 1, 0);
  for (int h = 0; h < nh; ++h)
    if (t.usable[h / 3]) ++start[std::min(he_from(mesh, h), he_to(mesh, h)) + 1];
  for (int v = 0; v < t.num_vertices; ++v) start[v + 1] += start[v];
  std::vector<int> bucket(static_cast<size_t>(start.back()));
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int h = 0; h < nh; ++h)
      if (t.usable[h / 3]) bucket[fill[std::min(he_from(mesh, h), he_to(mesh, h))]++] = h;
  }
  t.he_edge.assign(static_cast<size_t>(nh), -1);
  t.twin.assign(static_cast<size_t>(nh), -1);
  t.edge_he.reserve(bucket.size());
  t.edge_start.reserve(bucket.size() / 2 + 2);
  auto hi = [&](int h) { return std::max(he_from(mesh, h), he_to(mesh, h)); };
  for (int v = 0; v < t.num_vertices; ++v) {
    auto first = bucket.begin() + start[v], last = bucket.begin() + start[v + 1];
    std::sort(first, last, [&](int a, int b) { return hi(a) != hi(b) ? hi(a) < hi(b) : a < b; });
    for (auto it = first; it != last;) {
      auto run = it;
      while (run != last && hi(*run) == hi(*it)) ++run;
      const int e = static_cast<int>(t.edge_start.size());
      t.edge_start.push_back(static_cast<int>(t.edge_he.size()));
      for (auto k = it; k != run; ++k) {
        t.edge_he.push_back(*k);
        t.he_edge[*k] = e;
      }
      if (run - it == 2) {
        t.twin[*it] = *(it + 1);
        t.twin[*(it + 1)] = *it;
      }
      it = run;
    }
  }
  t.num_edges = static_cast<int>(t.edge_start.size());
  t.edge_start.push_back(static_cast<int>(t.edge_he.size()));
  return t;
}

std::vector<int> corner_fans(const TriMesh& mesh, const MeshTopology& topo) {
  const int nc = 3 * topo.num_faces;
  DisjointSets sets(nc);
  // Across a two-face edge, the corners at each endpoint are joined. Half-edge h starts at
  // corner h and ends at corner he_next(h); when both faces use the edge in the same
  // direction (an orientation conflict) the start corners are at the same vertex.
  for (int e = 0; e < topo.num_edges; ++e) {
    if (topo.edge_size(e) != 2) continue;
    const int h1 = topo.edge_he[topo.edge_start[e]], h2 = topo.edge_he[topo.edge_start[e] + 1];
    if (he_from(mesh, h1) == he_from(mesh, h2)) {
      sets.join(h1, h2);
      sets.join(he_next(h1), he_next(h2));
    } else {
      sets.join(h1, he_next(h2));
      sets.join(he_next(h1), h2);
    }
  }
  std::vector<int> fan(static_cast<size_t>(nc), -1);
  for (int c = 0; c < nc; ++c)
    if (topo.usable[c / 3]) fan[c] = sets.find(c);
  return fan;
}

std::vector<int> fans_per_vertex(const TriMesh& mesh, const std::vector<int>& fan_of_corner) {
  // Every fan contains corners of one vertex only, so a vertex has as many fans as it has
  // corners that are their fan's representative.
  std::vector<int> fans(static_cast<size_t>(mesh.V.rows()), 0);
  for (int c = 0; c < static_cast<int>(fan_of_corner.size()); ++c)
    if (fan_of_corner[c] == c) ++fans[mesh.F(c / 3, c % 3)];
  return fans;
}

std::vector<std::vector<int>> trace_boundary_loops(const TriMesh& mesh, const MeshTopology& topo, bool* ok) {
  *ok = true;
  const int nh = 3 * topo.num_faces;
  auto is_boundary = [&](int h) { return topo.he_edge[h] >= 0 && topo.edge_size(topo.he_edge[h]) == 1; };
  // Successor of boundary half-edge a->b: leave b inside the same face, then rotate around
  // b across two-face edges until the outgoing half-edge is a boundary one. The rotation
  // stays in one fan, which is a path of faces ending in two boundary edges.
  auto successor = [&](int h) {
    int g = he_next(h);
    for (int guard = 0; guard < nh && topo.twin[g] >= 0; ++guard) g = he_next(topo.twin[g]);
    return (topo.twin[g] < 0 && is_boundary(g) && he_from(mesh, g) == he_to(mesh, h)) ? g : -1;
  };
  std::vector<std::vector<int>> loops;
  std::vector<char> seen(static_cast<size_t>(nh), 0);
  for (int h0 = 0; h0 < nh; ++h0) {
    if (!is_boundary(h0) || seen[h0]) continue;
    std::vector<int> loop;
    int h = h0;
    do {
      if (h < 0 || seen[h]) {
        *ok = false;
        return {};
      }
      seen[h] = 1;
      loop.push_back(h);
      h = successor(h);
    } while (h != h0);
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace detail

namespace {

using detail::MeshTopology;

void count_vertex_and_face_problems(const TriMesh& mesh, MeshCheck& c, std::vector<char>& referenced) {
  const int nv = c.vertices;
  for (int v = 0; v < nv; ++v) {
    if (!mesh.V.row(v).allFinite()) {
      if (c.nonfinite_vertices++ == 0) c.first_nonfinite_vertex = v;
    }
  }
  referenced.assign(static_cast<size_t>(nv), 0);
  for (int f = 0; f < c.faces; ++f) {
    bool valid = true;
    for (int k = 0; k < 3; ++k) {
      const int i = mesh.F(f, k);
      if (i >= 0 && i < nv) continue;
      valid = false;
      if (c.invalid_indices++ == 0) {
        c.first_invalid_face = f;
        c.first_invalid_index = i;
      }
    }
    if (!valid) continue;
    for (int k = 0; k < 3; ++k) referenced[mesh.F(f, k)] = 1;
    if (mesh.F(f, 0) == mesh.F(f, 1) || mesh.F(f, 1) == mesh.F(f, 2) || mesh.F(f, 0) == mesh.F(f, 2)) {
      if (c.degenerate_faces++ == 0) c.first_degenerate_face = f;
    }
  }
  Eigen::RowVector3d lo = Eigen::RowVector3d::Constant(INFINITY), hi = -lo;
  for (int v = 0; v < nv; ++v) {
    if (!referenced[v]) {
      if (c.unreferenced_vertices++ == 0) c.first_unreferenced_vertex = v;
      continue;
    }
    if (!mesh.V.row(v).allFinite()) continue;
    lo = lo.cwiseMin(mesh.V.row(v));
    hi = hi.cwiseMax(mesh.V.row(v));
  }
  c.bbox_diag = (hi.array() >= lo.array()).all() ? (hi - lo).norm() : 0.0;
}

void count_zero_area_faces(const TriMesh& mesh, const MeshTopology& topo, MeshCheck& c) {
  const double limit = kZeroAreaRelTolerance * c.bbox_diag * c.bbox_diag;
  for (int f = 0; f < c.faces; ++f) {
    if (!topo.usable[f]) continue;
    const Eigen::RowVector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::RowVector3d e1 = mesh.V.row(mesh.F(f, 1)) - a, e2 = mesh.V.row(mesh.F(f, 2)) - a;
    const double twice_area = e1.cross(e2).norm();
    if (twice_area <= limit) {  // false for NaN: non-finite faces are counted elsewhere
      if (c.zero_area_faces++ == 0) c.first_zero_area_face = f;
    }
  }
}

// Edge classes, orientation conflicts and duplicate faces, all from the edge table.
void count_edge_problems(const TriMesh& mesh, const MeshTopology& topo, MeshCheck& c) {
  c.edges = topo.num_edges;
  for (int e = 0; e < topo.num_edges; ++e) {
    const int n = topo.edge_size(e);
    const int h1 = topo.edge_he[topo.edge_start[e]];
    if (n == 1) {
      ++c.boundary_edges;
    } else if (n > 2) {
      if (c.nonmanifold_edges++ < kMaxReportedIds) {
        const int a = detail::he_from(mesh, h1), b = detail::he_to(mesh, h1);
        c.nonmanifold_edge_ids.push_back(std::min(a, b));
        c.nonmanifold_edge_ids.push_back(std::max(a, b));
        c.nonmanifold_edge_face_counts.push_back(n);
      }
    } else if (detail::he_from(mesh, h1) == detail::he_from(mesh, topo.edge_he[topo.edge_start[e] + 1])) {
      if (c.orientation_conflicts++ == 0) {
        c.first_conflict_from = detail::he_from(mesh, h1);
        c.first_conflict_to = detail::he_to(mesh, h1);
      }
    }
  }
  // Two faces with the same vertex set share all their edges, in particular the edge of
  // their half-edge 3f, so comparing within that edge's group finds every duplicate.
  auto sorted = [&](int f) {
    std::array<int, 3> s = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    std::sort(s.begin(), s.end());
    return s;
  };
  for (int f = 0; f < c.faces; ++f) {
    if (!topo.usable[f]) continue;
    const int e = topo.he_edge[3 * f];
    if (topo.edge_size(e) < 2) continue;
    const auto key = sorted(f);
    for (int k = topo.edge_start[e]; k < topo.edge_start[e + 1]; ++k) {
      const int g = topo.edge_he[k] / 3;
      if (g >= f || sorted(g) != key) continue;
      if (c.duplicate_faces++ == 0) {
        c.first_duplicate_face = f;
        c.first_duplicate_of = g;
      }
      break;
    }
  }
}

void count_nonmanifold_vertices(const TriMesh& mesh, const MeshTopology& topo, MeshCheck& c) {
  const std::vector<int> fans = detail::fans_per_vertex(mesh, detail::corner_fans(mesh, topo));
  for (int v = 0; v < c.vertices; ++v) {
    if (fans[v] <= 1) continue;
    if (c.nonmanifold_vertices++ < kMaxReportedIds) {
      c.nonmanifold_vertex_ids.push_back(v);
      c.nonmanifold_vertex_fans.push_back(fans[v]);
    }
  }
}

// Components over faces via shared vertices; degenerate faces connect their vertices too.
void count_components(const TriMesh& mesh, const std::vector<char>& referenced, MeshCheck& c) {
  detail::DisjointSets sets(c.vertices);
  for (int f = 0; f < c.faces; ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), d = mesh.F(f, 2);
    if (a < 0 || b < 0 || d < 0 || a >= c.vertices || b >= c.vertices || d >= c.vertices) continue;
    sets.join(a, b);
    sets.join(b, d);
  }
  for (int v = 0; v < c.vertices; ++v)
    if (referenced[v] && sets.find(v) == v) ++c.components;
}

int count_boundary_loops(const TriMesh& mesh, const MeshTopology& topo, const MeshCheck& c) {
  if (c.boundary_edges == 0) return 0;
  if (c.nonmanifold_edges == 0 && c.orientation_conflicts == 0) {
    bool ok = false;
    const auto loops = detail::trace_boundary_loops(mesh, topo, &ok);
    if (ok) return static_cast<int>(loops.size());
  }
  // Without a consistent orientation the loops are not well defined: count the connected
  // pieces of the boundary-edge graph instead (what meshcheck.py does in every case).
  detail::DisjointSets sets(c.vertices);
  std::vector<char> on_boundary(static_cast<size_t>(c.vertices), 0);
  for (int e = 0; e < topo.num_edges; ++e) {
    if (topo.edge_size(e) != 1) continue;
    const int h = topo.edge_he[topo.edge_start[e]];
    const int a = detail::he_from(mesh, h), b = detail::he_to(mesh, h);
    on_boundary[a] = on_boundary[b] = 1;
    sets.join(a, b);
  }
  int loops = 0;
  for (int v = 0; v < c.vertices; ++v)
    if (on_boundary[v] && sets.find(v) == v) ++loops;
  return loops;
}

// Orientable iff faces can be 2-coloured (flip / keep) so that every two-face edge ends up
// used in opposite directions: a breadth-first propagation of flips.
bool is_orientable(const TriMesh& mesh, const MeshTopology& topo) {
  std::vector<signed char> flip(static_cast<size_t>(topo.num_faces), -1);
  std::vector<int> queue;
  for (int seed = 0; seed < topo.num_faces; ++seed) {
    if (!topo.usable[seed] || flip[seed] >= 0) continue;
    flip[seed] = 0;
    queue.assign(1, seed);
    while (!queue.empty()) {
      const int f = queue.back();
      queue.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int h = 3 * f + k, g = topo.twin[h];
        if (g < 0) continue;
        const bool same_direction = detail::he_from(mesh, h) == detail::he_from(mesh, g);
        const signed char want = static_cast<signed char>(flip[f] ^ (same_direction ? 1 : 0));
        if (flip[g / 3] < 0) {
          flip[g / 3] = want;
          queue.push_back(g / 3);
        } else if (flip[g / 3] != want) {
          return false;
        }
      }
    }
  }
  return true;
}

// The first problem that keeps `c` from being parameterized, or "" if there is none.
std::string first_problem(const MeshCheck& c, bool allow_boundary) {
  auto s = [](auto x) { return std::to_string(x); };
  auto plural = [&](int n, const char* one, const char* many) { return s(n) + " " + (n == 1 ? one : many); };
  if (c.faces == 0) return "mesh has no faces";
  if (c.invalid_indices > 0)
    return "face " + s(c.first_invalid_face) + " has vertex index " + s(c.first_invalid_index) +
           " outside [0, " + s(c.vertices) + ") (" + plural(c.invalid_indices, "invalid index", "invalid indices") + ")";
  if (c.nonfinite_vertices > 0)
    return "vertex " + s(c.first_nonfinite_vertex) + " has a NaN/Inf coordinate (" +
           plural(c.nonfinite_vertices, "such vertex", "such vertices") + ")";
  if (c.degenerate_faces > 0)
    return "face " + s(c.first_degenerate_face) + " repeats a vertex (degenerate; " +
           plural(c.degenerate_faces, "such face", "such faces") + "); remove degenerate faces";
  if (c.duplicate_faces > 0)
    return "face " + s(c.first_duplicate_face) + " has the same vertices as face " + s(c.first_duplicate_of) +
           " (" + plural(c.duplicate_faces, "duplicate face", "duplicate faces") + "); remove duplicates";
  if (c.nonmanifold_edges > 0) {
    std::string where = c.nonmanifold_edge_ids.size() >= 2
                            ? "edge (" + s(c.nonmanifold_edge_ids[0]) + "," + s(c.nonmanifold_edge_ids[1]) +
                                  ") is shared by " + s(c.nonmanifold_edge_face_counts[0]) + " faces"
                            : "an edge is shared by more than 2 faces";
    return where + " (non-manifold; " + plural(c.nonmanifold_edges, "such edge", "such edges") + ")";
  }
  if (c.nonmanifold_vertices > 0) {
    std::string where = !c.nonmanifold_vertex_ids.empty()
                            ? "vertex " + s(c.nonmanifold_vertex_ids[0]) + " is non-manifold (" +
                                  s(c.nonmanifold_vertex_fans[0]) + " face fans meet there"
                            : "a vertex is non-manifold (several face fans meet there";
    return where + "; " + plural(c.nonmanifold_vertices, "such vertex", "such vertices") +
           "); run `spherekit check --repair`";
  }
  if (c.components != 1)
    return "mesh has " + s(c.components) + " connected components; split it or pass one component";
  if (c.unreferenced_vertices > 0)
    return "vertex " + s(c.first_unreferenced_vertex) + " is used by no face (" +
           plural(c.unreferenced_vertices, "unreferenced vertex", "unreferenced vertices") +
           "); a sphere map needs every vertex on the surface: drop them with `spherekit check MESH --repair -o "
           "OUT` (vertex numbers change: remap landmark files)";
  if (!c.orientable) return "mesh is not orientable (like a Moebius strip); no consistent face orientation exists";
  if (c.orientation_conflicts > 0)
    return "faces are inconsistently oriented (" + plural(c.orientation_conflicts, "edge", "edges") +
           " used twice in the same direction, first (" + s(c.first_conflict_from) + "," + s(c.first_conflict_to) +
           ")); reorient the faces consistently";
  if (c.genus != 0) {
    const std::string numbers = "(Euler characteristic " + s(c.euler) + ", " +
                                plural(c.boundary_loops, "boundary loop", "boundary loops") + ")";
    if (c.genus < 0) return "mesh has no integer genus " + numbers + "; only genus-0 surfaces can be mapped to the sphere";
    return "mesh has genus " + s(c.genus) + " " + numbers + "; only genus-0 surfaces can be mapped to the sphere";
  }
  if (!allow_boundary && c.boundary_loops > 0)
    return "mesh has " + plural(c.boundary_loops, "boundary loop", "boundary loops") +
           " (holes); close them first (fill_holes)";
  return "";
}

}  // namespace

MeshCheck check_mesh(const TriMesh& mesh) {
  MeshCheck c;
  c.vertices = static_cast<int>(mesh.V.rows());
  c.faces = static_cast<int>(mesh.F.rows());
  std::vector<char> referenced;
  count_vertex_and_face_problems(mesh, c, referenced);
  const MeshTopology topo = detail::build_topology(mesh);
  count_zero_area_faces(mesh, topo, c);
  count_edge_problems(mesh, topo, c);
  count_nonmanifold_vertices(mesh, topo, c);
  count_components(mesh, referenced, c);
  c.boundary_loops = count_boundary_loops(mesh, topo, c);
  c.orientable = c.orientation_conflicts == 0 || is_orientable(mesh, topo);

  const int usable_faces = static_cast<int>(std::count(topo.usable.begin(), topo.usable.end(), 1));
  c.euler = (c.vertices - c.unreferenced_vertices) - c.edges + usable_faces;
  c.genus = -1;
  if (c.components == 1 && c.nonmanifold_edges == 0 && c.nonmanifold_vertices == 0 && c.orientable &&
      usable_faces > 0) {
    const int twice_genus = 2 - c.euler - c.boundary_loops;
    if (twice_genus >= 0 && twice_genus % 2 == 0) c.genus = twice_genus / 2;
  }
  return c;
}

bool MeshCheck::genus0_ok() const { return first_problem(*this, true).empty(); }

Status require_genus0(const MeshCheck& check, bool allow_boundary) {
  const std::string problem = first_problem(check, allow_boundary);
  if (problem.empty()) return Status::ok_status();
  return Status(ErrorCode::InvalidInput, problem);
}

Status require_supported_coordinates(const TriMesh& mesh) {
  if (mesh.V.rows() == 0) return Status::ok_status();
  char text[200];
  const double largest = mesh.V.cwiseAbs().maxCoeff();
  if (!(largest <= kMaxCoordinate)) {
    std::snprintf(text, sizeof text,
                  "coordinates reach %.3g, beyond the supported |x| <= %.0e (lengths, areas and stretch would "
                  "overflow); scale the mesh down",
                  largest, kMaxCoordinate);
    return Status(ErrorCode::InvalidInput, text);
  }
  // No overflow below kMaxCoordinate: the diagonal is at most 2 sqrt(3) kMaxCoordinate.
  const double extent = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  if (extent == 0) return Status(ErrorCode::InvalidInput, "all vertices are at one point (zero extent)");
  if (extent < kMinExtent) {
    std::snprintf(text, sizeof text,
                  "the mesh is %.3g across, below the supported %.0e (areas and stretch would underflow); scale "
                  "the mesh up",
                  extent, kMinExtent);
    return Status(ErrorCode::InvalidInput, text);
  }
  return Status::ok_status();
}

Status require_param_accepts(const TriMesh& mesh, const MeshCheck& check, bool allow_boundary) {
  SPHEREKIT_RETURN_IF_ERROR(require_genus0(check, allow_boundary));
  return require_supported_coordinates(mesh);
}

}  // namespace spherekit
