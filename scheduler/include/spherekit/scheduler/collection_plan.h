// The plan that builds a large consistent collection (Asirvatham, Praun, Hoppe 2005) as
// independent jobs:
//   subset   `consistent` on k representative members: steps 1-5 give the feature locations F
//            (and step 6 their maps);
//   maps     every other member mapped to F on its own (`add`: the paper's §5 way to grow a
//            collection), one task each, all at once (the collection's lock serialises only the
//            manifest updates);
//   convert  optionally `convert --collection` of the result;
//   check    every member listed with its map, every output present (`submit --verify`).
// The result is, by construction, `consistent` on the subset followed by `add` of the rest.
//
// Why a subset: step 5 simplifies one mesh whose vertices live in R^d, d = 3k, keeping one
// packed quadric of d(d+1)/2 doubles per vertex of the N x N remesh (libparam's QuadricND), so
// its memory is about 8 N^2 (3k)(3k+1)/2 bytes: 60 MB at k = 20, 1.5 GB at k = 100, 150 GB at
// k = 1000 for N = 65. joint_quadric_bytes() gives it, largest_subset_for_memory() inverts it.
#pragma once

#include <string>
#include <vector>

#include "spherekit/scheduler/job_plan.h"

namespace spherekit::scheduler {

struct CollectionPlanOptions {
  std::string exe;                          ///< the spherekit program (absolute path)
  std::string collection;                   ///< the collection folder to write
  std::string work_dir;                     ///< scripts, logs, per-task reports, the plan
  std::vector<std::string> meshes;          ///< every member's mesh (absolute paths)
  std::vector<std::string> features;        ///< its feature file, one per mesh
  std::vector<std::string> names;           ///< member names (mesh file stems), unique
  std::vector<int> subset;                  ///< indices of the members that decide F
  std::vector<std::string> map_args;        ///< given to `consistent` and every `add` (e.g. --effort 1 --seed 3)
  std::vector<std::string> consistent_args; ///< given to `consistent` only (e.g. --remesh-size 33)
  std::string convert_output;               ///< empty: no conversion stage
  std::vector<std::string> convert_args;    ///< given to `convert --collection`
  int cpus_per_task = 1;
  int threads = 1;
};

/// The plan. Errors: InvalidArgument (sizes, names not unique, subset empty, out of range or
/// repeated).
Result<JobPlan> plan_collection(const CollectionPlanOptions& options);

/// Bytes of step 5's quadrics for k members and an N x N remesh (the bound that decides k).
double joint_quadric_bytes(int members, int remesh_size);

/// The largest k whose joint_quadric_bytes fit in `bytes` (at least 1).
int largest_subset_for_memory(double bytes, int remesh_size);

/// k members spread over the shapes: farthest-point order on the descriptors (one vector per
/// member, same length), starting from the member farthest from the mean; ties go to the
/// lower index. Deterministic. Returns the indices sorted. k is clamped to [1, n].
std::vector<int> farthest_point_subset(const std::vector<std::vector<double>>& descriptors, int k);

/// A rotation- and scale-invariant descriptor of a member's feature layout: the distances
/// between every pair of its feature points, divided by their root mean square. `points`:
/// one x, y, z per feature, in the collection's feature order.
std::vector<double> feature_layout_descriptor(const std::vector<double>& points);

}  // namespace spherekit::scheduler
