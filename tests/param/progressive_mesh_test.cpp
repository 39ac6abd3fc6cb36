// Progressive mesh: collapses down to a tetrahedron, exact replay, n-D coordinates.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "detail/quadric.h"
#include "spherekit/progressive_mesh.h"
#include "test_meshes.h"

using namespace spherekit;

namespace {

// Replays the collapses forward on a copy of F (independently of the library's refiner) and
// returns the alive faces' corners at the base.
std::vector<std::array<int, 3>> replay_forward(const ProgressiveMesh& pm, std::vector<std::array<int, 3>>& F,
                                               std::vector<char>& alive) {
  for (const auto& c : pm.collapses) {
    for (int f : c.removed) alive[static_cast<size_t>(f)] = 0;
    for (int j = c.moved_begin; j < c.moved_end; ++j)
      for (int& v : F[static_cast<size_t>(pm.moved_faces[static_cast<size_t>(j)])])
        if (v == c.vt) v = c.vs;
  }
  std::vector<std::array<int, 3>> base;
  for (size_t f = 0; f < F.size(); ++f)
    if (alive[f]) base.push_back(F[f]);
  return base;
}

bool is_closed_manifold(const std::vector<std::array<int, 3>>& F) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& f : F)
    for (int k = 0; k < 3; ++k) directed[{f[k], f[(k + 1) % 3]}]++;
  for (const auto& [e, n] : directed)
    if (n != 1 || directed.count({e.second, e.first}) != 1) return false;
  return true;
}

// A valid hierarchy: it ends in a tetrahedron, removes every other vertex once, and undoing
// the collapses in reverse order restores the input faces exactly.
void check_replays_exactly(const ProgressiveMesh& pm, const TriMesh& m) {
  CHECK(pm.base_vertices.size() == 4);
  CHECK(pm.base_faces.size() == 4);
  CHECK(pm.collapses.size() == static_cast<size_t>(m.V.rows() - 4));
  std::vector<std::array<int, 3>> F(static_cast<size_t>(m.F.rows()));
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) F[static_cast<size_t>(f)] = {m.F(f, 0), m.F(f, 1), m.F(f, 2)};
  std::vector<char> alive(F.size(), 1);
  auto base = replay_forward(pm, F, alive);
  CHECK(base.size() == 4);
  CHECK(is_closed_manifold(base));
  // Every vertex is removed at most once and never a base vertex.
  std::set<int> removed;
  for (const auto& c : pm.collapses) {
    CHECK(removed.insert(c.vt).second);
    CHECK(c.vl != c.vr);
  }
  for (int v : pm.base_vertices) CHECK(removed.count(v) == 0);
  // Undo in reverse order: restores the input faces exactly.
  for (int i = static_cast<int>(pm.collapses.size()) - 1; i >= 0; --i) {
    const auto& c = pm.collapses[static_cast<size_t>(i)];
    for (int j = c.moved_begin; j < c.moved_end; ++j)
      for (int& v : F[static_cast<size_t>(pm.moved_faces[static_cast<size_t>(j)])])
        if (v == c.vs) v = c.vt;
    for (int s = 0; s < 2; ++s) {
      F[static_cast<size_t>(c.removed[static_cast<size_t>(s)])] = pm.removed_corners[2 * static_cast<size_t>(i) + static_cast<size_t>(s)];
      alive[static_cast<size_t>(c.removed[static_cast<size_t>(s)])] = 1;
    }
  }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    CHECK(alive[static_cast<size_t>(f)]);
    CHECK(F[static_cast<size_t>(f)] == std::array<int, 3>{m.F(f, 0), m.F(f, 1), m.F(f, 2)});
  }
}

}  // namespace

