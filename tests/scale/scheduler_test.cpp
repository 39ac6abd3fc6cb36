// The scheduler library without a scheduler (issue 23): job plans, Slurm scripts and
// arguments, parsing Slurm's answers, the success checks, and both runners against a fake
// cluster or tiny shell commands.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "spherekit/scheduler/collection_plan.h"
#include "spherekit/scheduler/run_plan.h"
#include "spherekit/scheduler/slurm.h"
#include "test_paths.h"

namespace fs = std::filesystem;
namespace sch = spherekit::scheduler;
using spherekit::ErrorCode;

namespace {

// Three stages: one task, an array of three after it, an aftercorr array of three.
sch::JobPlan small_plan(const std::string& work) {
  sch::JobPlan p;
  p.work_dir = work;
  p.cpus_per_task = 2;
  p.threads = 2;
  p.stages.push_back({"first", {{"f", {"/bin/sh", "-c", "echo f > " + work + "/f.txt"}, {work + "/f.txt"}}}, {}});
  sch::JobStage maps{"maps", {}, {{sch::Dependency::AfterOk, 0}}};
  sch::JobStage conv{"conv", {}, {{sch::Dependency::AfterCorr, 1}}};
  for (int i = 0; i < 3; ++i) {
    const std::string m = work + "/m" + std::to_string(i) + ".txt", c = work + "/c" + std::to_string(i) + ".txt";
    maps.tasks.push_back({"m" + std::to_string(i), {"/bin/sh", "-c", "echo " + std::to_string(i) + " > " + m}, {m}});
    conv.tasks.push_back({"c" + std::to_string(i), {"/bin/sh", "-c", "cp " + m + " " + c}, {c}});
  }
  p.stages.push_back(maps);
  p.stages.push_back(conv);
  return p;
}

}  // namespace

TEST_CASE("job plans: validation and a JSON round trip", "[scheduler][scale]") {
  sch::JobPlan p = small_plan("/w");
  REQUIRE(sch::validate_plan(p).ok());
  const std::string text = sch::plan_to_json(p);
  auto back = sch::plan_from_json(text, "plan.json");
  REQUIRE(back.ok());
  CHECK(sch::plan_to_json(back.value()) == text);
  CHECK(back->log_path(1, 2, "err") == "/w/logs/maps_2.err");

  sch::JobPlan bad = p;
  bad.stages[2].tasks.pop_back();  // aftercorr needs equal counts
  CHECK(sch::validate_plan(bad).code() == ErrorCode::InvalidArgument);
  bad = p;
  bad.stages[1].after = {{sch::Dependency::AfterOk, 1}};  // itself
  CHECK(sch::validate_plan(bad).code() == ErrorCode::InvalidArgument);
  bad = p;
  bad.stages[1].name = "first";
  CHECK(sch::validate_plan(bad).message().find("two stages named") != std::string::npos);
  bad = p;
  bad.stages[0].name = "a b";
  CHECK(sch::validate_plan(bad).code() == ErrorCode::InvalidArgument);
  auto broken = sch::plan_from_json("{\"format\": \"x\"}", "p.json");
  REQUIRE_FALSE(broken.ok());
  CHECK(broken.status().message().find("p.json") == 0);
}

TEST_CASE("Slurm scripts: an array per stage, logs per task, threads, quoting that bash reads back", "[scheduler][scale]") {
  const std::string work = spherekit::test::temp_dir("scale_script");
  sch::JobPlan p = small_plan(work);
  p.stages[1].tasks[1].argv = {"/bin/echo", "it's", "a b", "$HOME", "\"q\""};
  sch::SlurmOptions o;
  o.partition = "ci";
  o.time_limit = "10:00";
  const std::string s = sch::stage_script(p, 1, o);
  for (const char* line : {"#SBATCH --array=0-2\n", "#SBATCH --cpus-per-task=2\n", "#SBATCH --partition=ci\n",
                           "#SBATCH --time=10:00\n", "export OMP_NUM_THREADS=2\n", "#SBATCH --job-name=spherekit-maps\n"})
    CHECK(s.find(line) != std::string::npos);
  CHECK(s.find("#SBATCH --output=" + work + "/logs/maps_%a.out\n") != std::string::npos);
  CHECK(s.find("#SBATCH --error=" + work + "/logs/maps_%a.err\n") != std::string::npos);
  CHECK(sch::stage_script(p, 0, o).find("#SBATCH --array=0-0\n") != std::string::npos);
  // The task's words survive the shell unchanged.
  {
    std::ofstream(work + "/maps.sh") << s;
  }
  REQUIRE(spherekit::test::run_shell("SLURM_ARRAY_TASK_ID=1 bash " + work + "/maps.sh", work + "/o.txt", work + "/e.txt") == 0);
  CHECK(spherekit::test::slurp(work + "/o.txt") == "it's a b $HOME \"q\"\n");
  CHECK(spherekit::test::run_shell("SLURM_ARRAY_TASK_ID=7 bash " + work + "/maps.sh", work + "/o.txt", work + "/e.txt") == 2);
}

