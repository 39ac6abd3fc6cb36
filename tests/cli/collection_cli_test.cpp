// End-to-end tests of the collection commands: `consistent` writes a collection folder in
// which features coincide on the sphere, `add` grows it, `correspond` transfers points and
// measures the map; failures leave nothing behind.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "test_paths.h"

#include "cli_test_prelude.h"

namespace {

// `v x y z` lines of an OBJ.
std::vector<Eigen::Vector3d> obj_points(const std::string& path) {
  std::vector<Eigen::Vector3d> out;
  std::istringstream in(slurp(path));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) != 0) continue;
    std::istringstream f(line.substr(2));
    Eigen::Vector3d p;
    f >> p.x() >> p.y() >> p.z();
    out.push_back(p);
  }
  return out;
}

// `name value...` lines into name -> values.
std::map<std::string, std::vector<double>> named_rows(const std::string& path) {
  std::map<std::string, std::vector<double>> out;
  std::istringstream in(slurp(path));
  for (std::string line; std::getline(in, line);) {
    std::istringstream f(line);
    std::string name;
    if (!(f >> name) || name[0] == '#') continue;
    std::vector<double> v;
    for (double x; f >> x;) v.push_back(x);
    out[name] = v;
  }
  return out;
}

// Every feature vertex of `mesh_stem` sits on its collection location (to the 17 digits the
// files carry).
void require_features_on_locations(const std::string& samples, const std::string& col, const std::string& stem) {
  const auto S = obj_points(col + "/" + stem + ".sphere.obj");
  const auto lm = named_rows(samples + "/" + stem + ".lm.txt");
  const auto F = named_rows(col + "/features.txt");
  REQUIRE(lm.size() == F.size());
  for (const auto& [name, v] : lm) {
    INFO(stem << ": " << name);
    REQUIRE(F.count(name) == 1);
    const Eigen::Vector3d loc(F.at(name)[0], F.at(name)[1], F.at(name)[2]);
    const Eigen::Vector3d s = S.at(static_cast<size_t>(v[0]));
    CHECK(std::atan2(s.cross(loc).norm(), s.dot(loc)) < 1e-12);
  }
}

}  // namespace

