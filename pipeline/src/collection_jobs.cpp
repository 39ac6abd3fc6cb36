// make_collection() and add_to_collection() (collection.h): the consistent parameterization
// of a collection into its folder, and a new member mapped onto an existing collection's
// feature locations.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>

#include "sample_collection.h"
#include "spherekit/check_mesh.h"
#include "spherekit/file_status.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/metrics.h"
#include "spherekit/propose_landmarks.h"
#include "spherekit/pipeline/collection.h"
#include "spherekit/pipeline/collection_update.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/version.h"
#include "spherekit/format_text.h"
#include "stopwatch.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline {
namespace {


// A map may enter a collection only if it is a bijection with every feature on its location.
Status require_exact(const ConstrainedParamResult& r, const std::string& label) {
  if (r.flipped_faces != 0)
    return Status(ErrorCode::SolverFailed,
                  format_text("%s: the map has %d flipped faces (not bijective)", label.c_str(), r.flipped_faces));
  if (!(r.max_feature_angle < 1e-9))
    return Status(ErrorCode::Internal, format_text("%s: a feature is %.3g rad off its location", label.c_str(), r.max_feature_angle));
  return Status();
}

// Feature vertices of a mesh in the order of `names`, from its landmark file.
Result<std::vector<int>> features_in_order(const std::string& lm_path, int vertices,
                                           const std::vector<std::string>& names) {
  auto lms = formats::read_landmarks(lm_path, vertices);
  if (!lms.ok()) return with_file(lms.status(), lm_path);
  std::vector<int> fv;
  for (const std::string& name : names) {
    auto it = std::find_if(lms->begin(), lms->end(), [&](const Landmark& l) { return l.name == name; });
    if (it == lms->end())
      return Status(ErrorCode::InvalidInput, format_text("%s: no feature '%s' (the collection needs every one of its %zu features)",
                                                         lm_path.c_str(), name.c_str(), names.size()));
    fv.push_back(it->vertex);
  }
  return fv;
}

std::string default_features_path(const std::string& mesh) {
  const fs::path p(mesh);
  return (p.parent_path() / (p.stem().string() + ".lm.txt")).string();
}

std::string absolute_path(const std::string& p) {
  std::error_code ec;
  return fs::weakly_canonical(fs::absolute(p, ec), ec).string();
}

// A mesh param accepts (the one verdict, check_mesh.h); errors name the file.
Result<TriMesh> read_accepted_mesh(const std::string& path) {
  auto mesh = formats::read_mesh(path);
  if (!mesh.ok()) return with_file(mesh.status(), path);
  SPHEREKIT_RETURN_IF_ERROR(with_file(require_param_accepts(mesh.value(), check_mesh(mesh.value())), path));
  return mesh;
}

// The members: the given meshes with their feature files, or the built-in samples.
Status read_members(const MakeCollectionJob& a, MakeCollectionResult& out) {
  std::vector<CollectionInput>& members = out.members;
  std::vector<std::string>& names = out.feature_names;  // in the first member's order
  if (a.meshes.empty()) {
    SPHEREKIT_ASSIGN_OR_RETURN(auto samples, samples::make_sample_collection());
    for (const auto& s : samples) {
      CollectionInput m;
      m.name = s.name;
      m.source = "builtin:" + s.name;
      m.features_file = "builtin";
      m.mesh = s.mesh;
      if (names.empty())
        for (const Landmark& l : s.landmarks) names.push_back(l.name);
      for (const Landmark& l : s.landmarks) m.feature_vertices.push_back(l.vertex);
      members.push_back(std::move(m));
    }
    return Status();
  }
  std::set<std::string> stems;
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    const std::string& path = a.meshes[i];
    CollectionInput m;
    m.name = fs::path(path).stem().string();
    if (!stems.insert(m.name).second)
      return Status(ErrorCode::InvalidArgument,
                    path + ": another input has the same file name stem '" + m.name + "' (sphere maps are named after it)");
    SPHEREKIT_ASSIGN_OR_RETURN(m.mesh, read_accepted_mesh(path));
    m.source = absolute_path(path);
    m.features_file = a.features.empty() ? default_features_path(path) : a.features[i];
    const int nv = static_cast<int>(m.mesh.V.rows());
    if (names.empty()) {
      auto lms = formats::read_landmarks(m.features_file, nv);
      if (!lms.ok()) return with_file(lms.status(), m.features_file);
      if (lms->empty()) return Status(ErrorCode::InvalidInput, m.features_file + ": no features");
      for (const Landmark& l : lms.value()) names.push_back(l.name);
    }
    SPHEREKIT_ASSIGN_OR_RETURN(m.feature_vertices, features_in_order(m.features_file, nv, names));
    // Extra features of later members would be silently ignored: refuse them instead.
    auto all = formats::read_landmarks(m.features_file, nv);
    if (all.ok() && all->size() != names.size())
      return Status(ErrorCode::InvalidInput,
                    format_text("%s: has %zu features, %s has %zu (feature files must name the same features)",
                                m.features_file.c_str(), all->size(),
                                members.empty() ? "it" : members[0].features_file.c_str(), names.size()));
    members.push_back(std::move(m));
  }
  return Status();
}