TEST_CASE("sbatch arguments: dependencies, kill-on-invalid-dep; job ids from --parsable", "[scheduler][scale]") {
  const sch::JobPlan p = small_plan("/w");
  const std::vector<std::string> ids = {"11", "12"};
  CHECK(sch::sbatch_arguments(p, 0, {}, "/w/first.sh") == std::vector<std::string>{"--parsable", "/w/first.sh"});
  CHECK(sch::sbatch_arguments(p, 1, ids, "/w/maps.sh") ==
        std::vector<std::string>{"--parsable", "--dependency=afterok:11", "--kill-on-invalid-dep=yes", "/w/maps.sh"});
  CHECK(sch::sbatch_arguments(p, 2, ids, "/w/conv.sh")[1] == "--dependency=aftercorr:12");
  CHECK(sch::parse_sbatch_job_id("1234\n").value() == "1234");
  CHECK(sch::parse_sbatch_job_id("1234;ci\n").value() == "1234");
  CHECK_FALSE(sch::parse_sbatch_job_id("Submitted batch job 5\n").ok());
  CHECK_FALSE(sch::parse_sbatch_job_id("").ok());
}

TEST_CASE("scontrol records and the stage check: states AND output files", "[scheduler][scale]") {
  const std::string text =
      "JobId=21 ArrayJobId=20 ArrayTaskId=0 JobName=spherekit-maps\n"
      "   JobState=COMPLETED Reason=None Dependency=(null)\n"
      "   ExitCode=0:0 TRES=cpu=1,mem=1M\n"
      "\n"
      "JobId=22 ArrayJobId=20 ArrayTaskId=1 JobName=spherekit-maps\n"
      "   JobState=FAILED Reason=NonZeroExitCode\n"
      "   ExitCode=5:0\n"
      "\n"
      "JobId=20 ArrayJobId=20 ArrayTaskId=2 JobName=spherekit-maps\n"
      "   JobState=COMPLETED Reason=None\n"
      "   ExitCode=0:0\n";
  auto st = sch::parse_scontrol_jobs(text);
  REQUIRE(st.ok());
  REQUIRE(st->size() == 3);
  CHECK((*st)[1].job_id == "20");
  CHECK((*st)[1].task == 1);
  CHECK((*st)[1].state == "FAILED");
  CHECK((*st)[1].exit_code == 5);
  auto pending = sch::parse_scontrol_jobs("JobId=30 ArrayJobId=30 ArrayTaskId=1-3 JobState=PENDING Reason=Dependency\n");
  REQUIRE(pending.ok());
  CHECK((*pending)[0].task == -1);
  CHECK_FALSE(sch::parse_scontrol_jobs("JobState=COMPLETED\n").ok());
  CHECK(sch::is_final_state("CANCELLED"));
  CHECK_FALSE(sch::is_final_state("PENDING"));
  CHECK(sch::squeue_says_done(0, "\n"));
  CHECK_FALSE(sch::squeue_says_done(0, "20_1 RUNNING\n"));
  CHECK(sch::squeue_says_done(1, "slurm_load_jobs error: Invalid job id specified\n"));
  CHECK_FALSE(sch::squeue_says_done(1, "slurm_load_jobs error: Unable to contact slurm controller\n"));

  const sch::JobPlan p = small_plan("/w");
  auto all_exist = [](const std::string&) { return true; };
  spherekit::Status s = sch::check_stage(p, 1, st.value(), all_exist);
  CHECK(s.code() == ErrorCode::SolverFailed);
  CHECK(s.message() == "stage maps: task 1 (m1) FAILED exit 5:0 (NonZeroExitCode); log /w/logs/maps_1.err");
  // Recorded COMPLETED with exit 0, but no output: failed (SCALE.md trap 3).
  std::vector<sch::TaskState> ok3 = st.value();
  ok3[1].state = "COMPLETED";
  ok3[1].exit_code = 0;
  CHECK(sch::check_stage(p, 1, ok3, all_exist).ok());
  s = sch::check_stage(p, 1, ok3, [](const std::string& f) { return f != "/w/m2.txt"; });
  CHECK(s.message().find("task 2 (m2) COMPLETED but its output /w/m2.txt is missing") != std::string::npos);
  ok3.pop_back();
  CHECK(sch::check_stage(p, 1, ok3, all_exist).message().find("no record") != std::string::npos);
}