TEST_CASE("consistent writes a collection; add grows it; correspond uses it", "[cli][collection]") {
  const std::string dir = spherekit::test::temp_dir("cli_collection");
  const std::string s = dir + "/samples", col = dir + "/col";
  REQUIRE(sk("samples -o " + q(s) + " --members 3 --vertices 900", dir).exit_code == 0);
  CliRun r = sk("consistent -o " + q(col) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_b.obj") +
                    " --remesh-size 33 --effort 1 --report " + q(dir + "/report.json"),
                dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  // The per-step table.
  for (const char* step : {"unconstrained map of sample_a", "constrained maps of 1 meshes to F'", "remesh 33 x 33",
                           "joint unconstrained map", "constrained maps of 2 meshes to F"})
    CHECK(r.out.find(step) != std::string::npos);
  CHECK(fs::exists(col + "/collection.json"));
  CHECK(fs::exists(col + "/features.txt"));
  json man = read_json(col + "/collection.json");
  CHECK(man["format"] == "spherekit-collection");
  CHECK(man["features"].size() == 13);
  REQUIRE(man["meshes"].size() == 2);
  CHECK(man["meshes"][0]["map"] == "sample_a.sphere.obj");
  CHECK(man["meshes"][1]["result"]["flipped_faces"] == 0);
  CHECK(read_json(dir + "/report.json")["times"]["step5_joint_map"].get<double>() > 0);
  require_features_on_locations(s, col, "sample_a");
  require_features_on_locations(s, col, "sample_b");
  // Every member's unconstrained efficiency, what the efficiency retry compares against; a
  // member made twice says so only where its first map kept less than the bar.
  CHECK(man["options"]["efficiency_retry"].get<double>() == 0.8);
  for (const json& m : man["meshes"]) {
    INFO(m["name"]);
    REQUIRE(m["result"].contains("unconstrained_efficiency"));
    const double u = m["result"]["unconstrained_efficiency"].get<double>();
    CHECK(u > 0);
    CHECK(u <= 1);
    if (m["result"].contains("efficiency_retry"))
      CHECK(m["result"]["efficiency_retry"]["first_efficiency"].get<double>() < 0.8 * u);
  }
  // No staging folders left beside it.
  for (const auto& e : fs::directory_iterator(dir)) CHECK(e.path().filename().string().rfind(".col", 0) != 0);

  // add: the third member lands on the same locations.
  r = sk("add " + q(col) + " " + q(s + "/sample_c.obj") + " --effort 1 -q", dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  require_features_on_locations(s, col, "sample_c");
  man = read_json(col + "/collection.json");
  REQUIRE(man["meshes"].size() == 3);
  CHECK(man["meshes"][2]["added"] == true);
  CHECK(man["meshes"][2]["result"]["unconstrained_efficiency"].get<double>() > 0);
  // The collection was made with the correspondence refinement (the default): consistent
  // recorded it per member, and add refined the new map against the reference the same way.
  CHECK(man["options"]["refine_correspondence"] == true);
  CHECK(man["options"]["refinement"]["sample_growth"] == 2);
  CHECK(man["options"]["refinement"]["max_samples"] == 512);
  CHECK(man["meshes"][0]["result"]["correspondence_refinement"]["note"] == "template");
  for (int i : {1, 2}) {
    INFO(man["meshes"][i]["name"]);
    const json& cr = man["meshes"][i]["result"]["correspondence_refinement"];
    REQUIRE(cr.is_object());
    if (cr["refined"].get<bool>()) {
      CHECK(cr["rounds"].get<int>() >= 1);
      CHECK(man["meshes"][i]["result"]["efficiency"].get<double>() == Approx(cr["efficiency_after"].get<double>()));
    }
  }
  // Without it (--no-refine-correspondence) add keeps the constrained map: no record, and a
  // different map whenever the refined one was taken.
  // (A copy of c's files, so that c_plain is its own source and `correspond` below finds c.)
  fs::copy_file(s + "/sample_c.obj", s + "/c_plain.obj");
  fs::copy_file(s + "/sample_c.lm.txt", s + "/c_plain.lm.txt");
  r = sk("add " + q(col) + " " + q(s + "/c_plain.obj") + " --no-refine-correspondence --effort 1 -q", dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  man = read_json(col + "/collection.json");
  REQUIRE(man["meshes"].size() == 4);
  CHECK(man["meshes"][0]["name"] == "c_plain");  // sorted by name
  CHECK_FALSE(man["meshes"][0]["result"].contains("correspondence_refinement"));
  require_features_on_locations(s, col, "c_plain");
  if (man["meshes"][3]["result"]["correspondence_refinement"]["refined"].get<bool>())
    CHECK(slurp(col + "/c_plain.sphere.obj") != slurp(col + "/sample_c.sphere.obj"));

  // Adding it again is refused (exit 2), and the collection is unchanged.
  const std::string before = slurp(col + "/collection.json");
  r = sk("add " + q(col) + " " + q(s + "/sample_c.obj") + " -q", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("already has a mesh named 'sample_c'") != std::string::npos);
  CHECK(slurp(col + "/collection.json") == before);

  // correspond: measured against the samples' ground truth, and point transfer.
  r = sk("correspond " + q(col) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_c.obj") + " --corr " +
             q(s + "/sample_a.corr.txt") + " " + q(s + "/sample_c.corr.txt") + " --json",
         dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  json e = json::parse(r.out, nullptr, false);
  REQUIRE_FALSE(e.is_discarded());
  CHECK(e["pairs"].get<int>() > 400);
  CHECK(e["mean"].get<double>() < 0.05);
  CHECK(e["under_0.1"].get<double>() > 0.9);
  // The feature vertices of a go exactly to those of c (same sphere points).
  const auto Va = obj_points(s + "/sample_a.obj"), Vc = obj_points(s + "/sample_c.obj");
  const auto lma = named_rows(s + "/sample_a.lm.txt"), lmc = named_rows(s + "/sample_c.lm.txt");
  std::string pts;
  std::vector<Eigen::Vector3d> expect;
  for (const auto& [name, v] : lma) {
    const Eigen::Vector3d p = Va.at(static_cast<size_t>(v[0]));
    pts += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
    expect.push_back(Vc.at(static_cast<size_t>(lmc.at(name)[0])));
  }
  {
    std::ofstream(dir + "/points.txt") << pts;
  }
  // std::to_string keeps 6 decimals: the points are within 1e-6 of a's feature vertices.
  r = sk("correspond " + q(col) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_c.obj") + " --points " +
             q(dir + "/points.txt") + " -o " + q(dir + "/on_c.txt"),
         dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  std::istringstream got(slurp(dir + "/on_c.txt"));
  for (const Eigen::Vector3d& x : expect) {
    Eigen::Vector3d y;
    REQUIRE(got >> y.x() >> y.y() >> y.z());
    CHECK((x - y).norm() < 0.02);  // the 1e-6 offset, magnified by the local stretch ratio at most
  }
}

TEST_CASE("collection commands fail with one line and leave nothing behind", "[cli][collection]") {
  const std::string dir = spherekit::test::temp_dir("cli_collection_bad");
  const std::string s = dir + "/samples";
  REQUIRE(sk("samples -o " + q(s) + " --members 2 --vertices 600", dir).exit_code == 0);
  const std::string a = s + "/sample_a.obj", b = s + "/sample_b.obj";

  // A non-empty folder that is not a collection is never replaced (before any work).
  fs::create_directories(dir + "/busy");
  std::ofstream(dir + "/busy/keep.txt") << "mine\n";
  CliRun r = sk("consistent -o " + q(dir + "/busy") + " " + q(a) + " " + q(b), dir);
  CHECK(r.exit_code == 4);
  CHECK(r.err.find("not a collection") != std::string::npos);
  CHECK(slurp(dir + "/busy/keep.txt") == "mine\n");

  // A feature file without one of the first mesh's features: exit 3, names the file.
  std::string lm = slurp(s + "/sample_b.lm.txt");
  lm = lm.substr(lm.find('\n') + 1);  // drop the first feature
  std::ofstream(dir + "/short.lm.txt") << lm;
  r = sk("consistent -o " + q(dir + "/out1") + " " + q(a) + " " + q(b) + " --features " + q(s + "/sample_a.lm.txt") +
             " " + q(dir + "/short.lm.txt"),
         dir);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("short.lm.txt") != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir + "/out1"));

  // A missing default feature file.
  fs::copy_file(a, dir + "/lonely.obj");
  r = sk("consistent -o " + q(dir + "/out2") + " " + q(dir + "/lonely.obj") + " " + q(b), dir);
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("lonely.lm.txt") != std::string::npos);
  CHECK_FALSE(fs::exists(dir + "/out2"));

  // Two inputs with one stem would overwrite each other's map.
  fs::create_directories(dir + "/other");
  fs::copy_file(b, dir + "/other/sample_a.obj");
  r = sk("consistent -o " + q(dir + "/out3") + " " + q(a) + " " + q(dir + "/other/sample_a.obj"), dir);
  CHECK(r.exit_code == 2);
  CHECK_FALSE(fs::exists(dir + "/out3"));

  // add / correspond on a folder that is not a collection.
  r = sk("add " + q(dir + "/busy") + " " + q(a), dir);
  CHECK(r.exit_code == 4);
  CHECK(r.err.find("collection.json") != std::string::npos);
  r = sk("correspond " + q(dir + "/nowhere") + " " + q(a) + " " + q(b) + " --points " + q(dir + "/busy/keep.txt"), dir);
  CHECK(r.exit_code == 4);
}

// The refinement's later rounds flow onto more samples (256, 512, 512), at most one per 8
// member vertices (these 900-vertex members keep 256); a collection written before that has no
// `sample_growth` entry, and add refines a member as its members were refined: 256 samples in
// every round, whatever the other entries say (and without the snap when there is no
// `snap_sweeps` entry).
TEST_CASE("add refines a new member with the sample counts the collection was made with", "[cli][collection]") {
  const std::string dir = spherekit::test::temp_dir("cli_collection_growth");
  const std::string s = dir + "/samples", col = dir + "/col";
  REQUIRE(sk("samples -o " + q(s) + " --members 3 --vertices 900", dir).exit_code == 0);
  CliRun r = sk("consistent -o " + q(col) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_b.obj") +
                    " --remesh-size 33 --effort 1 -q",
                dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  json man = read_json(col + "/collection.json");
  REQUIRE(man["options"]["refinement"]["sample_growth"] == 2);
  REQUIRE(man["options"]["refinement"]["vertices_per_sample"] == 8);
  {
    const json& b = man["meshes"][1]["result"]["correspondence_refinement"];
    INFO(b.dump());
    REQUIRE(b["refined"] == true);
    REQUIRE(b["rounds"] == 3);
    CHECK(b["samples"] == 256);
  }
  // add follows the manifest: one sample per vertex allowed, sample_b grows to 512 ...
  auto readd_b = [&](const std::function<void(json&)>& edit) {
    edit(man["options"]["refinement"]);
    {
      std::ofstream f(col + "/collection.json", std::ios::binary | std::ios::trunc);
      f << man.dump(2);
    }
    CliRun a = sk("add " + q(col) + " " + q(s + "/sample_b.obj") + " --replace --effort 1 -q", dir);
    INFO("stderr: " << a.err);
    REQUIRE(a.exit_code == 0);
    man = read_json(col + "/collection.json");
    REQUIRE(man["meshes"][1]["name"] == "sample_b");
    const json c = man["meshes"][1]["result"]["correspondence_refinement"];
    INFO(c.dump());
    REQUIRE(c["refined"] == true);
    REQUIRE(c["rounds"] == 3);
    return c;
  };
  CHECK(readd_b([](json& o) { o["vertices_per_sample"] = 1; })["samples"] == 512);
  // ... and in a collection written before the growing counts, 256 in every round.
  CHECK(readd_b([](json& o) { o.erase("sample_growth"); })["samples"] == 256);
  // Likewise the snap toward the fitted partners before the stretch passes: on by default,
  // and not made in a collection written before it.
  CHECK(man["options"]["refinement"]["snap_sweeps"] == 3);
  CHECK(man["meshes"][1]["result"]["correspondence_refinement"]["snap_moves"].get<int>() > 0);
  CHECK(readd_b([](json& o) { o.erase("snap_sweeps"); })["snap_moves"] == 0);
}
