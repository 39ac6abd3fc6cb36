// Determinism of the `spherekit` program (issue 8): the same command run twice gives
// byte-identical outputs, and so does `--threads 1` against `--threads 2`, for `param`,
// `consistent` and `convert` on the built-in samples. Reports and manifests are compared
// after removing what is legitimately different between two runs: timings, CPU seconds,
// peak memory, the output path and (between thread counts) the recorded thread count.
// Everything else, including any key added later, must be equal.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "test_paths.h"
#include "test_files.h"

#include "cli_test_prelude.h"

namespace {

using spherekit::test::files_in;

// The smallest useful built-in collection: two members of ~600 vertices, sample_b with a
// hole (hole filling and its weights take part). Small keeps the test near 10 s in Release.
std::string make_samples(const std::string& dir) {
  const std::string s = dir + "/samples";
  const CliRun r = sk("samples -o " + q(s) + " --members 2 --vertices 600", dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.out.find("1 hole") != std::string::npos);
  return s;
}

// The keys of cmd_param.cpp / cmd_consistent.cpp reports that measure the run, not the
// result: "times" (every stage's seconds and the wall time, also per mesh in a collection),
// "cpu_seconds" and "peak_rss_mb". Removed at any depth.
void erase_run_measures(json& j) {
  if (j.is_object()) {
    for (const char* key : {"times", "cpu_seconds", "peak_rss_mb"}) j.erase(key);
    for (auto& [key, value] : j.items()) erase_run_measures(value);
  } else if (j.is_array()) {
    for (json& e : j) erase_run_measures(e);
  }
}

// A report with the run measures removed; `threads` (when >= 0) must be the recorded thread
// count, which is then removed too (it is an input that must not change the result).
json comparable_report(const std::string& path, int threads) {
  json j = read_json(path);
  // The result must still be there after stripping: the comparison would be empty otherwise.
  REQUIRE(j.contains("options"));
  if (threads >= 0) {
    CHECK(j["options"]["threads"] == threads);
    j["options"].erase("threads");
  }
  erase_run_measures(j);
  j.erase("output");  // each run writes to its own folder
  return j;
}

// A report that still holds timing keys would make every comparison fail by noise; one that
// holds none means the removal above is no longer needed for that key, so check both ways.
void require_has_timings(const std::string& path) {
  const json j = read_json(path);
  CHECK(j.contains("times"));
  CHECK(j.contains("cpu_seconds"));
}

void require_same_bytes(const std::string& a, const std::string& b) {
  INFO("files: " << a << " vs " << b);
  REQUIRE(fs::is_regular_file(a));
  REQUIRE(fs::is_regular_file(b));
  const std::string x = slurp(a), y = slurp(b);
  CHECK(x.size() > 0);
  CHECK(x.size() == y.size());
  CHECK(x == y);
}

// Two collection folders: the same files, each map, features.txt and the manifest byte for
// byte (the thread counts `threads_a`/`threads_b` that made them may differ).
void require_same_collection(const std::string& a, int threads_a, const std::string& b, int threads_b) {
  const std::vector<std::string> names = files_in(a);
  CHECK(names == files_in(b));
  CHECK(std::count(names.begin(), names.end(), "collection.json") == 1);
  CHECK(std::count(names.begin(), names.end(), "features.txt") == 1);
  // The lock file (.collection.lock) is empty by design.
  for (const std::string& name : names)
    if (name[0] != '.') require_same_bytes(a + "/" + name, b + "/" + name);
  // The manifest records neither times nor the thread count (issue 23: the same bytes from any
  // machine or job order); the reports hold those.
  for (const std::string& m : {a, b}) {
    const json j = read_json(m + "/collection.json");
    CHECK_FALSE(j.contains("times"));
    CHECK_FALSE(j["options"].contains("threads"));
  }
  (void)threads_a;
  (void)threads_b;
}

}  // namespace

