// Issue 23: the Slurm back end on a real (one-node) cluster. scripts/test.sh starts one with
// scripts/slurm_local.sh and sets SLURM_CONF; elsewhere the test skips with a message. A
// 12-member generated collection goes through `submit --scheduler slurm` (F from 4 members,
// 8 `add` tasks as one job array, conversion, the final check; two threads per task) and must
// give byte for byte the local run's maps, manifest and assets; a plan with a broken member
// must fail.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "scale_helpers.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using spherekit::test::CliRun;
using spherekit::test::q;
using spherekit::test::read_json;
using spherekit::test::sk;
using spherekit::test::slurp;

namespace {

bool slurm_available(std::string* why) {
  const char* conf = std::getenv("SLURM_CONF");
  if (!conf || !fs::exists(conf)) {
    *why = "SLURM_CONF is not set to a slurm.conf (scripts/test.sh starts a one-node cluster with "
           "scripts/slurm_local.sh when slurm-wlm can be installed)";
    return false;
  }
  const std::string tmp = spherekit::test::temp_dir("scale_slurm_probe");
  if (spherekit::test::run_shell("timeout 10 sinfo -h -o %T", tmp + "/o", tmp + "/e") != 0 ||
      slurp(tmp + "/o").find("idle") == std::string::npos) {
    *why = "sinfo finds no idle node (" + slurp(tmp + "/e") + ")";
    return false;
  }
  return true;
}

}  // namespace

TEST_CASE("Slurm back end: a 12-member collection through job arrays equals the local run byte for byte",
          "[cli][scale][slurm][slow]") {
  std::string why;
  if (!slurm_available(&why)) {
    SPHEREKIT_SKIP("no Slurm cluster: " << why);
  }
  const std::string dir = spherekit::test::temp_dir("scale_slurm");
  const std::string s = dir + "/s";
  REQUIRE(sk("samples -o " + q(s) + " --members 12 --vertices 300", dir).exit_code == 0);
  std::string meshes;
  for (const auto& e : fs::directory_iterator(s))
    if (e.path().extension() == ".obj") meshes += " " + q(e.path().string());
  const std::string common = meshes + " --subset 4 --effort 0 --remesh-size 17 --convert-args '--gi 33 --lods 2'";
  // Both runs write the same paths (the assets record their collection's path): the local
  // result is moved aside before the Slurm run.
  auto submit = [&](const std::string& extra) {
    return sk("submit -o " + q(dir + "/col") + " --convert " + q(dir + "/assets") + common + extra + " -q", dir);
  };
  CliRun local = submit("");
  INFO("local: " << local.err);
  REQUIRE(local.exit_code == 0);
  for (const char* f : {"col", "assets", "col.jobs"}) fs::rename(dir + "/" + f, dir + "/local_" + f);
  // Two threads per task there, one here: the bytes do not depend on it.
  CliRun slurm = submit(" --scheduler slurm --cpus-per-task 2 --threads 2 --poll 0.5 --timeout 900");
  INFO("slurm: " << slurm.err);
  REQUIRE(slurm.exit_code == 0);

  // The same collection: manifest, F and every map, byte for byte.
  const auto a = spherekit::test::collection_files(dir + "/local_col"), b = spherekit::test::collection_files(dir + "/col");
  REQUIRE(a.size() == 14);  // manifest, features.txt, 12 maps
  CHECK(a == b);
  CHECK(spherekit::test::collection_map_problems(dir + "/col", nullptr) == 0);
  // The same assets (the report differs in its times).
  auto assets = [](const std::string& d) {
    auto f = spherekit::test::visible_files(d);
    f.erase("convert_report.json");
    return f;
  };
  const auto la = assets(dir + "/local_assets");
  CHECK(la.size() > 12 * 3);
  CHECK(la == assets(dir + "/assets"));
  // What Slurm ran: one array per stage, two logs per task, the final check's report.
  const std::string jobs = dir + "/col.jobs";
  for (const char* stage : {"subset", "maps", "convert", "check"}) CHECK(fs::exists(jobs + "/slurm/" + stage + ".sh"));
  CHECK_FALSE(fs::exists(dir + "/local_col.jobs/slurm"));
  const std::string maps_script = slurp(jobs + "/slurm/maps.sh");
  CHECK(maps_script.find("#SBATCH --array=0-7\n") != std::string::npos);
  CHECK(maps_script.find("#SBATCH --cpus-per-task=2\n") != std::string::npos);
  CHECK(maps_script.find("'--threads' '2'") != std::string::npos);
  CHECK(maps_script.find("export OMP_NUM_THREADS=2\n") != std::string::npos);
  for (int t = 0; t < 8; ++t) CHECK(fs::exists(jobs + "/logs/maps_" + std::to_string(t) + ".err"));
  const auto rep = read_json(jobs + "/submit_report.json");
  CHECK(rep["ok"] == true);
  CHECK(rep["listed"] == 12);
  CHECK(rep["max_task_peak_rss_mb"].get<double>() > 0);

  // A member whose feature file names a vertex it does not have: its add task fails, the
  // later stages are cancelled, submit says which task and exits non-zero.
  const std::string bad = dir + "/bad";
  fs::create_directory(bad);
  std::string bad_meshes;
  for (const char* m : {"sample_a", "sample_b", "sample_c", "sample_d", "sample_e", "sample_f"}) {
    fs::copy_file(s + "/" + m + ".obj", bad + "/" + m + ".obj");
    fs::copy_file(s + "/" + m + ".lm.txt", bad + "/" + m + ".lm.txt");
    bad_meshes += " " + q(bad + "/" + m + ".obj");
  }
  {
    std::string lm = slurp(bad + "/sample_f.lm.txt");
    const size_t sp = lm.find(' ');
    lm = lm.substr(0, sp) + " 99999" + lm.substr(lm.find('\n'));
    std::ofstream(bad + "/sample_f.lm.txt", std::ios::trunc) << lm;
  }
  CliRun failed = sk("submit -o " + q(dir + "/badcol") + bad_meshes +
                         " --subset 3 --subset-by first --effort 0 --remesh-size 17 --scheduler slurm --poll 0.5 "
                         "--timeout 600 -q",
                     dir);
  INFO("failing plan: " << failed.err);
  CHECK(failed.exit_code != 0);
  CHECK(failed.err.find("stage maps: task 2 (sample_f)") != std::string::npos);
  CHECK(failed.err.find("maps_2.err") != std::string::npos);
}
