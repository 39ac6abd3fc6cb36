// submit's data jobs (submit_jobs.h): the subset choice, the work folder, the final check.
#include "spherekit/scheduler/submit_jobs.h"

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "spherekit/file_status.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/metrics.h"
#include "spherekit/scheduler/collection_plan.h"
#include "spherekit/scheduler/job_plan.h"

namespace fs = std::filesystem;

namespace spherekit::scheduler {

Result<std::vector<std::vector<double>>> feature_layouts(const std::vector<std::string>& meshes,
                                                         const std::vector<std::string>& features) {
  if (features.size() != meshes.size())
    return Status(ErrorCode::InvalidArgument, "feature_layouts: one feature file per mesh");
  std::vector<std::vector<double>> out;
  std::vector<std::string> names;
  for (size_t i = 0; i < meshes.size(); ++i) {
    SPHEREKIT_ASSIGN_OR_RETURN(TriMesh mesh, formats::read_mesh(meshes[i]));
    auto lms = formats::read_landmarks(features[i], static_cast<int>(mesh.V.rows()));
    if (!lms.ok()) return with_file(lms.status(), features[i]);
    if (names.empty())
      for (const Landmark& l : lms.value()) names.push_back(l.name);
    std::vector<double> p;
    for (const std::string& n : names) {
      auto it = std::find_if(lms->begin(), lms->end(), [&](const Landmark& l) { return l.name == n; });
      if (it == lms->end())
        return Status(ErrorCode::InvalidInput, features[i] + ": no feature '" + n + "' (" + features[0] + " has it)");
      for (int a = 0; a < 3; ++a) p.push_back(mesh.V(it->vertex, a));
    }
    out.push_back(feature_layout_descriptor(p));
  }
  return out;
}

std::string absolute_path(const std::string& p) {
  std::error_code ec;
  return fs::weakly_canonical(fs::absolute(p, ec), ec).string();
}

Status add_members(CollectionPlanOptions& o, const std::vector<std::string>& meshes,
                   const std::vector<std::string>& features) {
  for (size_t i = 0; i < meshes.size(); ++i) {
    std::error_code ec;
    if (!fs::is_regular_file(meshes[i], ec)) return Status(ErrorCode::IoError, meshes[i] + ": cannot open (no such file)");
    const fs::path p(meshes[i]);
    o.meshes.push_back(absolute_path(meshes[i]));
    o.features.push_back(absolute_path(
        i < features.size() ? features[i] : (p.parent_path() / (p.stem().string() + ".lm.txt")).string()));
    o.names.push_back(p.stem().string());
  }
  return Status();
}

Result<SubsetChoice> choose_subset(const CollectionPlanOptions& o, const SubsetRequest& r) {
  const int n = static_cast<int>(o.meshes.size());
  SubsetChoice c;
  // k: as given, else as many as the joint step's memory allows, at most 12 (the step-2/6
  // maps of the subset run in one job, so a larger k lengthens the critical path).
  c.k_memory = largest_subset_for_memory(r.joint_memory_mb * 1024 * 1024, r.remesh_size);
  const int k = r.k > 0 ? std::min(r.k, n) : std::min({n, 12, c.k_memory});
  if (!r.members.empty()) {
    for (const std::string& m : r.members) {
      auto it = std::find(o.names.begin(), o.names.end(), m);
      if (it == o.names.end())
        return Status(ErrorCode::InvalidArgument, "--subset-members: '" + m + "' is not one of the meshes");
      c.subset.push_back(static_cast<int>(it - o.names.begin()));
    }
  } else if (!r.farthest) {
    for (int i = 0; i < k; ++i) c.subset.push_back(i);
  } else {
    SPHEREKIT_ASSIGN_OR_RETURN(auto d, feature_layouts(o.meshes, o.features));
    c.subset = farthest_point_subset(d, k);
  }
  return c;
}

Status write_plan(const JobPlan& plan) {
  const std::string& work_dir = plan.work_dir;
  std::error_code ec;
  fs::create_directories(work_dir + "/reports", ec);
  if (ec) return Status(ErrorCode::IoError, work_dir + ": cannot create (" + ec.message() + ")");
  fs::remove_all(work_dir + "/reports", ec);
  fs::remove(work_dir + "/submit_report.json", ec);
  fs::create_directories(work_dir + "/reports", ec);
  return formats::write_file_atomic(work_dir + "/plan.json", plan_to_json(plan));
}

Status run_plan(const JobPlan& plan, const RunRequest& r, const ProgressFn& progress) {
  if (!r.slurm) return run_plan_local(plan, process_runner(), progress);
  return run_plan_slurm(
      plan, r.slurm_options, process_runner(),
      [](double sec) { std::this_thread::sleep_for(std::chrono::duration<double>(sec)); }, r.poll_seconds,
      r.timeout_seconds, nullptr, progress);
}

Status PlanVerification::failure() const {
  if (!missing.empty())
    return Status(ErrorCode::SolverFailed, collection + ": " + std::to_string(missing.size()) +
                                               " planned members are not in the manifest (first: " + missing[0] + ")");
  if (!broken.empty()) return Status(ErrorCode::SolverFailed, collection + ": " + broken[0]);
  return Status();
}

std::string to_json(const PlanVerification& v) {
  using Json = nlohmann::ordered_json;
  Json tasks = Json::array();
  for (const TaskMeasure& t : v.tasks)
    tasks.push_back({{"stage", t.stage}, {"task", t.task}, {"peak_rss_mb", t.peak_rss_mb}, {"wall_seconds", t.wall_seconds}});
  const Json report{{"collection", v.collection},       {"members", v.members},
                    {"listed", v.listed},               {"missing", v.missing},
                    {"broken", v.broken},               {"tasks", tasks},
                    {"max_task_peak_rss_mb", v.max_task_peak_rss_mb}, {"ok", v.ok()}};
  // Non-finite doubles become null (nlohmann's choice), which every JSON reader accepts.
  return report.dump(2) + "\n";
}

namespace {

bool is_task_report(const std::string& out) {
  return out.size() >= 5 && out.compare(out.size() - 5, 5, ".json") == 0 && out.find("/reports/") != std::string::npos;
}

}  // namespace

Result<PlanVerification> verify_plan(const std::string& plan_path) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, formats::read_file(plan_path));
  SPHEREKIT_ASSIGN_OR_RETURN(JobPlan plan, plan_from_json(text, plan_path));
  SPHEREKIT_ASSIGN_OR_RETURN(formats::Collection col, formats::read_collection(plan.collection));
  PlanVerification v;
  v.collection = plan.collection;
  v.work_dir = plan.work_dir;
  v.members = plan.members.size();
  v.listed = col.manifest.members.size();
  for (const std::string& m : plan.members)
    if (col.manifest.member_index(m) < 0) v.missing.push_back(m);
  // Every map once, at the end: present, of its mesh, a bijection by the exact predicate.
  for (const formats::CollectionMember& e : col.manifest.members) {
    auto mesh = formats::read_mesh(e.source.value_or(""));
    if (!mesh.ok()) { v.broken.push_back(e.name + ": " + mesh.status().message()); continue; }
    auto map = formats::read_sphere_map((fs::path(plan.collection) / e.map).string(), mesh.value());
    if (!map.ok()) { v.broken.push_back(e.name + ": " + map.status().message()); continue; }
    if (const int f = count_flipped_faces(mesh->F, map->S); f != 0)
      v.broken.push_back(e.name + ": " + std::to_string(f) + " flipped faces");
  }
  // Per-task measures from the tasks' own reports; a task without one is not measured.
  for (const JobStage& st : plan.stages)
    for (const JobTask& t : st.tasks)
      for (const std::string& out : t.outputs) {
        if (!is_task_report(out)) continue;
        auto r = formats::read_file(out);
        if (!r.ok()) continue;
        const auto j = nlohmann::ordered_json::parse(r.value(), nullptr, false);
        if (j.is_discarded()) continue;
        TaskMeasure m{st.name, t.label, j.value("peak_rss_mb", 0.0), 0.0};
        if (j.contains("times") && j["times"].is_object()) m.wall_seconds = j["times"].value("wall", 0.0);
        v.max_task_peak_rss_mb = std::max(v.max_task_peak_rss_mb, m.peak_rss_mb);
        v.tasks.push_back(m);
      }
  SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(plan.work_dir + "/submit_report.json", to_json(v)));
  return v;
}

}  // namespace spherekit::scheduler