// A map computed elsewhere (e.g. `param --features --targets DIR/features.txt` in a job) is
// accepted only as add would have produced it: the mesh's vertices and faces, a bijection by
// the exact predicate, every feature vertex on its location F_k (within require_exact's bound).
Result<Json> verify_registered_map(const std::string& map_path, const TriMesh& mesh, const std::vector<int>& fv,
                                   const std::vector<Eigen::Vector3d>& F, ConstrainedParamResult& out,
                                   std::string& bytes) {
  auto map = formats::read_sphere_map(map_path, mesh);
  if (!map.ok()) return with_file(map.status(), map_path);
  if (const int flipped = count_flipped_faces(mesh.F, map->S); flipped != 0)
    return Status(ErrorCode::InvalidInput,
                  format_text("%s: %d flipped or degenerate faces on the sphere (not a bijection)", map_path.c_str(), flipped));
  double worst = 0;
  for (size_t k = 0; k < fv.size(); ++k) {
    const Eigen::Vector3d p = map->S.row(fv[k]).transpose();
    worst = std::max(worst, std::atan2(p.cross(F[k]).norm(), p.dot(F[k])));
  }
  if (!(worst < 1e-9))
    return Status(ErrorCode::InvalidInput,
                  format_text("%s: a feature vertex is %.3g rad off the collection's location (a map to other locations?)",
                              map_path.c_str(), worst));
  SPHEREKIT_ASSIGN_OR_RETURN(SphereMapMetrics m, evaluate_sphere_map(mesh, map->S));
  SPHEREKIT_ASSIGN_OR_RETURN(bytes, formats::read_file(map_path));
  out = ConstrainedParamResult{};
  out.map = map.value();
  out.efficiency = m.efficiency;
  out.l2_stretch = m.l2_stretch;
  out.linf_stretch = m.linf;
  out.winding = m.winding;
  out.max_feature_angle = worst;
  Json j;
  j["efficiency"] = m.efficiency;
  j["l2_stretch"] = m.l2_stretch;
  j["linf_stretch"] = m.linf;
  j["flipped_faces"] = 0;
  j["winding"] = m.winding;
  j["max_feature_angle"] = worst;
  j["method"] = map->provenance.method;
  j["registered_from"] = absolute_path(map_path);
  return j;
}

// What the correspondence refinement did to one member (refine_correspondence.h); no time,
// so that the manifest's bytes do not depend on the machine.
Json refinement_json(const RefinedMember& m) {
  Json j{{"refined", m.refined}};
  if (!m.note.empty()) j["note"] = m.note;
  if (m.note == "template") return j;
  j["rounds"] = m.rounds;
  j["samples"] = m.samples;
  j["energy_before"] = m.energy_before;
  j["energy_after"] = m.energy_after;
  j["crushed_faces"] = m.crushed_faces;
  j["folded_samples_left_out"] = m.folded_samples_left_out;
  j["flow_relaxations"] = m.flow_relaxations;
  j["snap_moves"] = m.snap_moves;
  j["efficiency_before"] = m.efficiency_before;
  j["efficiency_after"] = m.efficiency_after;
  return j;
}

