// The collection pipeline as a job plan (collection_plan.h).
#include "spherekit/scheduler/collection_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace spherekit::scheduler {
namespace {

std::vector<std::string> with_threads(std::vector<std::string> argv, int threads) {
  argv.push_back("--threads");
  argv.push_back(std::to_string(threads));
  return argv;
}

}  // namespace

double joint_quadric_bytes(int members, int remesh_size) {
  const double d = 3.0 * members;
  return 8.0 * static_cast<double>(remesh_size) * remesh_size * d * (d + 1) / 2;
}

int largest_subset_for_memory(double bytes, int remesh_size) {
  int k = 1;
  while (joint_quadric_bytes(k + 1, remesh_size) <= bytes && k < 100000) ++k;
  return k;
}

std::vector<int> farthest_point_subset(const std::vector<std::vector<double>>& d, int k) {
  const int n = static_cast<int>(d.size());
  if (n == 0) return {};
  k = std::clamp(k, 1, n);
  auto dist2 = [&](const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size() && i < b.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return s;
  };
  std::vector<double> mean(d[0].size(), 0.0);
  for (const auto& v : d)
    for (size_t i = 0; i < mean.size() && i < v.size(); ++i) mean[i] += v[i] / n;
  int first = 0;
  for (int i = 1; i < n; ++i)
    if (dist2(d[static_cast<size_t>(i)], mean) > dist2(d[static_cast<size_t>(first)], mean)) first = i;
  std::vector<int> chosen = {first};
  std::vector<double> nearest(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  while (static_cast<int>(chosen.size()) < k) {
    const auto& last = d[static_cast<size_t>(chosen.back())];
    int best = -1;
    for (int i = 0; i < n; ++i) {
      nearest[static_cast<size_t>(i)] = std::min(nearest[static_cast<size_t>(i)], dist2(d[static_cast<size_t>(i)], last));
      if (std::find(chosen.begin(), chosen.end(), i) != chosen.end()) continue;
      if (best < 0 || nearest[static_cast<size_t>(i)] > nearest[static_cast<size_t>(best)]) best = i;
    }
    chosen.push_back(best);
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

std::vector<double> feature_layout_descriptor(const std::vector<double>& p) {
  const size_t m = p.size() / 3;
  std::vector<double> out;
  double sum2 = 0;
  for (size_t a = 0; a < m; ++a)
    for (size_t b = a + 1; b < m; ++b) {
      const double dx = p[3 * a] - p[3 * b], dy = p[3 * a + 1] - p[3 * b + 1], dz = p[3 * a + 2] - p[3 * b + 2];
      out.push_back(std::sqrt(dx * dx + dy * dy + dz * dz));
      sum2 += out.back() * out.back();
    }
  const double rms = out.empty() ? 0 : std::sqrt(sum2 / static_cast<double>(out.size()));
  if (rms > 0)
    for (double& x : out) x /= rms;
  return out;
}

Result<JobPlan> plan_collection(const CollectionPlanOptions& o) {
  const size_t n = o.meshes.size();
  if (n == 0) return Status(ErrorCode::InvalidArgument, "collection plan: no meshes");
  if (o.features.size() != n || o.names.size() != n)
    return Status(ErrorCode::InvalidArgument, "collection plan: one feature file and one name per mesh");
  if (std::set<std::string>(o.names.begin(), o.names.end()).size() != n)
    return Status(ErrorCode::InvalidArgument, "collection plan: member names are not unique");
  if (o.subset.empty()) return Status(ErrorCode::InvalidArgument, "collection plan: empty subset");
  std::vector<char> in_subset(n, 0);
  for (int i : o.subset) {
    if (i < 0 || static_cast<size_t>(i) >= n || in_subset[static_cast<size_t>(i)])
      return Status(ErrorCode::InvalidArgument, "collection plan: subset index out of range or repeated");
    in_subset[static_cast<size_t>(i)] = 1;
  }
  JobPlan plan;
  plan.work_dir = o.work_dir;
  plan.cpus_per_task = o.cpus_per_task;
  plan.threads = o.threads;
  plan.collection = o.collection;
  plan.members = o.names;
  std::sort(plan.members.begin(), plan.members.end());
  const std::string reports = o.work_dir + "/reports";

  // subset: steps 1-6 on k members.
  JobStage subset{"subset", {}, {}};
  {
    JobTask t;
    t.label = std::to_string(o.subset.size()) + " members";
    t.argv = {o.exe, "consistent", "-o", o.collection};
    std::vector<int> idx = o.subset;
    std::sort(idx.begin(), idx.end());
    for (int i : idx) t.argv.push_back(o.meshes[static_cast<size_t>(i)]);
    t.argv.push_back("--features");
    for (int i : idx) t.argv.push_back(o.features[static_cast<size_t>(i)]);
    t.argv.insert(t.argv.end(), o.map_args.begin(), o.map_args.end());
    t.argv.insert(t.argv.end(), o.consistent_args.begin(), o.consistent_args.end());
    t.argv = with_threads(t.argv, o.threads);
    t.argv.insert(t.argv.end(), {"--quiet", "--report", reports + "/subset.json"});
    t.outputs = {o.collection + "/collection.json", reports + "/subset.json"};
    subset.tasks.push_back(std::move(t));
  }
  plan.stages.push_back(std::move(subset));
  int last = 0;

  // maps: every other member to F, one task each (in name order: the logs' numbering).
  std::vector<size_t> rest;
  for (size_t i = 0; i < n; ++i)
    if (!in_subset[i]) rest.push_back(i);
  std::sort(rest.begin(), rest.end(), [&](size_t a, size_t b) { return o.names[a] < o.names[b]; });
  if (!rest.empty()) {
    JobStage maps{"maps", {}, {{Dependency::AfterOk, 0}}};
    for (size_t i : rest) {
      JobTask t;
      t.label = o.names[i];
      const std::string report = reports + "/maps_" + o.names[i] + ".json";
      t.argv = {o.exe, "add", o.collection, o.meshes[i], "--features", o.features[i]};
      t.argv.insert(t.argv.end(), o.map_args.begin(), o.map_args.end());
      t.argv = with_threads(t.argv, o.threads);
      t.argv.insert(t.argv.end(), {"--quiet", "--report", report});
      t.outputs = {o.collection + "/" + o.names[i] + ".sphere.obj", report};
      maps.tasks.push_back(std::move(t));
    }
    plan.stages.push_back(std::move(maps));
    last = static_cast<int>(plan.stages.size()) - 1;
  }

  if (!o.convert_output.empty()) {
    JobStage conv{"convert", {}, {{Dependency::AfterOk, last}}};
    JobTask t;
    t.label = "convert --collection";
    t.argv = {o.exe, "convert", "--collection", o.collection, "-o", o.convert_output};
    t.argv.insert(t.argv.end(), o.convert_args.begin(), o.convert_args.end());
    t.argv.insert(t.argv.end(), {"--quiet"});
    t.outputs = {o.convert_output + "/convert_report.json"};
    conv.tasks.push_back(std::move(t));
    plan.stages.push_back(std::move(conv));
    last = static_cast<int>(plan.stages.size()) - 1;
  }

  JobStage check{"check", {}, {{Dependency::AfterOk, last}}};
  check.tasks.push_back({"verify", {o.exe, "submit", "--verify", o.work_dir + "/plan.json"}, {o.work_dir + "/submit_report.json"}});
  plan.stages.push_back(std::move(check));
  SPHEREKIT_RETURN_IF_ERROR(validate_plan(plan));
  return plan;
}

}  // namespace spherekit::scheduler
