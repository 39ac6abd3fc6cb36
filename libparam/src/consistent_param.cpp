// Consistent parameterization of a collection (Asirvatham, Praun, Hoppe 2005 §3, Fig. 2):
// the six steps, with the constrained maps of steps 2 and 6 run for several meshes at once.
#include "spherekit/consistent_param.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/SparseCholesky>
#include <set>

#include "detail/collapsed_map.h"
#include "detail/parallel_jobs.h"
#include "detail/rotation.h"
#include "detail/sphere_embedding.h"
#include "detail/stage_util.h"
#include "spherekit/fill_holes.h"
#include "spherekit/format_text.h"
#include "spherekit/geometry_image.h"
#include "spherekit/metrics.h"
#include "spherekit/progressive_mesh.h"
#include "spherekit/sphere_param.h"

namespace spherekit {
namespace {

using detail::seconds_since;

std::string mesh_label(int i) { return "mesh " + std::to_string(i); }

// Step 6 "collapsed" for a mesh whose map to F keeps less than this fraction of its step-2
// map's stretch efficiency (detail/collapsed_map.h: normal maps keep 0.96-1.01x, a reference
// 0.80 in the non-isometric pair bunny + gargoyle).
constexpr double kStepSixCollapse = 0.7;
// Step 6 "wound" for a mesh whose network to F has a path more than kStepSixWinding times its
// shortest route, and kStepSixWindingGrowth times its step-2 network's longest (normal
// networks: at most 1.25x; detail/collapsed_map.h).
constexpr double kStepSixWinding = 2.0;
constexpr double kStepSixWindingGrowth = 1.5;

// Forwards a callee's progress with the step named in front ("step 5: refine").
ProgressFn prefixed(const ProgressFn& progress, const std::string& step) {
  if (!progress) return {};
  return [progress, step](const ProgressEvent& e) {
    const std::string stage = step + ": " + std::string(e.stage);
    return progress(ProgressEvent{stage, e.level, e.fraction});
  };
}

// The reference's unconstrained map in the shape of a constrained result, so that every
// mesh of the collection has one kind of entry.
ConstrainedParamResult as_constrained(const SphereParamResult& r) {
  ConstrainedParamResult c;
  c.map = r.map;
  c.flipped_faces = r.flipped_faces;
  c.efficiency = r.efficiency;
  c.l2_stretch = r.l2_stretch;
  c.linf_stretch = r.linf_stretch;
  c.winding = r.winding;
  c.holes_filled = r.holes_filled;
  c.times.check = r.times.check;
  c.times.simplify = r.times.simplify;
  c.times.refine = r.times.refine;
  c.times.total = r.times.total;
  return c;
}

// Constrained maps of the meshes `which` to `targets`, several at once (steps 2 and 6), each
// made again where it keeps too little of its mesh's unconstrained efficiency
// (constrained_param_or_retry); a mesh's unconstrained efficiency is computed where it is
// still 0 in `unconstrained_efficiency` (step 2) and reused after (step 6).
Status constrained_maps(const std::vector<TriMesh>& meshes, const std::vector<std::vector<int>>& features,
                        const std::vector<int>& which, const std::vector<Eigen::Vector3d>& targets,
                        const ConsistentParamOptions& options, const std::string& stage, const ProgressFn& progress,
                        std::vector<ConstrainedParamResult>* out, std::vector<double>* unconstrained_efficiency,
                        MeshFailure* failure) {
  // Each job's own error, so that the failing mesh is known as a value: run_parallel_jobs
  // returns the lowest-numbered job's real failure.
  std::vector<Status> reasons(which.size());
  const Status s = detail::run_parallel_jobs(
      static_cast<int>(which.size()), options.threads, stage, progress,
      [&](int j, int threads, const std::function<bool()>& keep_going) -> Status {
        const int i = which[static_cast<size_t>(j)];
        ConstrainedParamOptions o = options.constrained;
        o.sphere.threads = threads;  // effort only: same bits for any count
        const ProgressFn cancel = [&](const ProgressEvent&) { return keep_going(); };
        double& unconstrained = (*unconstrained_efficiency)[static_cast<size_t>(i)];
        if (options.efficiency_retry > 0 && unconstrained == 0) {
          // The mesh's own unconstrained map, once (step 2), with step 1's settings.
          auto u = own_unconstrained_efficiency(meshes[static_cast<size_t>(i)], o, cancel);
          if (!u.ok()) {
            reasons[static_cast<size_t>(j)] = u.status();
            return u.status().with_context(mesh_label(i));
          }
          unconstrained = *u;
        }
        auto r = constrained_param_or_retry(meshes[static_cast<size_t>(i)], features[static_cast<size_t>(i)], targets,
                                            o, unconstrained, options.efficiency_retry, cancel);
        if (!r.ok()) reasons[static_cast<size_t>(j)] = r.status();
        else if (r->flipped_faces != 0)  // never expected: the stage checks; a guard for the collection
          reasons[static_cast<size_t>(j)] = Status(ErrorCode::Internal, "constrained map has flipped faces");
        if (!reasons[static_cast<size_t>(j)].ok()) return reasons[static_cast<size_t>(j)].with_context(mesh_label(i));
        (*out)[static_cast<size_t>(i)] = std::move(r).value();
        return Status();
      });
  if (!s.ok() && s.code() != ErrorCode::Cancelled)
    for (size_t j = 0; j < which.size(); ++j)
      if (!reasons[j].ok() && reasons[j].code() != ErrorCode::Cancelled) {
        *failure = {which[j], reasons[j]};
        break;
      }
  return s;
}

// Replaces the positions of the `hole` vertices by the harmonic interpolation (uniform
// graph Laplacian) of the others: the smoothest membrane over each hole.
void span_holes_harmonically(TriMesh& mesh, const std::vector<char>& hole) {
  const int nv = static_cast<int>(mesh.V.rows());
  std::vector<int> unknown(static_cast<size_t>(nv), -1);
  int nu = 0;
  for (int v = 0; v < nv; ++v)
    if (hole[static_cast<size_t>(v)]) unknown[static_cast<size_t>(v)] = nu++;
  if (nu == 0 || nu == nv) return;
  std::vector<std::set<int>> nbr(static_cast<size_t>(nv));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = mesh.F(f, c), b = mesh.F(f, (c + 1) % 3);
      nbr[static_cast<size_t>(a)].insert(b);
      nbr[static_cast<size_t>(b)].insert(a);
    }
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nu, 3);
  for (int v = 0; v < nv; ++v) {
    const int r = unknown[static_cast<size_t>(v)];
    if (r < 0) continue;
    trip.emplace_back(r, r, static_cast<double>(nbr[static_cast<size_t>(v)].size()));
    for (int u : nbr[static_cast<size_t>(v)]) {
      if (const int c = unknown[static_cast<size_t>(u)]; c >= 0)
        trip.emplace_back(r, c, -1.0);
      else
        rhs.row(r) += mesh.V.row(u);
    }
  }
  Eigen::SparseMatrix<double> L(nu, nu);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(L);
  if (solver.info() != Eigen::Success) return;  // keep the rim positions (still valid input)
  const Eigen::MatrixXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return;
  for (int v = 0; v < nv; ++v)
    if (const int r = unknown[static_cast<size_t>(v)]; r >= 0) mesh.V.row(v) = x.row(r);
}