// `add` in a collection made with the correspondence refinement: the new member's map is
// refined against the reference member, as `consistent` refined every member (one
// template, so an added member agrees with the others as theirs do). Reads the reference's
// mesh and map (O(1) reads per add). No refinement (nullopt): the collection was made
// without it, or has no reference member (other than the one being replaced).
Result<std::optional<RefinedMember>> refine_added_member(const formats::Collection& c, int replacing, const TriMesh& mesh,
                                                         const std::vector<int>& fv, const std::vector<Eigen::Vector3d>& F,
                                                         const ProgressFn& progress, double own_efficiency,
                                                         ConstrainedParamResult* map) {
  const Json& opt = c.manifest.options;
  if (!opt.is_object() || !opt.value("refine_correspondence", false) || !c.manifest.reference)
    return std::optional<RefinedMember>{};
  const int ref = c.manifest.member_index(*c.manifest.reference);
  if (ref < 0 || ref == replacing || !c.manifest.members[static_cast<size_t>(ref)].feature_vertices)
    return std::optional<RefinedMember>{};
  SPHEREKIT_ASSIGN_OR_RETURN(formats::LoadedMember rm, formats::load_collection_member(c, ref));
  std::vector<int> rf;
  for (long long v : *c.manifest.members[static_cast<size_t>(ref)].feature_vertices) rf.push_back(static_cast<int>(v));
  RefineCorrespondenceOptions ro;
  if (opt.contains("refinement") && opt["refinement"].is_object()) {
    const Json& r = opt["refinement"];
    ro.iterations = r.value("iterations", ro.iterations);
    ro.damping = r.value("damping", ro.damping);
    ro.rounds = r.value("rounds", ro.rounds);
    ro.samples = r.value("samples", ro.samples);
    // Collections written before the stretch polish have no entry: their members were
    // refined without it, and an added member is refined as they were.
    ro.stretch_passes = r.value("stretch_passes", 0);
    // Likewise for the growing sample counts: before them every round took `samples`.
    ro.sample_growth = r.value("sample_growth", 1);
    // And for the snap toward the fitted partners.
    ro.snap_sweeps = r.value("snap_sweeps", 0);
    ro.max_samples = r.value("max_samples", ro.max_samples);
    ro.vertices_per_sample = r.value("vertices_per_sample", ro.vertices_per_sample);
  }
  ro.template_mesh = 0;
  ro.threads = 1;
  ro.own_efficiency = {0.0, own_efficiency};
  std::vector<TriMesh> meshes{std::move(rm.mesh), mesh};
  std::vector<std::vector<int>> features{rf, fv};
  std::vector<RowMat3d> maps{std::move(rm.map.S), map->map.S};
  SPHEREKIT_ASSIGN_OR_RETURN(RefineCorrespondenceResult rr, refine_correspondence(meshes, features, maps, ro, progress));
  if (rr.members[1].refined) SPHEREKIT_RETURN_IF_ERROR(replace_refined_map(mesh, fv, F, std::move(maps[1]), map));
  return std::optional<RefinedMember>(rr.members[1]);
}

// A failed map whose landmarks were found suspect says so in its one error line: a landmark on
// another feature forces a twisted map, which fails as a solver error that names no landmark
// (sample_c with its nose and tail tips swapped: "the stretch optimization did not converge").
Status with_landmark_hint(const Status& s, const std::vector<std::string>& suspects, const std::string& lm_file) {
  if (suspects.empty() || s.code() == ErrorCode::Cancelled) return s;
  std::string names;
  for (const std::string& n : suspects) names += (names.empty() ? "'" : ", '") + n + "'";
  return Status(s.code(), s.message() + " (most likely misplaced in " + lm_file + ": " + names + ")");
}