TEST_CASE("progressive mesh of a genus-0 mesh ends in a tetrahedron and replays exactly", "[param][pm]") {
  // Accumulated quadrics (the default) and the parameterization's memoryless quadrics
  // with normals (MeshSimplify -minqem).
  const bool memoryless = GENERATE(false, true);
  INFO("memoryless with normals: " << memoryless);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    TriMesh m = test::random_blob(2, seed);
    RowMatXd P = m.V;
    ProgressiveMeshOptions opt;
    opt.memoryless = memoryless;
    opt.normal_weight = memoryless ? 0.02 : 0.0;
    auto pm = build_progressive_mesh(P, m.F, opt);
    REQUIRE(pm.ok());
    check_replays_exactly(*pm, m);
  }
}

TEST_CASE("progressive mesh accepts 3n-dimensional coordinates and kept vertices", "[param][pm]") {
  TriMesh a = test::random_blob(2, 7), b = test::random_blob(2, 8);  // same connectivity
  RowMatXd P(a.V.rows(), 6);
  P.leftCols(3) = a.V;
  P.rightCols(3) = b.V;
  ProgressiveMeshOptions opt;
  opt.keep_vertices.assign(static_cast<size_t>(a.V.rows()), 0);
  opt.keep_vertices[5] = opt.keep_vertices[17] = 1;
  auto pm = build_progressive_mesh(P, a.F, opt);
  REQUIRE(pm.ok());
  CHECK(pm->base_vertices.size() == 4);
  for (const auto& c : pm->collapses) {
    CHECK(c.vt != 5);
    CHECK(c.vt != 17);
  }
}

// The normal term (Hoppe 1999) makes a thin spike expensive to collapse: its normals turn
// through every direction within a small distance. With it, the spike's tip outlives more
// of the (nearly flat) sphere around it than with positions alone.
TEST_CASE("progressive mesh: the normal term keeps a thin spike to coarser levels", "[param][pm]") {
  TriMesh m = test::icosphere(3);
  const Eigen::RowVector3d axis(0, 0, 1);
  int tip = 0;
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    if (m.V.row(v).dot(axis) > m.V.row(tip).dot(axis)) tip = static_cast<int>(v);
  // A spike: the tip and its ring pulled out along the axis, ring narrowed.
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const double c = m.V.row(v).normalized().dot(axis);
    if (c > 0.97) m.V.row(v) = (0.05 * m.V.row(v).normalized() + (1.0 + 1.5 * (c - 0.97) / 0.03) * axis);
  }
  auto removal_rank = [&](double normal_weight) {
    ProgressiveMeshOptions opt;
    opt.memoryless = true;
    opt.normal_weight = normal_weight;
    RowMatXd P = m.V;
    auto pm = build_progressive_mesh(P, m.F, opt);
    REQUIRE(pm.ok());
    for (size_t i = 0; i < pm->collapses.size(); ++i)
      if (pm->collapses[i].vt == tip) return static_cast<int>(i);
    return static_cast<int>(pm->collapses.size());  // a base vertex: never removed
  };
  const int without = removal_rank(0.0), with = removal_rank(0.1);
  INFO("tip removed at collapse " << without << " without normals, " << with << " with");
  CHECK(with > without);
}

TEST_CASE("progressive mesh refuses a torus", "[param][pm]") {
  TriMesh t = test::torus();
  RowMatXd P = t.V;
  auto pm = build_progressive_mesh(P, t.F);
  REQUIRE_FALSE(pm.ok());
  CHECK(pm.status().code() == ErrorCode::SolverFailed);
}

