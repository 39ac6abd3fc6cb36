// Issue 23: crash safety. `kill -9` at 20 seeded random moments of `add`, of `consistent`
// rewriting a collection, and of `convert --collection` rewriting its assets: the folder always
// reads as the old or the new version, never a mix or nothing, and running the command again
// completes it (and clears the leftovers of the killed run).
#include <catch2/catch.hpp>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "scale_helpers.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using spherekit::test::q;
using spherekit::test::sk;

namespace {

using Files = std::map<std::string, std::string>;

struct KillOutcome {
  int old_state = 0, new_state = 0;
};

// Runs `argv` 20 times from the folder state `reset` makes, killing it after a seeded random
// delay in [0, 1.2 t] (t: an uninterrupted run's time, so some kills land after it finished);
// after each kill `read` must give `old_files` or `new_files`, and a re-run must give
// `new_files` and leave no hidden sibling behind.
KillOutcome kill_at_random_moments(const std::vector<std::string>& argv, const std::function<void()>& reset,
                                   const std::function<Files()>& read, const Files& old_files, const Files& new_files,
                                   const std::string& target, double t, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> delay(0.0, 1.2 * t);
  KillOutcome o;
  for (int i = 0; i < 20; ++i) {
    reset();
    const double d = delay(rng);
    INFO("kill " << i << " after " << d << " s");
    const int pid = spherekit::test::spawn_quiet(argv);
    REQUIRE(pid > 0);
    std::this_thread::sleep_for(std::chrono::duration<double>(d));
    ::kill(pid, SIGKILL);
    spherekit::test::wait_for(pid);
    const Files now = read();
    const bool is_old = now == old_files, is_new = now == new_files;
    CHECK((is_old || is_new));
    o.old_state += is_old;
    o.new_state += is_new;
    // Again, to the end (a completed run may refuse to add a member twice: then it is there).
    const int again = spherekit::test::wait_for(spherekit::test::spawn_quiet(argv));
    CHECK((again == 0 || (is_new && again == 2)));
    CHECK(read() == new_files);
    CHECK(spherekit::test::hidden_siblings(target).empty());
  }
  return o;
}

double timed_run(const std::vector<std::string>& argv) {
  const auto t0 = std::chrono::steady_clock::now();
  REQUIRE(spherekit::test::wait_for(spherekit::test::spawn_quiet(argv)) == 0);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TEST_CASE("kill -9 at 20 random moments of add, consistent and convert --collection: old or new, re-run completes",
          "[cli][collection][scale][slow]") {
  const std::string dir = spherekit::test::temp_dir("scale_crash");
  const std::string s = dir + "/s", base = dir + "/base", col = dir + "/col";
  REQUIRE(sk("samples -o " + q(s) + " --members 3 --vertices 300", dir).exit_code == 0);
  const std::string exe = SPHEREKIT_EXE;
  const std::vector<std::string> make_old = {exe, "consistent", "-o", base, s + "/sample_a.obj", s + "/sample_b.obj",
                                             "--effort", "0", "--remesh-size", "17", "-q"};
  timed_run(make_old);
  auto reset = [&] {
    fs::remove_all(col);
    for (const auto& n : spherekit::test::hidden_siblings(col)) fs::remove_all(dir + "/" + n);
    fs::copy(base, col, fs::copy_options::recursive);
  };
  auto read = [&] { return spherekit::test::collection_files(col); };
  const Files old_files = spherekit::test::collection_files(base);
  REQUIRE(old_files.size() == 4);

  SECTION("add") {
    const std::vector<std::string> add = {exe, "add", col, s + "/sample_c.obj", "--effort", "0", "-q"};
    reset();
    const double t = timed_run(add);
    const Files new_files = read();
    REQUIRE(new_files.size() == 5);
    const KillOutcome o = kill_at_random_moments(add, reset, read, old_files, new_files, col, t, 23);
    WARN("add: " << o.old_state << " kills left the old collection, " << o.new_state << " the new (run " << t << " s)");
    CHECK(spherekit::test::collection_map_problems(col, nullptr) == 0);
  }
  SECTION("consistent over an existing collection") {
    const std::vector<std::string> redo = {exe, "consistent", "-o", col, s + "/sample_a.obj", s + "/sample_b.obj",
                                           s + "/sample_c.obj", "--effort", "0", "--remesh-size", "17", "-q"};
    reset();
    const double t = timed_run(redo);
    const Files new_files = read();
    REQUIRE(new_files.size() == 5);
    const KillOutcome o = kill_at_random_moments(redo, reset, read, old_files, new_files, col, t, 24);
    WARN("consistent: " << o.old_state << " kills left the old collection, " << o.new_state << " the new (run " << t
                        << " s)");
  }
  SECTION("convert --collection over existing assets") {
    const std::string out = dir + "/assets", out_base = dir + "/assets_base";
    const std::vector<std::string> conv_old = {exe, "convert", "--collection", base, "-o", out_base, "--gi", "9", "-q"};
    timed_run(conv_old);
    // New assets: the same collection converted at another size.
    const std::vector<std::string> conv = {exe, "convert", "--collection", base, "-o", out, "--gi", "17", "-q"};
    auto reset_assets = [&] {
      fs::remove_all(out);
      for (const auto& n : spherekit::test::hidden_siblings(out)) fs::remove_all(dir + "/" + n);
      fs::copy(out_base, out, fs::copy_options::recursive);
    };
    // convert_report.json carries times: the images identify the version.
    auto read_assets = [&] {
      Files f = spherekit::test::visible_files(out);
      f.erase("convert_report.json");
      return f;
    };
    reset_assets();
    const Files old_assets = read_assets();
    const double t = timed_run(conv);
    const Files new_assets = read_assets();
    REQUIRE(new_assets != old_assets);
    const KillOutcome o = kill_at_random_moments(conv, reset_assets, read_assets, old_assets, new_assets, out, t, 25);
    WARN("convert: " << o.old_state << " kills left the old assets, " << o.new_state << " the new (run " << t << " s)");
  }
}