// The added mesh's landmarks checked against the reference member's (suspect_landmarks), as
// make_collection checks given files. The reference's mesh is read from its source; where it
// cannot be (moved, or the reference is the member being replaced) nothing is said.
std::vector<std::string> added_landmark_warnings(const formats::Collection& c, int replacing, const TriMesh& mesh,
                                                 const std::vector<int>& fv, const std::string& lm_file,
                                                 std::vector<std::string>* suspect_names) {
  std::vector<std::string> out;
  if (!c.manifest.reference) return out;
  const int ref = c.manifest.member_index(*c.manifest.reference);
  if (ref < 0 || ref == replacing) return out;
  const formats::CollectionMember& rm = c.manifest.members[static_cast<size_t>(ref)];
  if (!rm.feature_vertices || !rm.source) return out;
  auto ref_mesh = read_accepted_mesh(*rm.source);
  if (!ref_mesh.ok()) return out;
  std::vector<int> rf;
  for (long long v : *rm.feature_vertices) rf.push_back(static_cast<int>(v));
  auto suspects = suspect_landmarks(std::vector<TriMesh>{*ref_mesh, mesh}, std::vector<std::vector<int>>{rf, fv}, 0);
  if (!suspects.ok()) return out;
  const std::vector<std::string> names = c.manifest.feature_names();
  for (const SuspectLandmark& x : *suspects) {
    suspect_names->push_back(names[static_cast<size_t>(x.landmark)]);
    out.push_back(format_text("%s: landmark '%s' is not where %s's is: its distances to the others differ by a factor %.2f "
                              "(the other landmarks: %.2f); misplaced, or on another feature?",
                              lm_file.c_str(), names[static_cast<size_t>(x.landmark)].c_str(), rm.name.c_str(),
                              std::exp(x.disagreement), std::exp(x.typical)));
  }
  return out;
}

formats::CollectionManifest manifest_of(const MakeCollectionResult& out, const ConsistentParamOptions& o,
                                        const std::string& refinement_failure) {
  const ConsistentParamResult& r = out.maps;
  formats::CollectionManifest man;
  man.library_version = kVersion;
  man.method = o.refine_locations ? "consistent (steps 1-6)" : "consistent (steps 1-2: reference locations)";
  man.reference = out.members[static_cast<size_t>(out.reference)].name;
  for (size_t k = 0; k < out.feature_names.size(); ++k)
    man.features.push_back({out.feature_names[k], r.final_locations[k], r.initial_locations[k]});
  for (size_t i = 0; i < out.members.size(); ++i) {
    const CollectionInput& m = out.members[i];
    formats::CollectionMember e;
    e.name = m.name;
    e.source = m.source;
    e.features_file = m.features_file == "builtin" ? m.features_file : absolute_path(m.features_file);
    e.map = m.name + ".sphere.obj";
    e.vertices = m.mesh.V.rows();
    e.faces = m.mesh.F.rows();
    e.feature_vertices = std::vector<long long>(m.feature_vertices.begin(), m.feature_vertices.end());
    e.added = false;
    e.result = map_entry_json(r.maps[i]);
    if (i < r.unconstrained_efficiency.size() && r.unconstrained_efficiency[i] > 0)
      e.result["unconstrained_efficiency"] = r.unconstrained_efficiency[i];
    if (i < r.refinement.members.size()) e.result["correspondence_refinement"] = refinement_json(r.refinement.members[i]);
    man.members.push_back(std::move(e));
  }
  man.options = constrained_options_json(o.constrained);
  man.options["remesh_size"] = o.remesh_size;
  man.options["refine_locations"] = o.refine_locations;
  man.options["refine_correspondence"] = o.refine_correspondence;
  man.options["efficiency_retry"] = o.efficiency_retry;
  if (o.refine_correspondence)
    man.options["refinement"] = Json{{"iterations", o.refinement.iterations},
                                     {"damping", o.refinement.damping},
                                     {"rounds", o.refinement.rounds},
                                     {"samples", o.refinement.samples},
                                     {"stretch_passes", o.refinement.stretch_passes},
                                     {"snap_sweeps", o.refinement.snap_sweeps},
                                     {"sample_growth", o.refinement.sample_growth},
                                     {"max_samples", o.refinement.max_samples},
                                     {"vertices_per_sample", o.refinement.vertices_per_sample}};
  if (!refinement_failure.empty()) {
    man.method = "consistent (steps 1-2: reference locations; step 6 failed)";
    man.extra["refinement_failure"] = refinement_failure;
    Json rejected = Json::array();
    for (const auto& p : r.rejected_locations) rejected.push_back(Json::array({p.x(), p.y(), p.z()}));
    man.extra["rejected_locations"] = rejected;
  }
  man.extra["steps"] = Json{{"reference_efficiency", r.reference_efficiency},
                            {"joint_efficiency", r.joint_efficiency},
                            {"joint_flipped_faces", r.joint_flips},
                            {"remesh_vertices", r.remesh_vertices}};
  // No times and no thread count (effort only): the same inputs give the same manifest bytes
  // on any machine and in any job order (issue 23); consistent_times_json() has the times.
  man.options.erase("threads");
  sort_members(man);
  return man;
}

}  // namespace

