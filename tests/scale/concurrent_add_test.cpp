// Issue 23: collections that grow safely. Concurrent `add`s into one collection all land (the
// manifest's read-modify-write is under the folder's lock), the manifest does not depend on the
// order they finish in, and a map computed elsewhere can be registered (verified) instead of
// computed again.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "scale_helpers.h"
#include "test_paths.h"

#include "cli_test_prelude.h"

namespace {

const char* const kAdded[] = {"sample_c", "sample_d", "sample_e", "sample_f",
                              "sample_g", "sample_h", "sample_i", "sample_j"};

}  // namespace

TEST_CASE("8 concurrent adds into one collection: all 8 in the manifest, every map valid, order-independent bytes",
          "[cli][collection][scale]") {
  const std::string dir = spherekit::test::temp_dir("scale_concurrent_add");
  const std::string s = dir + "/s", col = dir + "/col", seq = dir + "/seq";
  REQUIRE(sk("samples -o " + q(s) + " --members 12 --vertices 300", dir).exit_code == 0);
  CliRun r = sk("consistent -o " + q(col) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_b.obj") +
                    " --effort 0 --remesh-size 17 -q",
                dir);
  INFO("consistent: " << r.err);
  REQUIRE(r.exit_code == 0);
  fs::copy(col, seq);

  // All eight at once, each one's exit code kept.
  std::string script;
  for (const char* m : kAdded)
    script += q(SPHEREKIT_EXE) + " add " + q(col) + " " + q(s + "/" + m + ".obj") + " --effort 0 -q 2>" +
              q(dir + "/" + m + ".err") + " & pids=\"$pids $!\"\n";
  script += "fail=0; for p in $pids; do wait $p || fail=1; done; exit $fail\n";
  const int code = spherekit::test::run_shell(script, dir + "/out.txt", dir + "/err.txt");
  for (const char* m : kAdded) INFO(m << ": " << slurp(dir + "/" + m + ".err"));
  REQUIRE(code == 0);

  const json man = read_json(col + "/collection.json");
  REQUIRE(man["meshes"].size() == 10);
  std::vector<std::string> names;
  for (const auto& e : man["meshes"]) names.push_back(e["name"].get<std::string>());
  CHECK(std::is_sorted(names.begin(), names.end()));
  for (const char* m : kAdded) CHECK(std::count(names.begin(), names.end(), m) == 1);
  std::string problem;
  CHECK(spherekit::test::collection_map_problems(col, &problem) == 0);
  INFO(problem);
  // No temporary files left in the folder.
  for (const auto& e : fs::directory_iterator(col)) CHECK(e.path().filename().string().find(".tmp.") == std::string::npos);

  // The same adds one after another, in reverse order: the same bytes (members sorted by
  // name, no times in the manifest).
  for (int i = 7; i >= 0; --i) {
    r = sk("add " + q(seq) + " " + q(s + "/" + kAdded[i] + ".obj") + " --effort 0 -q", dir);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
  }
  CHECK(spherekit::test::collection_files(seq) == spherekit::test::collection_files(col));
}

TEST_CASE("add --map registers a map computed elsewhere, verified like add's own", "[cli][collection][scale]") {
  const std::string dir = spherekit::test::temp_dir("scale_register");
  const std::string s = dir + "/s", col = dir + "/col", ref = dir + "/ref";
  REQUIRE(sk("samples -o " + q(s) + " --members 4 --vertices 300", dir).exit_code == 0);
  CliRun r = sk("consistent -o " + q(col) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_b.obj") +
                    " --effort 0 --remesh-size 17 -q",
                dir);
  REQUIRE(r.exit_code == 0);
  fs::copy(col, ref);
  // The per-member job: param with the collection's locations as targets (elsewhere).
  r = sk("param " + q(s + "/sample_c.obj") + " --features " + q(s + "/sample_c.lm.txt") + " --targets " +
             q(col + "/features.txt") + " -o " + q(dir + "/c.sphere.obj") + " --effort 0 -q",
         dir);
  INFO("param: " << r.err);
  REQUIRE(r.exit_code == 0);
  r = sk("add " + q(col) + " " + q(s + "/sample_c.obj") + " --map " + q(dir + "/c.sphere.obj") + " -q", dir);
  INFO("add --map: " << r.err);
  REQUIRE(r.exit_code == 0);
  // The registered map is the file given, and what add itself computes before the
  // correspondence refinement (a registered map is taken as given, never refined).
  CHECK(slurp(col + "/sample_c.sphere.obj") == slurp(dir + "/c.sphere.obj"));
  REQUIRE(sk("add " + q(ref) + " " + q(s + "/sample_c.obj") + " --effort 0 --no-refine-correspondence -q", dir).exit_code == 0);
  CHECK(slurp(ref + "/sample_c.sphere.obj") == slurp(col + "/sample_c.sphere.obj"));
  const json man = read_json(col + "/collection.json");
  REQUIRE(man["meshes"].size() == 3);
  CHECK(man["meshes"][2]["result"]["registered_from"].get<std::string>().find("c.sphere.obj") != std::string::npos);
  CHECK(spherekit::test::collection_map_problems(col, nullptr) == 0);

  // Refused: features elsewhere (the unconstrained map), and another mesh's map.
  REQUIRE(sk("param " + q(s + "/sample_d.obj") + " -o " + q(dir + "/d_free.sphere.obj") + " --effort 0 -q", dir).exit_code == 0);
  const std::string before = slurp(col + "/collection.json");
  r = sk("add " + q(col) + " " + q(s + "/sample_d.obj") + " --map " + q(dir + "/d_free.sphere.obj") + " -q", dir);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("off the collection's location") != std::string::npos);
  r = sk("add " + q(col) + " " + q(s + "/sample_d.obj") + " --map " + q(dir + "/c.sphere.obj") + " -q", dir);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("c.sphere.obj") != std::string::npos);
  CHECK(slurp(col + "/collection.json") == before);
  CHECK_FALSE(fs::exists(col + "/sample_d.sphere.obj"));
}