TEST_CASE("n-D quadric measures squared distance to the triangle's plane", "[param][pm]") {
  // Triangle in the plane z = 1 of R^3, weight 2: Q(x) = 2 (z - 1)^2.
  double p0[3] = {0, 0, 1}, p1[3] = {1, 0, 1}, p2[3] = {0, 1, 1};
  detail::QuadricND q(3);
  q.add_triangle(p0, p1, p2, 2.0);
  double x[3] = {5, -3, 4};
  CHECK(q.evaluate(x) == Approx(2.0 * 9.0));
  // In R^6 the same triangle duplicated: the 2-plane {(u, u) : u in plane}; a point (u, u + e)
  // with e orthogonal offset has squared distance |e|^2 / 2.
  double a0[6] = {0, 0, 1, 0, 0, 1}, a1[6] = {1, 0, 1, 1, 0, 1}, a2[6] = {0, 1, 1, 0, 1, 1};
  detail::QuadricND q6(6);
  q6.add_triangle(a0, a1, a2, 1.0);
  double y[6] = {0.2, 0.3, 1, 0.2, 0.3, 1};
  CHECK(q6.evaluate(y) == Approx(0.0).margin(1e-12));
  double z[6] = {0.2, 0.3, 1, 0.2 + 1.0, 0.3, 1};  // offset (0,0,0,1,0,0) -> distance^2 = 1/2
  CHECK(q6.evaluate(z) == Approx(0.5));
}

TEST_CASE("n-D quadric of one coordinate block measures that block's plane distance alone", "[param][pm]") {
  // The triangle of block [3, 6) lies in the plane y = 2 there; block [0, 3) is arbitrary.
  double a0[6] = {7, 1, 3, 0, 2, 0}, a1[6] = {-4, 0, 5, 1, 2, 0}, a2[6] = {2, 9, 1, 0, 2, 1};
  detail::QuadricND q(6);
  q.add_triangle(a0, a1, a2, 3.0, 3, 6);
  double x[6] = {100, -50, 25, 0.4, 2.5, -7};  // block [3, 6) is 0.5 from the plane
  CHECK(q.evaluate(x) == Approx(3.0 * 0.25));
  x[0] = -3, x[1] = 8, x[3] = 11, x[5] = 4;  // moves within the plane and in the other block
  CHECK(q.evaluate(x) == Approx(3.0 * 0.25));
  // The whole range is the plain 2-plane quadric, to the bit.
  detail::QuadricND whole(6), range(6);
  whole.add_triangle(a0, a1, a2, 1.5);
  range.add_triangle(a0, a1, a2, 1.5, 0, 6);
  CHECK(whole.evaluate(x) == range.evaluate(x));
}

// Levels of detail of n models (model_planes): each model's own plane distances. For one
// model the option changes nothing (the same collapses); for two models it still makes a
// valid progressive mesh down to a tetrahedron; it refuses the normal term.
TEST_CASE("progressive mesh: model planes", "[param][pm]") {
  TriMesh a = test::random_blob(2, 7), b = test::random_blob(2, 8);  // same connectivity
  for (bool memoryless : {false, true}) {
    auto build = [&](const RowMatXd& P, bool model_planes) {
      ProgressiveMeshOptions opt;
      opt.memoryless = memoryless;
      opt.model_planes = model_planes;
      auto pm = build_progressive_mesh(P, a.F, opt);
      REQUIRE(pm.ok());
      return *pm;
    };
    RowMatXd one = a.V;
    const ProgressiveMesh plain = build(one, false), planes = build(one, true);
    REQUIRE(plain.collapses.size() == planes.collapses.size());
    int differ = 0;
    for (size_t i = 0; i < plain.collapses.size(); ++i)
      differ += plain.collapses[i].vt != planes.collapses[i].vt || plain.collapses[i].vs != planes.collapses[i].vs;
    CHECK(differ == 0);
    RowMatXd two(a.V.rows(), 6);
    two.leftCols(3) = a.V;
    two.rightCols(3) = b.V;
    const ProgressiveMesh joint = build(two, false), own = build(two, true);
    CHECK(own.base_vertices.size() == 4);
    std::vector<std::array<int, 3>> F(static_cast<size_t>(a.F.rows()));
    for (Eigen::Index f = 0; f < a.F.rows(); ++f) F[static_cast<size_t>(f)] = {a.F(f, 0), a.F(f, 1), a.F(f, 2)};
    std::vector<char> alive(F.size(), 1);
    CHECK(is_closed_manifold(replay_forward(own, F, alive)));
    // The two costs differ, so the orders do.
    int order_differs = 0;
    for (size_t i = 0; i < std::min(joint.collapses.size(), own.collapses.size()); ++i)
      order_differs += joint.collapses[i].vt != own.collapses[i].vt;
    CHECK(order_differs > 0);
  }
  ProgressiveMeshOptions bad;
  bad.model_planes = true;
  bad.normal_weight = 0.02;
  RowMatXd P = a.V;
  auto refused = build_progressive_mesh(P, a.F, bad);
  REQUIRE_FALSE(refused.ok());
  CHECK(refused.status().code() == ErrorCode::InvalidArgument);
}

