// The built-in sample collection: procedural, animal-like genus-0 shapes (body, four legs,
// tail, head, ears) in several proportions and poses, each meshed with its own
// connectivity (some with a hole), with corresponding landmarks and an exact ground-truth
// correspondence. The main job and the tests run on these, so no downloaded data is needed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spherekit/features.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::samples {

/// One member of the collection.
struct SampleMesh {
  std::string name;                  ///< file stem, e.g. "sample_a"
  TriMesh mesh;                      ///< genus 0, manifold, ccw outward faces; may have one hole
  std::vector<Landmark> landmarks;   ///< same names, same order in every member
  /// Ground truth: #V by 3 unit vectors, the point of the common template domain (unit
  /// sphere) that each vertex is. Two surface points of different members correspond
  /// exactly when their template points are equal.
  RowMat3d template_points;
  int boundary_loops = 0;
};

struct SampleCollectionOptions {
  int members = 4;             ///< how many shapes (1..1000; names sample_a.., sample_aa.., sample_aaa..)
  int target_vertices = 3000;  ///< approximate vertex count per member
  std::uint64_t seed = 1;      ///< all shape and meshing randomness derives from this
};

/// Builds the collection. Deterministic in the options.
Result<std::vector<SampleMesh>> make_sample_collection(const SampleCollectionOptions& options = {});

/// Ground-truth image on member `to` of vertex `v` of member `from`: the surface point of
/// `to` whose template point equals from.template_points(v) (located by gnomonic
/// barycentrics in `to`'s template triangulation). Returns false if not found (a hole).
bool ground_truth_point(const SampleMesh& from, int v, const SampleMesh& to, Eigen::Vector3d* point);

/// Writes the collection to `dir`: `<name>.obj`, `<name>.lm.txt` (landmarks),
/// `<name>.template.txt` (per-vertex template points, `x y z` per line) and
/// `<name>.corr.txt` (line k of every member's file names corresponding vertices, the
/// format of shared/tools/evalcorr.py --corr). Files are written atomically.
/// The .corr.txt samples are 500 Fibonacci points of the template sphere minus those in
/// any member's hole; line k is each member's vertex with the nearest template point
/// (so corresponding vertices agree to about half an edge length, not exactly).
/// `dir` is created if missing. Errors: InvalidArgument (empty collection, template
/// points not matching the vertices), IoError.
Status write_sample_collection(const std::string& dir, const std::vector<SampleMesh>& collection);

}  // namespace spherekit::samples
