// Tests of a collection's levels of detail on the template member's mesh (convert/src/
// template_lods.cpp, gltf_lods.cpp build_template_gltf_lods): the template laid on every member
// (vertices on the member's surface, the cut's vertices on their edges), one connectivity per
// level, level 0 the template's own triangulation, and the fold count that tells a laid
// template that does not fit a member.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <tuple>
#include <vector>

#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/template_lods.h"
#include "spherekit/correspondence.h"
#include "spherekit/metrics.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

struct TlMember {
  TriMesh mesh;
  RowMat3d S;
};

// A blob with its radial map: blobs of any connectivity are consistent through their
// directions, and the correspondence (same direction) is smooth.
TlMember tl_blob(int level, std::uint64_t seed) {
  TlMember b;
  b.mesh = test::random_blob(level, seed);
  b.S = b.mesh.V.rowwise().normalized();
  return b;
}

// A twist of the sphere about +z: the cap within `inner` of the pole turns by pi, the ring out
// to `outer` by less and less (each latitude circle rigidly, so it is a bijection). Mild at a
// fine member's edge scale, a half turn across one of a coarse template's triangles.
Eigen::Vector3d tl_twist(const Eigen::Vector3d& d, double inner, double outer) {
  const double polar = std::acos(std::clamp(d.z(), -1.0, 1.0));
  const double a = std::numbers::pi * std::clamp((outer - polar) / (outer - inner), 0.0, 1.0);
  return {std::cos(a) * d.x() - std::sin(a) * d.y(), std::sin(a) * d.x() + std::cos(a) * d.y(), d.z()};
}

std::vector<TemplateLodMember> tl_members(const std::vector<TlMember>& m) {
  std::vector<TemplateLodMember> out;
  for (const TlMember& x : m) out.push_back({&x.mesh, &x.S});
  return out;
}

}  // namespace

TEST_CASE("template levels: the template laid on every member, one connectivity per level", "[convert][lod]") {
  // Different connectivities (levels 3 and 4 of the icosphere), different shapes.
  const std::vector<TlMember> m{tl_blob(3, 7), tl_blob(4, 11)};
  auto layout = lay_template(tl_members(m), 0);
  REQUIRE(layout.ok());
  const FoldCutMesh& cut = layout->cut;
  const auto nv = cut.mesh.V.rows();
  REQUIRE(layout->positions.rows() == nv);
  REQUIRE(layout->positions.cols() == 6);
  CHECK(layout->folded_faces == std::vector<int>{0, 0});
  CHECK(layout->outside_vertices == std::vector<int>{0, 0});
  CHECK(layout->faces > 0);
  // The template's copy is the cut mesh itself.
  CHECK(layout->positions.leftCols(3) == RowMatXd(cut.mesh.V));
  // The other member's copies of the template's vertices lie on its surface.
  const ClosestPointLocator near(m[1].mesh);
  double worst = 0;
  for (int v = 0; v < cut.original_vertices; ++v) {
    const Eigen::Vector3d x = layout->positions.row(v).segment<3>(3).transpose();
    worst = std::max(worst, (surface_position(m[1].mesh, near.closest(x)) - x).norm());
  }
  CHECK(worst < 1e-12);
  // The cut's vertices lie on their edges as laid on each member, at the template's parameter.
  REQUIRE(!cut.edge_points.empty());
  const auto first = nv - static_cast<Eigen::Index>(cut.edge_points.size());
  for (std::size_t k = 0; k < cut.edge_points.size(); ++k) {
    const FoldCutMesh::EdgePoint& e = cut.edge_points[k];
    REQUIRE(e.a < first + static_cast<Eigen::Index>(k));
    REQUIRE(e.b < first + static_cast<Eigen::Index>(k));
    for (int mm = 0; mm < 2; ++mm) {
      const Eigen::Vector3d a = layout->positions.row(e.a).segment<3>(3 * mm).transpose();
      const Eigen::Vector3d b = layout->positions.row(e.b).segment<3>(3 * mm).transpose();
      const Eigen::Vector3d p = layout->positions.row(first + static_cast<Eigen::Index>(k)).segment<3>(3 * mm).transpose();
      CHECK((p - (a + e.t * (b - a))).norm() <= 1e-12 * (1 + a.norm()));
    }
  }

  OriginalLodOptions o;
  o.levels = 3;
  o.texture_size = 65;
  auto levels = template_lod_meshes(*layout, o);
  REQUIRE(levels.ok());
  REQUIRE(levels->size() == 3);
  for (const auto& level : *levels) {
    REQUIRE(level.size() == 2);
    CHECK(level[0].F == level[1].F);
    CHECK(level[0].UV == level[1].UV);
    CHECK(level[0].position_index == level[1].position_index);
    CHECK(level[0].V.rows() == level[0].UV.rows());
    CHECK(level[0].V != level[1].V);
  }
  // Level 0 is the template's own triangulation: on the template, exactly its vertices (the
  // cut's extra vertices collapsed again at no cost, in every member alike).
  const GltfMesh& t0 = (*levels)[0][0];
  std::set<std::tuple<double, double, double>> tv, lv;
  for (Eigen::Index v = 0; v < m[0].mesh.V.rows(); ++v) tv.emplace(m[0].mesh.V(v, 0), m[0].mesh.V(v, 1), m[0].mesh.V(v, 2));
  for (Eigen::Index p = 0; p < t0.V.rows(); ++p) lv.emplace(t0.V(p, 0), t0.V(p, 1), t0.V(p, 2));
  // Level 0 has the template's vertex count and is the template's own triangulation but where
  // the fold needs a vertex (its ends and crossings never move, and a fold vertex collapses
  // only along the fold): on the template, all but those are its vertices.
  int on_template = 0;
  for (const auto& x : lv) on_template += tv.count(x) > 0;
  CHECK(lv.size() == tv.size());
  CHECK(on_template >= static_cast<int>(0.95 * static_cast<double>(tv.size())));
  CHECK(t0.F.rows() == m[0].mesh.F.rows());
  // Coarser levels have fewer faces.
  CHECK((*levels)[1][0].F.rows() < t0.F.rows());
  CHECK((*levels)[2][0].F.rows() < (*levels)[1][0].F.rows());

  SECTION("as glTF: one connectivity, errors against each member's own mesh") {
    std::vector<GltfLodOptions> go(2);
    for (GltfLodOptions& x : go) x.levels = 3, x.normals = false;
    go[0].name = "a", go[1].name = "b";
    auto lods = build_template_gltf_lods(*layout, tl_members(m), 65, go);
    REQUIRE(lods.ok());
    REQUIRE(lods->size() == 2);
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK((*lods)[0].levels[k].mesh.F == (*lods)[1].levels[k].mesh.F);
      CHECK((*lods)[0].levels[k].primitive.decoded.mesh.F.rows() == (*lods)[1].levels[k].primitive.decoded.mesh.F.rows());
    }
    CHECK(build_template_gltf_lods(*layout, tl_members(m), 65, {go[0]}).status().code() == ErrorCode::InvalidArgument);
    // Without texture coordinates the fold's copies become one point alike on every member.
    for (GltfLodOptions& x : go) x.texcoords = false;
    auto plain = build_template_gltf_lods(*layout, tl_members(m), 65, go);
    REQUIRE(plain.ok());
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK((*plain)[0].levels[k].mesh.F == (*plain)[1].levels[k].mesh.F);
      CHECK((*plain)[0].levels[k].mesh.UV.rows() == 0);
      CHECK((*plain)[0].levels[k].mesh.V.rows() < (*lods)[0].levels[k].mesh.V.rows());
    }
  }
  SECTION("deterministic") {
    auto again = template_lod_meshes(*lay_template(tl_members(m), 0), o);
    REQUIRE(again.ok());
    for (std::size_t k = 0; k < 3; ++k) CHECK((*again)[k][1].V == (*levels)[k][1].V);
  }
}