Json map_entry_json(const ConstrainedParamResult& r) {
  Json j = constrained_measures_json(r);
  j["method"] = r.map.provenance.method;
  j["network"] = feature_network_json(r.network);
  if (r.efficiency_retried)  // constrained_param_or_retry: made twice, the more efficient kept
    j["efficiency_retry"] = Json{{"first_efficiency", r.first_efficiency}, {"as_unconstrained", r.as_unconstrained}};
  return j;
}

Json map_times_json(const ConstrainedParamResult& r) {
  return Json{{"network", r.times.network}, {"simplify", r.times.simplify}, {"refine", r.times.refine},
              {"total", r.times.total}};
}

Json consistent_times_json(const MakeCollectionResult& out) {
  const ConsistentParamResult& r = out.maps;
  Json t{{"step1_reference", r.times.reference}, {"step2_initial_maps", r.times.initial},
         {"step3_remesh", r.times.remesh},       {"step4_concatenate", r.times.concatenate},
         {"step5_joint_map", r.times.joint},     {"step6_final_maps", r.times.final_maps},
         {"refine_correspondence", r.times.refinement}, {"total", r.times.total}};
  for (size_t i = 0; i < out.members.size() && i < r.maps.size(); ++i) t["members"][out.members[i].name] = map_times_json(r.maps[i]);
  return t;
}