// Step 3: mesh i remeshed on the N x N octahedral grid through its map S, positions
// normalized to the mesh's unit bounding-box diagonal (so that every model weighs alike in
// the joint quadric and stretch). The grid vertex nearest each F' point becomes the
// feature: it takes the feature vertex's exact position (§3: "we snap the closest grid
// samples to the spherical locations F'"). Returns the welded vertex positions.
Result<RowMat3d> remesh_on_grid(const TriMesh& mesh, const RowMat3d& S, const std::vector<int>& feature_vertices,
                                const std::vector<int>& feature_texels, int n, int threads) {
  const detail::Normalization nz = detail::bounding_box_normalization(mesh.V);
  if (!(nz.diagonal > 0)) return Status(ErrorCode::InvalidInput, "mesh has zero extent");
  TriMesh unit;
  unit.V = (mesh.V.rowwise() - nz.centre) / nz.diagonal;
  unit.F = mesh.F;
  GeometryImageOptions gio;
  gio.threads = threads;
  SPHEREKIT_ASSIGN_OR_RETURN(GeometryImage image, sample_geometry_image(unit, S, n, gio));
  TriMesh grid = geometry_image_mesh(image);
  // Texels in holes hold the nearest boundary point: the hole region collapses onto the
  // rim, and such zero-area regions would drive the summed stretch of step 5 to crush the
  // other models there. A membrane spans the hole instead (as fill_holes does for the
  // unconstrained stage).
  if (image.texels_in_holes > 0) {
    int count = 0;
    const std::vector<int> id = geometry_image_welded_ids(n, &count);
    std::vector<char> hole(static_cast<size_t>(count), 0);
    for (size_t t = 0; t < id.size(); ++t)
      if (image.in_hole[t]) hole[static_cast<size_t>(id[t])] = 1;
    span_holes_harmonically(grid, hole);
  }
  // Sample positions are floats; the snapped features get the exact double position.
  for (size_t k = 0; k < feature_texels.size(); ++k)
    grid.V.row(feature_texels[k]) = unit.V.row(feature_vertices[k]);
  return RowMat3d(grid.V);
}