TEST_CASE("run_plan_local: afterok and aftercorr skip what depends on a failure; logs per task", "[scheduler][scale]") {
  const std::string work = spherekit::test::temp_dir("scale_local_plan");
  sch::JobPlan p = small_plan(work);
  REQUIRE(sch::run_plan_local(p, sch::process_runner()).ok());
  for (int i = 0; i < 3; ++i) CHECK(spherekit::test::slurp(work + "/c" + std::to_string(i) + ".txt") == std::to_string(i) + "\n");
  CHECK(fs::exists(work + "/logs/maps_2.out"));
  for (int i = 0; i < 3; ++i) fs::remove(work + "/c" + std::to_string(i) + ".txt");
  // Task 1 of maps fails: its corresponding conversion does not run, the others do.
  p.stages[1].tasks[1].argv = {"/bin/sh", "-c", "echo broken >&2; exit 5"};
  fs::remove(work + "/m1.txt");
  spherekit::Status s = sch::run_plan_local(p, sch::process_runner());
  CHECK(s.code() == ErrorCode::SolverFailed);
  CHECK(s.message() == "stage maps: task 1 (m1) failed: exit 5; log " + work + "/logs/maps_1.err");
  CHECK(spherekit::test::slurp(work + "/logs/maps_1.err") == "broken\n");
  CHECK(fs::exists(work + "/c0.txt"));
  CHECK_FALSE(fs::exists(work + "/c1.txt"));
  CHECK(fs::exists(work + "/c2.txt"));
  // Exit 0 without its output is a failure too.
  p.stages[1].tasks[1].argv = {"/bin/true"};
  s = sch::run_plan_local(p, sch::process_runner());
  CHECK(s.message().find("exit 0 but its output " + work + "/m1.txt is missing") != std::string::npos);
}

namespace {

// A Slurm stand-in: sbatch records jobs, squeue says RUNNING for the first polls, scontrol
// reports each task with the state `state_of` gives (the tasks are not run).
struct FakeSlurm {
  std::vector<std::vector<std::string>> calls;
  int next_id = 100, polls_left = 2;
  std::map<std::string, int> tasks_of;
  std::function<std::string(const std::string& id, int task)> state_of = [](const std::string&, int) {
    return std::string("COMPLETED");
  };
  sch::CommandRunner runner() {
    return [this](const std::vector<std::string>& argv, const std::string&, const std::string&)
               -> spherekit::Result<sch::CommandResult> {
      calls.push_back(argv);
      sch::CommandResult r{0, ""};
      if (argv[0] == "sbatch") {
        const std::string id = std::to_string(next_id++);
        const std::string script = spherekit::test::slurp(argv.back());
        const size_t a = script.find("--array=0-");
        tasks_of[id] = std::stoi(script.substr(a + 10)) + 1;
        r.out = id + "\n";
      } else if (argv[0] == "squeue") {
        r.out = polls_left-- > 0 ? "100_0 RUNNING\n" : "";
      } else if (argv[0] == "scontrol") {
        const std::string id = argv[3];
        for (int t = 0; t < tasks_of[id]; ++t) {
          const std::string st = state_of(id, t);
          r.out += "JobId=" + std::to_string(1000 + t) + " ArrayJobId=" + id + " ArrayTaskId=" + std::to_string(t) +
                   "\n   JobState=" + st + " Reason=None\n   ExitCode=" + (st == "COMPLETED" ? "0:0" : "1:0") + "\n\n";
        }
      }
      return r;
    };
  }
};

}  // namespace