Result<MakeCollectionResult> make_collection(const MakeCollectionJob& a, const ProgressFn& progress,
                                             const formats::KeepGoingFn& keep_going) {
  Stopwatch wall;
  SPHEREKIT_RETURN_IF_ERROR(formats::require_staged_folder_target(a.output, formats::kCollectionManifest));
  if (!a.features.empty() && a.features.size() != a.meshes.size())
    return Status(ErrorCode::InvalidArgument,
                  format_text("%zu meshes but %zu --features files (give one per mesh, in order, or none)",
                              a.meshes.size(), a.features.size()));
  MakeCollectionResult out;
  SPHEREKIT_RETURN_IF_ERROR(read_members(a, out));
  if (!a.reference.empty()) {
    out.reference = -1;
    for (size_t i = 0; i < out.members.size(); ++i)
      if (out.members[i].name == a.reference || a.reference == std::to_string(i)) out.reference = static_cast<int>(i);
    if (out.reference < 0)
      return Status(ErrorCode::InvalidArgument, "--reference '" + a.reference + "' is neither a mesh's file stem nor an index");
  }
  ConsistentParamOptions o = a.options;
  o.reference = out.reference;
  std::vector<TriMesh> meshes;
  std::vector<std::vector<int>> features;
  for (const CollectionInput& m : out.members) {
    meshes.push_back(m.mesh);
    features.push_back(m.feature_vertices);
  }
  // Given landmark files are taken as they are, but a landmark on another feature on some
  // member (a wrong index, two names swapped in one file) twists that member's map without any
  // error: it is reported (the rule that leaves such an extremity out of a proposal).
  // A member's landmarks by their file (the built-in samples' by the member's name).
  auto m_label = [](const CollectionInput& m) { return m.features_file == "builtin" ? m.name : m.features_file; };
  std::vector<std::vector<std::string>> suspect_names(out.members.size());
  if (auto suspects = suspect_landmarks(meshes, features, out.reference); suspects.ok())
    for (const SuspectLandmark& x : *suspects) {
      suspect_names[static_cast<size_t>(x.member)].push_back(out.feature_names[static_cast<size_t>(x.landmark)]);
      out.landmark_warnings.push_back(format_text(
          "%s: landmark '%s' is not where %s's is: its distances to the others differ by a factor %.2f "
          "(the other landmarks: %.2f); misplaced, or on another feature?",
          m_label(out.members[static_cast<size_t>(x.member)]).c_str(),
          out.feature_names[static_cast<size_t>(x.landmark)].c_str(),
          out.members[static_cast<size_t>(out.reference)].name.c_str(), std::exp(x.disagreement), std::exp(x.typical)));
    }
  MeshFailure failure;
  auto result = parameterize_consistent(meshes, features, o, progress, &failure);
  if (!result.ok()) {
    // The mesh by its file, not by its index.
    if (failure.mesh < 0) return result.status();
    const CollectionInput& m = out.members[static_cast<size_t>(failure.mesh)];
    return with_file(with_landmark_hint(failure.reason, suspect_names[static_cast<size_t>(failure.mesh)], m.features_file),
                     m.source);
  }
  out.maps = std::move(result).value();
  const ConsistentParamResult& r = out.maps;
  for (size_t i = 0; i < out.members.size(); ++i)
    if (Status s = require_exact(r.maps[i], out.members[i].source);
        !s.ok() && !(static_cast<int>(i) == out.reference && !o.refine_locations))
      return s;
  if (!r.refinement_failure.empty())
    out.refinement_warning = r.refinement_failure_mesh < 0 ? r.refinement_failure
                                                           : out.members[static_cast<size_t>(r.refinement_failure_mesh)].name +
                                                                 ": " + r.refinement_failure_reason;
  out.manifest = manifest_of(out, o, out.refinement_warning);
  SPHEREKIT_RETURN_IF_ERROR(formats::write_staged_folder(
      a.output, formats::kCollectionManifest,
      [&](const std::string& dir) -> Status {
        for (size_t i = 0; i < out.members.size(); ++i)
          SPHEREKIT_RETURN_IF_ERROR(formats::write_sphere_map(
              (fs::path(dir) / (out.members[i].name + ".sphere.obj")).string(), out.members[i].mesh, r.maps[i].map));
        SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic((fs::path(dir) / formats::kCollectionFeatures).string(),
                                                             formats::sphere_points_text(out.feature_names, r.final_locations)));
        return formats::write_file_atomic((fs::path(dir) / formats::kCollectionManifest).string(),
                                          formats::collection_manifest_text(out.manifest));
      },
      keep_going));
  out.wall_seconds = wall.seconds();
  return out;
}