// The welded grid vertex nearest to each location (distinct vertices: a feature whose
// nearest vertex is taken gets the nearest free one).
std::vector<int> snap_texels(const std::vector<Eigen::Vector3d>& locations, int n) {
  int count = 0;
  const std::vector<int> id = geometry_image_welded_ids(n, &count);
  std::vector<Eigen::Vector3d> point(static_cast<size_t>(count));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d uv = texel_to_octahedral(i, j, n);
      point[static_cast<size_t>(id[static_cast<size_t>(i) * n + j])] = octahedral_to_sphere(uv.x(), uv.y());
    }
  std::vector<char> taken(static_cast<size_t>(count), 0);
  std::vector<int> texel;
  for (const Eigen::Vector3d& p : locations) {
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (int v = 0; v < count; ++v) {
      if (taken[static_cast<size_t>(v)]) continue;
      const double d = (point[static_cast<size_t>(v)] - p).squaredNorm();
      if (d < best_d) best_d = d, best = v;  // strict: the lowest id wins ties (deterministic)
    }
    taken[static_cast<size_t>(best)] = 1;
    texel.push_back(best);
  }
  return texel;
}

}  // namespace

Status replace_refined_map(const TriMesh& mesh, const std::vector<int>& feature_vertices,
                           const std::vector<Eigen::Vector3d>& locations, RowMat3d S, ConstrainedParamResult* map) {
  if (locations.size() != feature_vertices.size())
    return Status(ErrorCode::InvalidArgument, "need one location per feature vertex");
  // Measured as the constrained stage measures (constrained_param.cpp): on the mesh with its
  // holes closed by fans and normalized, stretch over the input's own faces only. On the open
  // mesh the winding is undefined (evaluate_sphere_map reports 0), and a refined member with
  // holes was reported with winding 0 beside its step-6 map's +1. Each fan's centre goes to
  // the normalized mean of its loop's sphere points: inside the hole's small region, so the
  // closed map's signed area is 4 pi times its degree.
  SPHEREKIT_ASSIGN_OR_RETURN(const FilledMesh filled, fill_holes(mesh));
  const detail::Normalization nz = detail::bounding_box_normalization(filled.mesh.V);
  if (!(nz.diagonal > 0)) return Status(ErrorCode::InvalidInput, "mesh has zero extent");
  TriMesh unit;
  unit.V = (filled.mesh.V.rowwise() - nz.centre) / nz.diagonal;
  unit.F = filled.mesh.F;
  RowMat3d S_closed(filled.mesh.V.rows(), 3);
  S_closed.topRows(S.rows()) = S;
  for (size_t h = 0; h < filled.loops.size(); ++h) {
    Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
    for (int v : filled.loops[h]) c += S.row(v);
    S_closed.row(filled.original_vertices + static_cast<Eigen::Index>(h)) = c.normalized();
  }
  std::vector<char> real(static_cast<size_t>(filled.mesh.F.rows()), 0);
  for (int f = 0; f < filled.original_faces; ++f) real[static_cast<size_t>(f)] = 1;
  SPHEREKIT_ASSIGN_OR_RETURN(const SphereMapMetrics mm, evaluate_sphere_map(unit, S_closed, {}, &real));
  map->map.S = std::move(S);
  map->flipped_faces = count_flipped_faces(mesh.F, map->map.S);
  map->efficiency = mm.efficiency;
  map->l2_stretch = mm.l2_stretch;
  map->linf_stretch = mm.linf;
  map->winding = mm.winding;
  map->max_feature_angle = 0;
  for (size_t f = 0; f < feature_vertices.size(); ++f) {
    const Eigen::Vector3d s = map->map.S.row(feature_vertices[f]).transpose();
    map->max_feature_angle = std::max(map->max_feature_angle, std::atan2(s.cross(locations[f]).norm(), s.dot(locations[f])));
  }
  return Status();
}