TEST_CASE("determinism: param gives the same map and report twice and for 1 or 2 threads", "[cli][determinism]") {
  const std::string dir = spherekit::test::temp_dir("determinism_param");
  const std::string s = make_samples(dir);
  const std::string mesh = s + "/sample_b.obj";  // the one with a hole

  struct Run {
    const char* folder;
    int threads;
  };
  const Run runs[] = {{"t1_first", 1}, {"t1_second", 1}, {"t2", 2}};
  for (const Run& run : runs) {
    const std::string out = dir + "/" + run.folder;
    fs::create_directories(out);
    const CliRun r = sk("param " + q(mesh) + " -o " + q(out + "/map.sphere.obj") + " --report " +
                            q(out + "/report.json") + " --threads " + std::to_string(run.threads) + " --quiet",
                        dir);
    INFO("run " << run.folder << ", stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
  }
  require_has_timings(dir + "/t1_first/report.json");

  // (No SECTIONs: Catch2 would run the three commands again for each.)
  {
    INFO("same command twice");
    require_same_bytes(dir + "/t1_first/map.sphere.obj", dir + "/t1_second/map.sphere.obj");
    CHECK(comparable_report(dir + "/t1_first/report.json", 1).dump(2) ==
          comparable_report(dir + "/t1_second/report.json", 1).dump(2));
  }
  {
    INFO("1 versus 2 threads");
    require_same_bytes(dir + "/t1_first/map.sphere.obj", dir + "/t2/map.sphere.obj");
    const json one = comparable_report(dir + "/t1_first/report.json", 1);
    const json two = comparable_report(dir + "/t2/report.json", 2);
    CHECK(one.dump(2) == two.dump(2));
    // The comparison covers the measures, not just the inputs.
    CHECK(one.contains("efficiency"));
    CHECK(one["flipped_faces"] == 0);
  }
}

TEST_CASE("determinism: consistent writes the same collection twice and for 1 or 2 threads",
          "[cli][determinism][collection]") {
  const std::string dir = spherekit::test::temp_dir("determinism_consistent");
  const std::string s = make_samples(dir);
  // Effort 1 and a 17 x 17 remesh keep each run near a second; every step (reference map,
  // parallel constrained maps, remesh, joint map, final maps) still runs.
  const std::string common = q(s + "/sample_a.obj") + " " + q(s + "/sample_b.obj") + " --remesh-size 17 --effort 1 --quiet";

  struct Run {
    const char* folder;
    int threads;
  };
  // Twice with 2 threads (where scheduling could leak into the result) and once with 1.
  const Run runs[] = {{"t2_first", 2}, {"t2_second", 2}, {"t1", 1}};
  for (const Run& run : runs) {
    const std::string out = dir + "/" + run.folder;
    const CliRun r = sk("consistent -o " + q(out) + " " + common + " --threads " + std::to_string(run.threads) +
                            " --report " + q(out + ".report.json"),
                        dir);
    INFO("run " << run.folder << ", stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    // Step 6 succeeded: the collection holds the final (refined) maps, not the fallback.
    CHECK_FALSE(read_json(out + "/collection.json").contains("refinement_failure"));
  }
  require_has_timings(dir + "/t2_first.report.json");

  {
    INFO("same command twice");
    require_same_collection(dir + "/t2_first", 2, dir + "/t2_second", 2);
    CHECK(comparable_report(dir + "/t2_first.report.json", 2).dump(2) ==
          comparable_report(dir + "/t2_second.report.json", 2).dump(2));
  }
  {
    INFO("1 versus 2 threads");
    require_same_collection(dir + "/t2_first", 2, dir + "/t1", 1);
    CHECK(comparable_report(dir + "/t2_first.report.json", 2).dump(2) ==
          comparable_report(dir + "/t1.report.json", 1).dump(2));
  }
}

TEST_CASE("determinism: convert writes the same EXR, remesh and glTF files twice", "[cli][determinism]") {
  const std::string dir = spherekit::test::temp_dir("determinism_convert");
  const std::string s = make_samples(dir);
  const std::string mesh = s + "/sample_b.obj";
  const std::string map = dir + "/sample_b.sphere.obj";
  CliRun r = sk("param " + q(mesh) + " -o " + q(map) + " --quiet", dir);
  INFO("param stderr: " << r.err);
  REQUIRE(r.exit_code == 0);

  // The repeat, and the repeat with one thread (`first` uses every core). Same input paths
  // (the glTF provenance names them), outputs under the same names in three folders. The
  // levels are the default `original` ones (the mesh itself simplified).
  for (const char* folder : {"first", "second", "one_thread"}) {
    const std::string out = dir + "/" + folder;
    fs::create_directories(out);
    const std::string threads = std::string(folder) == "one_thread" ? " --threads 1" : "";
    r = sk("convert " + q(mesh) + " " + q(map) + " -o " + q(out + "/gim.exr") + " --size 65 --lods 2 --psnr-samples 2000 --remesh " +
               q(out + "/remesh.obj") + " --quiet" + threads,
           dir);
    INFO("run " << folder << ", stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
  }
  const std::vector<std::string> names = files_in(dir + "/first");
  CHECK(names == files_in(dir + "/second"));
  CHECK(names == std::vector<std::string>{"gim.exr", "gim_lod0.glb", "gim_lod1.glb", "gim_lods.glb", "gim_normals.png",
                                           "gim_positions.png", "remesh.obj"});
  CHECK(names == files_in(dir + "/one_thread"));
  for (const std::string& name : names) {
    require_same_bytes(dir + "/first/" + name, dir + "/second/" + name);
    require_same_bytes(dir + "/first/" + name, dir + "/one_thread/" + name);
  }
}