Result<AddToCollectionResult> add_to_collection(const AddToCollectionJob& a, const ProgressFn& progress) {
  Stopwatch wall;
  SPHEREKIT_ASSIGN_OR_RETURN(formats::Collection c, formats::read_collection(a.dir));
  SPHEREKIT_ASSIGN_OR_RETURN(TriMesh mesh, read_accepted_mesh(a.mesh));
  AddToCollectionResult out;
  out.name = a.name.empty() ? fs::path(a.mesh).stem().string() : a.name;
  const std::string& name = out.name;
  // The map is written as DIR/<name>.sphere.obj: a name with a path would put it elsewhere
  // (and make the manifest unreadable, see read_collection).
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos)
    return Status(ErrorCode::InvalidArgument, "--name '" + name + "': must be a plain file name");
  const int existing = c.manifest.member_index(name);
  if (existing >= 0 && !a.replace)
    return Status(ErrorCode::InvalidArgument, a.mesh + ": the collection already has a mesh named '" + name +
                                                  "' (use --name, or --replace to map it again)");
  // Never grow a broken collection: every other member's map must be there. (Only there: add
  // reads the manifest and F, no other member's map, so that growing a collection of n members
  // costs O(1) reads per add, not O(n).)
  SPHEREKIT_RETURN_IF_ERROR(check_member_maps_present(c, existing));
  const std::string lm = a.features.empty() ? default_features_path(a.mesh) : a.features;
  const int nv = static_cast<int>(mesh.V.rows());
  SPHEREKIT_ASSIGN_OR_RETURN(std::vector<int> fv, features_in_order(lm, nv, c.manifest.feature_names()));
  const std::vector<Eigen::Vector3d> F = c.manifest.locations();
  std::vector<std::string> suspect_names;
  out.landmark_warnings = added_landmark_warnings(c, existing, mesh, fv, lm, &suspect_names);

  formats::CollectionMember e;
  e.name = name;
  e.source = absolute_path(a.mesh);
  e.features_file = absolute_path(lm);
  e.map = name + ".sphere.obj";
  e.vertices = nv;
  e.faces = mesh.F.rows();
  e.feature_vertices = std::vector<long long>(fv.begin(), fv.end());
  e.added = true;
  MemberUpdate u;
  u.replace = a.replace;
  u.feature_names = c.manifest.feature_names();
  u.locations = F;
  std::string registered_bytes;
  if (!a.map.empty()) {
    SPHEREKIT_ASSIGN_OR_RETURN(e.result, verify_registered_map(a.map, mesh, fv, F, out.map, registered_bytes));
    out.registered = true;
    u.write_map = [&](const std::string& path) { return formats::write_file_atomic(path, registered_bytes); };
  } else {
    ConstrainedParamOptions o = a.options;
    // The collection's shape-defining settings, unless given here.
    const Json& opt = c.manifest.options;
    if (opt.is_object() && opt.contains("seed") && opt["seed"].is_number_unsigned() && !a.seed_given)
      o.sphere.seed = opt["seed"].get<std::uint64_t>();
    double retry = a.efficiency_retry;
    if (opt.is_object() && opt.contains("efficiency_retry") && opt["efficiency_retry"].is_number() &&
        !a.efficiency_retry_given)
      retry = opt["efficiency_retry"].get<double>();
    double unconstrained = 0;
    if (retry > 0 && !o.as_unconstrained) {
      // The new mesh's own unconstrained map, what the retry compares against (as in steps 2 and 6).
      auto u = own_unconstrained_efficiency(mesh, o, progress);
      if (!u.ok()) return with_file(u.status(), a.mesh);
      unconstrained = *u;
    }
    auto result = constrained_param_or_retry(mesh, fv, F, o, unconstrained, retry, progress);
    if (!result.ok()) return with_file(with_landmark_hint(result.status(), suspect_names, lm), a.mesh);
    out.map = std::move(result).value();
    SPHEREKIT_RETURN_IF_ERROR(require_exact(out.map, a.mesh));
    std::optional<RefinedMember> refined;
    if (a.refine_correspondence) {
      SPHEREKIT_ASSIGN_OR_RETURN(refined, refine_added_member(c, existing, mesh, fv, F, progress, unconstrained, &out.map));
    }
    // The entry once, of the map as kept (refined or not), in the order consistent writes it.
    e.result = map_entry_json(out.map);
    if (unconstrained > 0) e.result["unconstrained_efficiency"] = unconstrained;
    if (refined) e.result["correspondence_refinement"] = refinement_json(*refined);
    u.write_map = [&](const std::string& path) { return formats::write_sphere_map(path, mesh, out.map.map); };
  }
  u.member = std::move(e);
  out.map_path = (fs::path(a.dir) / (name + ".sphere.obj")).string();
  // The read-modify-write of the manifest, under the folder's lock (collection_update.h).
  auto committed = commit_member(a.dir, u);
  if (!committed.ok()) {
    const Status& s = committed.status();
    if (s.code() == ErrorCode::InvalidArgument)  // the name was taken meanwhile: name the mesh, as above
      return Status(s.code(), a.mesh + ": " + s.message().substr(s.message().find(": ") + 2));
    return s;
  }
  out.manifest = std::move(committed).value();
  out.vertices = nv;
  out.features = c.manifest.features.size();
  out.wall_seconds = wall.seconds();
  return out;
}

}  // namespace spherekit::pipeline