namespace {

// The correspondence refinement after the last step (refine_correspondence.h), the measures
// of every refined map recomputed.
Status refine_maps(const std::vector<TriMesh>& meshes, const std::vector<std::vector<int>>& features,
                   const ConsistentParamOptions& options, const ProgressFn& progress, ConsistentParamResult* result) {
  const int n = static_cast<int>(meshes.size());
  if (!options.refine_correspondence || n < 2) return Status();
  const auto t0 = std::chrono::steady_clock::now();
  RefineCorrespondenceOptions ro = options.refinement;
  ro.template_mesh = options.reference;
  ro.threads = options.threads;
  ro.own_efficiency = result->unconstrained_efficiency;  // 0 where not measured (no efficiency retry)
  std::vector<RowMat3d> S(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) S[static_cast<size_t>(i)] = result->maps[static_cast<size_t>(i)].map.S;
  SPHEREKIT_ASSIGN_OR_RETURN(result->refinement, refine_correspondence(meshes, features, S, ro, progress));
  for (int i = 0; i < n; ++i)
    if (result->refinement.members[static_cast<size_t>(i)].refined)
      SPHEREKIT_RETURN_IF_ERROR(replace_refined_map(meshes[static_cast<size_t>(i)], features[static_cast<size_t>(i)],
                                                    result->final_locations, std::move(S[static_cast<size_t>(i)]),
                                                    &result->maps[static_cast<size_t>(i)]));
  result->times.refinement = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return Status();
}

}  // namespace