TEST_CASE("run_plan_slurm against a fake cluster: submission order, polling, failures found", "[scheduler][scale]") {
  const std::string work = spherekit::test::temp_dir("scale_fake_slurm");
  sch::JobPlan p = small_plan(work);
  // The outputs the tasks would have written.
  for (const auto& st : p.stages)
    for (const auto& t : st.tasks)
      for (const auto& f : t.outputs) std::ofstream(f) << "x";
  FakeSlurm fake;
  int sleeps = 0;
  sch::SlurmRun rec;
  spherekit::Status s = sch::run_plan_slurm(p, {}, fake.runner(), [&](double) { ++sleeps; }, 1, 0, &rec);
  INFO(s.message());
  CHECK(s.ok());
  CHECK(rec.job_ids == std::vector<std::string>{"100", "101", "102"});
  CHECK(sleeps == 2);
  REQUIRE(fake.calls.size() >= 3);
  CHECK(fake.calls[1][2] == "--dependency=afterok:100");
  CHECK(fake.calls[2][2] == "--dependency=aftercorr:101");
  CHECK(fs::exists(work + "/slurm/maps.sh"));

  // One task failed, and one "completed" without its output.
  FakeSlurm failing;
  failing.state_of = [](const std::string& id, int t) {
    return id == "102" && t == 1 ? std::string("CANCELLED") : std::string("COMPLETED");
  };
  fs::remove(work + "/m2.txt");
  s = sch::run_plan_slurm(p, {}, failing.runner(), [](double) {}, 1, 0);
  CHECK(s.code() == ErrorCode::SolverFailed);
  CHECK(s.message().find("stage maps: task 2 (m2) COMPLETED but its output") == 0);

  // A timeout cancels the jobs.
  FakeSlurm stuck;
  stuck.polls_left = 1000000;
  s = sch::run_plan_slurm(p, {}, stuck.runner(), [](double) {}, 1, 1e-9);
  CHECK(s.code() == ErrorCode::SolverFailed);
  CHECK(s.message().find("not finished") != std::string::npos);
  CHECK(stuck.calls.back() == std::vector<std::string>{"scancel", "100", "101", "102"});
}

TEST_CASE("collection plan: subset, one add per other member, check last; the memory bound", "[scheduler][scale]") {
  sch::CollectionPlanOptions o;
  o.exe = "/bin/spherekit";
  o.collection = "/c/lib";
  o.work_dir = "/c/lib.jobs";
  for (const char* n : {"e", "b", "d", "a", "c"}) {
    o.meshes.push_back(std::string("/m/") + n + ".obj");
    o.features.push_back(std::string("/m/") + n + ".lm.txt");
    o.names.push_back(n);
  }
  o.subset = {3, 1};
  o.map_args = {"--effort", "1"};
  o.threads = 2;
  auto p = sch::plan_collection(o);
  REQUIRE(p.ok());
  REQUIRE(p->stages.size() == 3);
  const auto& sub = p->stages[0].tasks[0].argv;
  CHECK(std::vector<std::string>(sub.begin(), sub.begin() + 8) ==
        std::vector<std::string>{"/bin/spherekit", "consistent", "-o", "/c/lib", "/m/b.obj", "/m/a.obj", "--features",
                                 "/m/b.lm.txt"});
  REQUIRE(p->stages[1].tasks.size() == 3);
  CHECK(p->stages[1].tasks[0].label == "c");  // by name
  CHECK(p->stages[1].tasks[0].argv[1] == "add");
  CHECK(std::find(p->stages[1].tasks[0].argv.begin(), p->stages[1].tasks[0].argv.end(), "--threads") !=
        p->stages[1].tasks[0].argv.end());
  CHECK(p->stages[1].tasks[0].outputs[0] == "/c/lib/c.sphere.obj");
  CHECK(p->stages[2].name == "check");
  CHECK(p->members == std::vector<std::string>{"a", "b", "c", "d", "e"});
  o.subset = {1, 1};
  CHECK_FALSE(sch::plan_collection(o).ok());

  // d = 3k, d(d+1)/2 doubles per vertex of a 65 x 65 remesh.
  CHECK(sch::joint_quadric_bytes(100, 65) == Approx(8.0 * 65 * 65 * 300 * 301 / 2));
  CHECK(sch::joint_quadric_bytes(100, 65) / 1e9 == Approx(1.53).epsilon(0.01));
  CHECK(sch::largest_subset_for_memory(sch::joint_quadric_bytes(20, 65), 65) == 20);
  CHECK(sch::largest_subset_for_memory(sch::joint_quadric_bytes(20, 65) - 1, 65) == 19);
}

TEST_CASE("farthest-point subset and the feature-layout descriptor", "[scheduler][scale]") {
  // Start: farthest from the mean (10), then farthest from it (0), then from both (5 or 4: 5).
  const std::vector<std::vector<double>> d = {{0}, {1}, {4}, {5}, {10}};
  CHECK(sch::farthest_point_subset(d, 2) == std::vector<int>{0, 4});
  CHECK(sch::farthest_point_subset(d, 3) == std::vector<int>{0, 3, 4});
  CHECK(sch::farthest_point_subset(d, 9).size() == 5);
  // Invariant under rotation and scale.
  const std::vector<double> tri = {0, 0, 0, 1, 0, 0, 0, 2, 0};
  const std::vector<double> turned = {0, 0, 0, 0, 3, 0, -6, 0, 0};  // rotated 90 degrees, scaled 3x
  const auto a = sch::feature_layout_descriptor(tri), b = sch::feature_layout_descriptor(turned);
  REQUIRE(a.size() == 3);
  for (size_t i = 0; i < 3; ++i) CHECK(a[i] == Approx(b[i]));
}