// Parallel fine levels (ProgressiveMeshOptions::block_vertices): the blocks' collapses are
// replayed on the whole mesh, so the hierarchy must be as valid as the plain greedy's, and
// the blocks come from the mesh alone, so it must not depend on the thread count.
TEST_CASE("progressive mesh in blocks: valid, the same for any thread count, the fine levels from the blocks",
          "[param][pm]") {
  TriMesh m = test::random_blob(4, 5);  // 2562 vertices: 8 blocks, then 2
  ProgressiveMeshOptions opt;
  opt.memoryless = true;
  opt.normal_weight = 0.02;
  auto plain = build_progressive_mesh(m.V, m.F, opt);
  REQUIRE(plain.ok());
  // The progressive mesh with blocks of `block_vertices`, for each thread count, each checked
  // to replay exactly.
  auto blocked = [&](int block_vertices, std::initializer_list<int> thread_counts) {
    opt.block_vertices = block_vertices;
    std::vector<ProgressiveMesh> pms;
    for (int threads : thread_counts) {
      opt.threads = threads;
      auto pm = build_progressive_mesh(m.V, m.F, opt);
      REQUIRE(pm.ok());
      check_replays_exactly(*pm, m);
      pms.push_back(std::move(*pm));
    }
    return pms;
  };
  std::vector<ProgressiveMesh> runs = blocked(300, {1, 3});
  for (const auto& pm : runs) CHECK(pm.forced_collapses == 0);
  REQUIRE(runs[0].collapses.size() == runs[1].collapses.size());
  for (size_t i = 0; i < runs[0].collapses.size(); ++i) {
    CHECK(runs[0].collapses[i].vt == runs[1].collapses[i].vt);
    CHECK(runs[0].collapses[i].vs == runs[1].collapses[i].vs);
  }
  CHECK(runs[0].moved_faces == runs[1].moved_faces);
  // The blocks made the fine levels: the order differs from the plain greedy's early on.
  size_t same_prefix = 0;
  while (same_prefix < plain->collapses.size() && plain->collapses[same_prefix].vt == runs[0].collapses[same_prefix].vt &&
         plain->collapses[same_prefix].vs == runs[0].collapses[same_prefix].vs)
    ++same_prefix;
  CHECK(same_prefix < runs[0].collapses.size() / 4);
  // A mesh of fewer than 1.5 blocks' vertices is simplified as one.
  opt.block_vertices = static_cast<int>(m.V.rows()) * 2 / 3 + 1;
  auto one = build_progressive_mesh(m.V, m.F, opt);
  REQUIRE(one.ok());
  REQUIRE(one->collapses.size() == plain->collapses.size());
  for (size_t i = 0; i < plain->collapses.size(); ++i) CHECK(one->collapses[i].vt == plain->collapses[i].vt);
  // From 1.5 blocks' vertices up it is cut in two (igea decimated to 13k vertices with blocks
  // of 8192), valid and the same for any thread count.
  const std::vector<ProgressiveMesh> halves = blocked(static_cast<int>(m.V.rows()) * 2 / 3, {1, 2});
  REQUIRE(halves[0].collapses.size() == plain->collapses.size());
  bool differs = false;
  for (size_t i = 0; i < plain->collapses.size(); ++i) {
    differs = differs || halves[0].collapses[i].vt != plain->collapses[i].vt;
    CHECK(halves[0].collapses[i].vt == halves[1].collapses[i].vt);
  }
  CHECK(differs);
}
