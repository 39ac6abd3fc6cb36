// JobPlan validation and its JSON form (job_plan.h).
#include "spherekit/scheduler/job_plan.h"

#include <cctype>
#include <nlohmann/json.hpp>
#include <set>

namespace spherekit::scheduler {
namespace {

using Json = nlohmann::ordered_json;

bool plain_word(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

const char* dependency_name(Dependency d) { return d == Dependency::AfterCorr ? "aftercorr" : "afterok"; }

}  // namespace

std::string JobPlan::log_path(int s, int t, const char* stream) const {
  return log_dir() + "/" + stages[static_cast<size_t>(s)].name + "_" + std::to_string(t) + "." + stream;
}

Status validate_plan(const JobPlan& plan) {
  if (plan.work_dir.empty()) return Status(ErrorCode::InvalidArgument, "job plan: no work folder");
  if (plan.cpus_per_task < 1 || plan.threads < 1)
    return Status(ErrorCode::InvalidArgument, "job plan: cpus per task and threads must be at least 1");
  if (plan.stages.empty()) return Status(ErrorCode::InvalidArgument, "job plan: no stages");
  std::set<std::string> names;
  for (size_t s = 0; s < plan.stages.size(); ++s) {
    const JobStage& st = plan.stages[s];
    if (!plain_word(st.name))
      return Status(ErrorCode::InvalidArgument, "job plan: stage name '" + st.name + "' is not a plain word");
    if (!names.insert(st.name).second)
      return Status(ErrorCode::InvalidArgument, "job plan: two stages named '" + st.name + "'");
    if (st.tasks.empty()) return Status(ErrorCode::InvalidArgument, "job plan: stage " + st.name + " has no tasks");
    for (const JobTask& t : st.tasks)
      if (t.argv.empty() || t.argv[0].empty())
        return Status(ErrorCode::InvalidArgument, "job plan: a task of stage " + st.name + " has no command");
    for (const auto& [kind, earlier] : st.after) {
      if (earlier < 0 || static_cast<size_t>(earlier) >= s)
        return Status(ErrorCode::InvalidArgument, "job plan: stage " + st.name + " depends on a stage that is not before it");
      if (kind == Dependency::AfterCorr && plan.stages[static_cast<size_t>(earlier)].tasks.size() != st.tasks.size())
        return Status(ErrorCode::InvalidArgument, "job plan: stage " + st.name + " is aftercorr on " +
                                                      plan.stages[static_cast<size_t>(earlier)].name +
                                                      ", which has another number of tasks");
    }
  }
  return Status();
}

std::string plan_to_json(const JobPlan& plan) {
  Json j;
  j["format"] = "spherekit-job-plan";
  j["format_version"] = 1;
  j["work_dir"] = plan.work_dir;
  j["cpus_per_task"] = plan.cpus_per_task;
  j["threads"] = plan.threads;
  j["collection"] = plan.collection;
  j["members"] = plan.members;
  j["stages"] = Json::array();
  for (const JobStage& st : plan.stages) {
    Json s;
    s["name"] = st.name;
    s["after"] = Json::array();
    for (const auto& [kind, earlier] : st.after) s["after"].push_back({{"kind", dependency_name(kind)}, {"stage", earlier}});
    s["tasks"] = Json::array();
    for (const JobTask& t : st.tasks) s["tasks"].push_back({{"label", t.label}, {"argv", t.argv}, {"outputs", t.outputs}});
    j["stages"].push_back(std::move(s));
  }
  return j.dump(2) + "\n";
}

Result<JobPlan> plan_from_json(const std::string& text, const std::string& source) {
  Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return Status(ErrorCode::ParseError, source + ": not valid JSON");
  JobPlan plan;
  try {
    if (j.value("format", "") != "spherekit-job-plan" || j.value("format_version", 0) != 1)
      return Status(ErrorCode::InvalidInput, source + ": not a spherekit-job-plan (version 1)");
    plan.work_dir = j.at("work_dir").get<std::string>();
    plan.cpus_per_task = j.at("cpus_per_task").get<int>();
    plan.threads = j.at("threads").get<int>();
    plan.collection = j.value("collection", "");
    plan.members = j.value("members", std::vector<std::string>{});
    for (const Json& s : j.at("stages")) {
      JobStage st;
      st.name = s.at("name").get<std::string>();
      for (const Json& a : s.at("after"))
        st.after.emplace_back(a.at("kind").get<std::string>() == "aftercorr" ? Dependency::AfterCorr : Dependency::AfterOk,
                              a.at("stage").get<int>());
      for (const Json& t : s.at("tasks"))
        st.tasks.push_back({t.at("label").get<std::string>(), t.at("argv").get<std::vector<std::string>>(),
                            t.at("outputs").get<std::vector<std::string>>()});
      plan.stages.push_back(std::move(st));
    }
  } catch (const Json::exception& e) {
    return Status(ErrorCode::InvalidInput, source + ": malformed job plan (" + std::string(e.what()) + ")");
  }
  if (Status s = validate_plan(plan); !s.ok()) return Status(ErrorCode::InvalidInput, source + ": " + s.message());
  return plan;
}

}  // namespace spherekit::scheduler
