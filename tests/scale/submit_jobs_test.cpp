// submit's data jobs in the scheduler library, without the executable (issue 21): the subset
// choice from the members' feature layouts, and the plan's final check on a hand-made
// collection (octahedra, which are their own sphere maps), good and broken.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/scheduler/submit_jobs.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace sch = spherekit::scheduler;
using namespace spherekit;

namespace {

// Members a, b, c: octahedron meshes with features "top", "side" and "third" (see below),
// a collection listing `listed` of them with the identity map, and a plan expecting all three.
struct Fixture {
  std::string dir;
  sch::CollectionPlanOptions options;
  std::string plan_path;
};

Fixture make_fixture(const std::string& name, const std::vector<std::string>& listed) {
  Fixture f;
  f.dir = test::temp_dir(name);
  const TriMesh mesh = test::octahedron();
  formats::CollectionManifest m;
  m.features = {{"top", Eigen::Vector3d(0, 0, 1), std::nullopt}, {"side", Eigen::Vector3d(1, 0, 0), std::nullopt}};
  const std::vector<std::string> names = {"a", "b", "c"};
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string src = f.dir + "/" + names[i] + ".obj", lm = f.dir + "/" + names[i] + ".lm.txt";
    REQUIRE(formats::write_mesh(src, mesh).ok());
    // +z, +x and a third: -x (a), +y (b), -z (c): three different layouts.
    const int third[] = {1, 2, 5};
    REQUIRE(formats::write_landmarks(lm, {{"top", 4}, {"side", 0}, {"third", third[i]}}).ok());
    f.options.meshes.push_back(src);
    f.options.features.push_back(lm);
    f.options.names.push_back(names[i]);
  }
  const std::string col = f.dir + "/col";
  std::filesystem::create_directories(col);
  for (const std::string& n : listed) {
    formats::CollectionMember e;
    e.name = n;
    e.map = n + ".sphere.obj";
    e.source = f.dir + "/" + n + ".obj";
    e.vertices = 6;
    e.faces = 8;
    e.feature_vertices = std::vector<long long>{4, 0};
    SphereMap map;
    map.S = mesh.V;
    REQUIRE(formats::write_sphere_map(col + "/" + e.map, mesh, map).ok());
    m.members.push_back(e);
  }
  REQUIRE(formats::write_file_atomic(col + "/features.txt", formats::sphere_points_text(m.feature_names(), m.locations())).ok());
  REQUIRE(formats::write_file_atomic(col + "/collection.json", formats::collection_manifest_text(m)).ok());
  sch::JobPlan plan;
  plan.work_dir = f.dir + "/work";
  plan.collection = col;
  plan.members = names;
  const std::string report = plan.work_dir + "/reports/add_b.json";
  plan.stages.push_back({"maps", {{"b", {"/bin/true"}, {col + "/b.sphere.obj", report}}}, {}});
  std::filesystem::create_directories(plan.work_dir);
  REQUIRE(formats::write_file_atomic(plan.work_dir + "/submit_report.json", "stale").ok());
  REQUIRE(sch::write_plan(plan).ok());
  CHECK_FALSE(std::filesystem::exists(plan.work_dir + "/submit_report.json"));  // an earlier run's report is gone
  REQUIRE(formats::write_file_atomic(report, "{\"peak_rss_mb\": 12.5, \"times\": {\"wall\": 3.25}}").ok());
  f.plan_path = plan.work_dir + "/plan.json";
  return f;
}

}  // namespace

TEST_CASE("submit jobs: the subset by name, first k or farthest layouts; errors named", "[scheduler][scale]") {
  const Fixture f = make_fixture("submit_subset", {});
  auto layouts = sch::feature_layouts(f.options.meshes, f.options.features);
  REQUIRE(layouts.ok());
  REQUIRE(layouts->size() == 3);
  CHECK(layouts->at(0) != layouts->at(1));
  CHECK(layouts->at(0) != layouts->at(2));
  CHECK(layouts->at(1) != layouts->at(2));

  sch::SubsetRequest r;
  r.members = {"c", "a"};
  auto named = sch::choose_subset(f.options, r);
  REQUIRE(named.ok());
  CHECK(named->subset == std::vector<int>{2, 0});
  r.members = {"z"};
  auto unknown = sch::choose_subset(f.options, r);
  REQUIRE_FALSE(unknown.ok());
  CHECK(unknown.status().message().find("'z'") != std::string::npos);

  r.members.clear();
  r.k = 2;
  r.farthest = false;
  CHECK(sch::choose_subset(f.options, r)->subset == std::vector<int>{0, 1});
  r.farthest = true;
  CHECK(sch::choose_subset(f.options, r)->subset == sch::farthest_point_subset(layouts.value(), 2));
  // The default k is bounded by the joint step's memory.
  r.k = 0;
  r.joint_memory_mb = sch::joint_quadric_bytes(2, 65) * 1.001 / (1024 * 1024);
  auto bounded = sch::choose_subset(f.options, r);
  REQUIRE(bounded.ok());
  CHECK(bounded->k_memory == 2);
  CHECK(bounded->subset.size() == 2);

  // A member lacking a feature of the first names both files.
  sch::CollectionPlanOptions bad = f.options;
  REQUIRE(formats::write_landmarks(bad.features[1], {{"top", 4}, {"third", 2}}).ok());
  auto missing = sch::feature_layouts(bad.meshes, bad.features);
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.status().message().find("'side'") != std::string::npos);
  CHECK(missing.status().message().find(bad.features[1]) != std::string::npos);
}

TEST_CASE("submit jobs: the final check finds missing members and flipped maps, and writes the report", "[scheduler][scale]") {
  Fixture f = make_fixture("submit_verify_good", {"a", "b", "c"});
  auto good = sch::verify_plan(f.plan_path);
  REQUIRE(good.ok());
  CHECK(good->ok());
  CHECK(good->failure().ok());
  CHECK(good->listed == 3);
  REQUIRE(good->tasks.size() == 1);
  CHECK(good->tasks[0].task == "b");
  CHECK(good->tasks[0].wall_seconds == 3.25);
  CHECK(good->max_task_peak_rss_mb == 12.5);
  auto report = formats::read_file(f.dir + "/work/submit_report.json");
  REQUIRE(report.ok());
  CHECK(report.value() == sch::to_json(good.value()));
  CHECK(report->find("\"ok\": true") != std::string::npos);

  f = make_fixture("submit_verify_bad", {"a", "b"});
  // Swap two vertices of b's map: faces around them turn over.
  const TriMesh mesh = test::octahedron();
  SphereMap flipped;
  flipped.S = mesh.V;
  flipped.S.row(0).swap(flipped.S.row(4));
  REQUIRE(formats::write_sphere_map(f.dir + "/col/b.sphere.obj", mesh, flipped).ok());
  auto bad = sch::verify_plan(f.plan_path);
  REQUIRE(bad.ok());
  CHECK_FALSE(bad->ok());
  CHECK(bad->missing == std::vector<std::string>{"c"});
  REQUIRE(bad->broken.size() == 1);
  CHECK(bad->broken[0].rfind("b: ", 0) == 0);
  CHECK(bad->failure().message().find("not in the manifest (first: c)") != std::string::npos);
  auto bad_report = formats::read_file(f.dir + "/work/submit_report.json");
  REQUIRE(bad_report.ok());
  CHECK(bad_report->find("\"ok\": false") != std::string::npos);

  CHECK_FALSE(sch::verify_plan(f.dir + "/no_such_plan.json").ok());
}