TEST_CASE("template levels: a template that does not fit a member folds over on it", "[convert][lod]") {
  // A coarse template; a fine member whose map is a twist of its directions: one-to-one and
  // mild at the member's edges, but a template triangle across the twisted ring has corners
  // half a turn apart round the pole when laid on the member.
  std::vector<TlMember> m{tl_blob(2, 7), tl_blob(5, 11), tl_blob(5, 11)};
  for (Eigen::Index v = 0; v < m[2].S.rows(); ++v) m[2].S.row(v) = tl_twist(m[2].S.row(v).transpose(), 0.2, 1.0).transpose();
  auto layout = lay_template(tl_members(m), 0);
  REQUIRE(layout.ok());
  CHECK(layout->folded_faces[0] == 0);
  CHECK(layout->folded_faces[1] == 0);
  REQUIRE(count_flipped_faces(m[2].mesh.F, m[2].S) == 0);  // the twisted map is still a bijection
  CHECK(layout->folded_faces[2] > 0);
  CHECK(layout->folded_faces[2] < layout->faces);
}

TEST_CASE("template levels: bad arguments are errors", "[convert][lod]") {
  const std::vector<TlMember> m{tl_blob(2, 7)};
  CHECK(lay_template({}, 0).status().code() == ErrorCode::InvalidArgument);
  CHECK(lay_template(tl_members(m), 1).status().code() == ErrorCode::InvalidArgument);
  CHECK(lay_template({TemplateLodMember{}}, 0).status().code() == ErrorCode::InvalidArgument);
  TlMember short_map = m[0];
  short_map.S.conservativeResize(short_map.S.rows() - 1, 3);
  CHECK(lay_template(tl_members({m[0], short_map}), 0).status().code() == ErrorCode::InvalidInput);
  auto layout = lay_template(tl_members(m), 0);
  REQUIRE(layout.ok());
  OriginalLodOptions o;
  o.levels = 0;
  CHECK(template_lod_meshes(*layout, o).status().code() == ErrorCode::InvalidArgument);
}