Result<ConsistentParamResult> parameterize_consistent(const std::vector<TriMesh>& meshes,
                                                      const std::vector<std::vector<int>>& features,
                                                      const ConsistentParamOptions& options,
                                                      const ProgressFn& progress, MeshFailure* failure_out) {
  MeshFailure unused;
  MeshFailure& failure = failure_out ? *failure_out : unused;
  failure = MeshFailure{};
  // An error of mesh i: the value for the caller, the message naming it for everyone else.
  auto fail_mesh = [&](int i, const Status& reason) {
    failure = {i, reason};
    return reason.with_context(mesh_label(i));
  };
  const auto t_start = std::chrono::steady_clock::now();
  const int n = static_cast<int>(meshes.size());
  if (n < 1) return Status(ErrorCode::InvalidArgument, "no meshes");
  if (features.size() != meshes.size())
    return Status(ErrorCode::InvalidArgument, "need one feature list per mesh (" + std::to_string(n) + " meshes, " +
                                                  std::to_string(features.size()) + " feature lists)");
  const size_t k = features[0].size();
  if (k < 1) return Status(ErrorCode::InvalidArgument, "no features");
  for (int i = 1; i < n; ++i)
    if (features[static_cast<size_t>(i)].size() != k)
    {
      const std::string counts = std::to_string(features[static_cast<size_t>(i)].size()) + " features, " +
                                 mesh_label(0) + " has " + std::to_string(k);
      failure = {i, Status(ErrorCode::InvalidArgument, "has " + counts)};
      return Status(ErrorCode::InvalidArgument, mesh_label(i) + " has " + counts);
    }
  const int ref = options.reference;
  if (ref < 0 || ref >= n)
    return Status(ErrorCode::InvalidArgument, "reference " + std::to_string(ref) + " is not a mesh index (0.." +
                                                  std::to_string(n - 1) + ")");
  const int grid = options.remesh_size;
  if (!is_geometry_image_size(grid) || grid < 9 || grid > 1025)
    return Status(ErrorCode::InvalidArgument, "remesh size must be 2^k+1 in 9..1025, got " + std::to_string(grid));
  if (static_cast<double>(k) * 4 > static_cast<double>(grid) * grid)
    return Status(ErrorCode::InvalidArgument, "remesh grid " + std::to_string(grid) + " is too coarse for " +
                                                  std::to_string(k) + " features");
  for (int i = 0; i < n; ++i)
    for (int v : features[static_cast<size_t>(i)])
      if (v < 0 || v >= meshes[static_cast<size_t>(i)].V.rows())
        return fail_mesh(i, Status(ErrorCode::InvalidInput,
                                   "feature vertex " + std::to_string(v) + " out of range (mesh has " +
                                       std::to_string(meshes[static_cast<size_t>(i)].V.rows()) + ")"));

  ConsistentParamResult result;
  result.maps.resize(static_cast<size_t>(n));
  SphereParamOptions sphere = options.constrained.sphere;
  sphere.threads = detail::resolve_threads(options.threads);

  // Step 1: unconstrained map of the reference; its feature images are F'.
  auto t0 = std::chrono::steady_clock::now();
  {
    auto r = parameterize_sphere(meshes[static_cast<size_t>(ref)], sphere, prefixed(progress, "step 1"));
    if (!r.ok()) return fail_mesh(ref, r.status());
    for (int v : features[static_cast<size_t>(ref)]) result.initial_locations.push_back(r->map.S.row(v).transpose());
    result.reference_efficiency = r->efficiency;
    result.unconstrained_efficiency.assign(static_cast<size_t>(n), 0.0);
    if (options.efficiency_retry > 0) result.unconstrained_efficiency[static_cast<size_t>(ref)] = r->efficiency;
    result.maps[static_cast<size_t>(ref)] = as_constrained(r.value());
  }
  result.times.reference = seconds_since(t0);

  // Step 2: the others constrained to F'. The reference keeps its map (its features are on
  // F' by definition).
  t0 = std::chrono::steady_clock::now();
  std::vector<int> others;
  for (int i = 0; i < n; ++i)
    if (i != ref) others.push_back(i);
  SPHEREKIT_RETURN_IF_ERROR(constrained_maps(meshes, features, others, result.initial_locations, options, "step 2",
                                             progress, &result.maps, &result.unconstrained_efficiency, &failure));
  result.times.initial = seconds_since(t0);
  result.final_locations = result.initial_locations;
  if (!options.refine_locations || n < 2) {
    // One mesh: the joint map of step 5 would be its own unconstrained map again.
    SPHEREKIT_RETURN_IF_ERROR(refine_maps(meshes, features, options, progress, &result));
    result.times.total = seconds_since(t_start);
    return result;
  }

  // Step 3: identical-connectivity remeshes, features snapped to the grid vertices nearest F'.
  t0 = std::chrono::steady_clock::now();
  const std::vector<int> texels = snap_texels(result.initial_locations, grid);
  std::vector<RowMat3d> remesh(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    if (!report_progress(progress, "step 3: remesh", i, static_cast<double>(i) / n))
      return Status(ErrorCode::Cancelled, "cancelled");
    auto g = remesh_on_grid(meshes[static_cast<size_t>(i)], result.maps[static_cast<size_t>(i)].map.S,
                            features[static_cast<size_t>(i)], texels, grid, options.threads);
    if (!g.ok()) return fail_mesh(i, g.status());
    remesh[static_cast<size_t>(i)] = std::move(g).value();
  }
  result.times.remesh = seconds_since(t0);

  // Step 4: one mesh with vertices in R^{3n}.
  t0 = std::chrono::steady_clock::now();
  const RowMat3i grid_faces = [&] {
    int count = 0;
    const std::vector<int> id = geometry_image_welded_ids(grid, &count);
    RowMat3i F = geometry_image_grid_faces(grid);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int c = 0; c < 3; ++c) F(f, c) = id[static_cast<size_t>(F(f, c))];
    return F;
  }();
  const Eigen::Index nv = remesh[0].rows();
  RowMatXd P(nv, 3 * n);
  for (int i = 0; i < n; ++i) P.middleCols(3 * i, 3) = remesh[static_cast<size_t>(i)];
  result.remesh_vertices = static_cast<int>(nv);
  result.times.concatenate = seconds_since(t0);

  // Step 5: unconstrained map of the joint mesh: progressive mesh under the n-D quadric
  // (progressive_mesh.h; fold-over checks per model) and coarse-to-fine embedding with the
  // stretch summed over the n geometries (each model scaled to the sphere's area).
  t0 = std::chrono::steady_clock::now();
  RowMat3d Sj;
  {
    const ProgressFn p5 = prefixed(progress, "step 5");
    ProgressiveMeshOptions pmo;
    SPHEREKIT_ASSIGN_OR_RETURN(ProgressiveMesh pm, build_progressive_mesh(P, grid_faces, pmo, p5));
    detail::OptimizerSettings settings = detail::optimizer_settings(sphere);
    settings.edge_frame_cruft = false;  // the collection stages' energy (stretch_optimizer.cpp, singular_cruft_term)
    detail::EmbedInput in;
    in.P = &P;
    in.pm = &pm;
    SPHEREKIT_RETURN_IF_ERROR(detail::embed_coarse_to_fine(in, settings, p5, &Sj, nullptr));
  }
  result.joint_flips = count_flipped_faces(grid_faces, Sj);
  if (result.joint_flips != 0)
    return Status(ErrorCode::Internal, "joint map of step 5 has " + std::to_string(result.joint_flips) + " flipped faces");
  {
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      TriMesh model;
      model.V = remesh[static_cast<size_t>(i)];
      model.F = grid_faces;
      SPHEREKIT_ASSIGN_OR_RETURN(SphereMapMetrics m, evaluate_sphere_map(model, Sj));
      sum += m.efficiency;
    }
    result.joint_efficiency = sum / n;
  }
  // F: the snapped samples' images, turned by the rotation that best matches F' (the joint
  // map's orientation is arbitrary; keeping the collection near the reference's makes
  // results comparable between runs with and without refinement).
  std::vector<Eigen::Vector3d> located;
  for (int t : texels) located.push_back(Sj.row(t).transpose());
  // (One feature leaves the orientation free: no rotation.)
  const Eigen::Matrix3d R =
      k >= 2 ? detail::best_rotation(located, result.initial_locations) : Eigen::Matrix3d::Identity();
  for (size_t f = 0; f < k; ++f) result.final_locations[f] = (R * located[f]).normalized();
  result.times.joint = seconds_since(t0);

  // Step 6: every mesh constrained to F.
  t0 = std::chrono::steady_clock::now();
  std::vector<int> all;
  for (int i = 0; i < n; ++i) all.push_back(i);
  std::vector<ConstrainedParamResult> final_maps(static_cast<size_t>(n));
  MeshFailure failure6;
  const Status s6 = constrained_maps(meshes, features, all, result.final_locations, options, "step 6", progress,
                                     &final_maps, &result.unconstrained_efficiency, &failure6);
  // A step-6 map can also complete and still be poor: where F moves features so that a
  // member's network must wind round (ICT heads with the nose tip and chin added to proposed
  // landmarks: one head's longest path 2.4x its shortest route, efficiency 0.43 against 0.80
  // for its step-2 map, and the refinement cannot undo it: correspondence error 0.14 against
  // 0.008-0.018 for the others). Such a map is a failure of the locations F for that member
  // (other Steiner costs gave 0.45-0.47), treated like a map that could not be made.
  const int collapsed = s6.ok() ? detail::first_collapsed_map(final_maps, result.maps, kStepSixCollapse) : -1;
  const int wound = s6.ok() && collapsed < 0
                        ? detail::first_wound_map(final_maps, result.maps, kStepSixWinding, kStepSixWindingGrowth)
                        : -1;
  if (s6.ok() && (collapsed >= 0 || wound >= 0)) {
    const int bad = collapsed >= 0 ? collapsed : wound;
    const auto& a = final_maps[static_cast<size_t>(bad)];
    const auto& b = result.maps[static_cast<size_t>(bad)];
    result.refinement_failure_mesh = bad;
    result.refinement_failure_reason =
        collapsed >= 0
            ? "its map to F has stretch efficiency " + format_text("%.3f", a.efficiency) + ", below " +
                  format_text("%.2f", kStepSixCollapse) + "x its step-2 map's " + format_text("%.3f", b.efficiency) +
                  " (longest network path " + format_text("%.2f", a.network.max_ratio) + "x its shortest route)"
            : "its network to F winds round: a path " + format_text("%.2f", a.network.max_ratio) +
                  "x its shortest route (to F' " + format_text("%.2f", b.network.max_ratio) + "x)";
    result.refinement_failure = mesh_label(bad) + ": " + result.refinement_failure_reason;
    result.rejected_locations = result.final_locations;
    result.final_locations = result.initial_locations;
  } else if (s6.ok()) {
    result.maps = std::move(final_maps);
  } else if (s6.code() == ErrorCode::SolverFailed) {
    // One mesh cannot be mapped to F: the step-2 maps are a complete, consistent answer (all
    // features on F'), so keep them rather than fail the collection, and say so.
    result.refinement_failure = s6.message();
    result.refinement_failure_mesh = failure6.mesh;
    result.refinement_failure_reason = failure6.reason.message();
    result.rejected_locations = result.final_locations;
    result.final_locations = result.initial_locations;
  } else {
    failure = failure6;
    return s6;
  }
  result.times.final_maps = seconds_since(t0);

  SPHEREKIT_RETURN_IF_ERROR(refine_maps(meshes, features, options, progress, &result));
  result.times.total = seconds_since(t_start);
  return result;
}

}  // namespace spherekit
