// The unconstrained spherical parameterization stage (Praun & Hoppe 2003):
//   check -> fill holes -> normalize -> progressive mesh -> coarse-to-fine embedding -> measure.
#include "spherekit/sphere_param.h"

#include <chrono>
#include <Eigen/SVD>
#include <cstdio>
#include <string>

#include "detail/sphere_embedding.h"
#include "detail/stage_util.h"
#include "spherekit/check_mesh.h"
#include "spherekit/fill_holes.h"
#include "spherekit/metrics.h"
#include "spherekit/progressive_mesh.h"
#include "spherekit/version.h"

namespace spherekit {
namespace {

using detail::seconds_since;

std::string options_digest(const SphereParamOptions& o) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "reg=%.17g;hole=%.17g;hshape=%.17g;seed=%llu;effort=%d;align=%d", o.regularizer_weight, o.hole_weight, o.hole_shape_weight,
                static_cast<unsigned long long>(o.seed), o.effort, o.align_rotation ? 1 : 0);
  std::string printed = buf;
  if (o.precise_layout) printed += ";precise;fine_split=0.95;layout_floor=0.03;pass_cap=64;outlier_polish";  // absent when off: the collection stages' digests are as before
  if (o.block_vertices > 0) printed += ";blocks=" + std::to_string(o.block_vertices);  // likewise
  return detail::options_digest_hex(printed);
}

// Rotation that best aligns each face's sphere direction with its surface normal (area
// weighted): the orthogonal Procrustes problem max sum_f w_f n_f . (R c_f), solved by the SVD
// of M = sum_f w_f n_f c_f^T (Praun & Hoppe's output alignment). It makes results
// independent of which base face got which tetrahedron corner, and gives symmetric shapes
// their radial projection (a regular tetrahedron maps exactly onto itself).
Eigen::Matrix3d alignment_rotation(const TriMesh& mesh, const RowMat3d& S, int faces) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (int f = 0; f < faces; ++f) {
    Eigen::Vector3d p0 = mesh.V.row(mesh.F(f, 0)), p1 = mesh.V.row(mesh.F(f, 1)), p2 = mesh.V.row(mesh.F(f, 2));
    Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);  // length = 2 area: the weight
    Eigen::Vector3d c = (S.row(mesh.F(f, 0)) + S.row(mesh.F(f, 1)) + S.row(mesh.F(f, 2))).transpose();
    double cl = c.norm();
    if (!(cl > 0)) continue;
    M += n * (c / cl).transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace

Result<SphereParamResult> parameterize_sphere(const TriMesh& mesh, const SphereParamOptions& options,
                                              const ProgressFn& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  SphereParamResult result;
  if (options.effort < 0 || options.effort > 5)
    return Status(ErrorCode::InvalidArgument, "effort must be in 0..5");

  // 1. Refuse what we cannot map (one precise message).
  MeshCheck check = check_mesh(mesh);
  SPHEREKIT_RETURN_IF_ERROR(require_param_accepts(mesh, check, /*allow_boundary=*/true));
  result.times.check = seconds_since(t_start);

  // 2. Close holes with tagged low-weight faces (removed again from the output).
  SPHEREKIT_ASSIGN_OR_RETURN(FilledMesh filled, fill_holes(mesh));
  result.holes_filled = filled.holes;
  const TriMesh& closed = filled.mesh;
  const int nf = static_cast<int>(closed.F.rows());
  std::vector<double> face_weight(static_cast<size_t>(nf), 1.0);
  std::vector<double> shape_weight(static_cast<size_t>(nf), 0.0);
  for (int f = filled.original_faces; f < nf; ++f) {
    face_weight[static_cast<size_t>(f)] = options.hole_weight;
    shape_weight[static_cast<size_t>(f)] = options.hole_shape_weight;
  }

  // 3. Normalize: centre and scale to unit bounding-box diagonal so that every tolerance in
  //    the simplifier is relative to the model (stretch efficiency is scale-invariant).
  const detail::Normalization nz = detail::bounding_box_normalization(closed.V);
  if (!(nz.diagonal > 0)) return Status(ErrorCode::InvalidInput, "mesh has zero extent");
  RowMatXd P = (closed.V.rowwise() - nz.centre) / nz.diagonal;

  // 4. Progressive mesh down to a tetrahedron.
  auto t0 = std::chrono::steady_clock::now();
  ProgressiveMeshOptions pmo;
  // The reference's simplification (MeshSimplify -minqem, REFERENCE.md §2.1): memoryless
  // quadrics with the vertex normals at 0.02 x the diagonal (P has a unit diagonal). Thin
  // limbs then survive to the coarse levels, which decide how much of the sphere they get
  // (issue 20: tentacle blob 0.1127 -> 0.1272 with the same optimizer).
  pmo.normal_weight = 0.02;
  pmo.memoryless = true;
  pmo.threads = options.threads;
  pmo.block_vertices = options.block_vertices;
  // Hole faces take full part in the simplification (only the optimizer down-weights
  // them, as the reference does): their geometry shapes the coarse levels like any other.
  SPHEREKIT_ASSIGN_OR_RETURN(ProgressiveMesh pm, build_progressive_mesh(P, closed.F, pmo, progress));
  result.times.simplify = seconds_since(t0);
  result.base_vertices = static_cast<int>(pm.base_vertices.size());

  // 5. Coarse-to-fine embedding with stretch optimization.
  t0 = std::chrono::steady_clock::now();
  detail::OptimizerSettings settings = detail::optimizer_settings(options);
  // The final pass on the measured energy including its normalization (issue 20, measured on
  // closed meshes, one thread, efficiency before -> after: knight 0.3148 -> 0.3279, armadillo
  // 0.4233 -> 0.4248, tentacles_r96 0.1647 -> 0.1697, a fan-capped cylinder 0.785 -> 0.947,
  // skin_star 0.1925 -> 0.1961; meshes with holes had it already). The collection stages
  // keep the plain energy: with it in every stage the FAUST correspondence moved from
  // 0.032 / 0.064 / 0.034 to 0.039 / 0.066 / 0.035 (evalcorr, 000 to 013 / 027 / 041). The
  // collections start from these maps, so they move anyway (0.034 / 0.073 / 0.034; TOSCA
  // cats 0.064 / 0.024 / 0.049 -> 0.067 / 0.024 / 0.048), within what small perturbations do.
  settings.measured_normalization = true;
  detail::EmbedInput in;
  in.P = &P;
  in.pm = &pm;
  in.face_weight = face_weight;
  in.face_shape_weight = shape_weight;
  RowMat3d S;
  detail::EmbedStats stats;
  SPHEREKIT_RETURN_IF_ERROR(detail::embed_coarse_to_fine(in, settings, progress, &S, &stats));
  result.times.refine = seconds_since(t0);
  result.optimization_passes = stats.passes;

  // 6. Rotate to the best alignment with the surface normals. A rotation preserves every
  //    orientation in exact arithmetic, but rounding of the rotated coordinates could flip a
  //    tiny triangle, so the rotated map is kept only if the exact check still passes.
  //    Both on the normalized mesh P: the face normals and stretch sums of the input's own
  //    coordinates overflow or underflow far from unit size (NaN stretch at 1e100), and the
  //    rotation and the measures (efficiency, normalized stretch) do not depend on scale.
  TriMesh unit;
  unit.V = P;
  unit.F = closed.F;
  if (options.align_rotation) {
    Eigen::Matrix3d R = alignment_rotation(unit, S, nf);
    RowMat3d rotated = S * R.transpose();
    rotated.rowwise().normalize();
    if (count_flipped_faces(closed.F, rotated) == 0) S = rotated;
  }

  // 7. Check and measure: flips by exact predicate over every face of the closed mesh
  //    (hole faces included: they are part of the bijection), stretch over the real faces.
  result.flipped_faces = count_flipped_faces(closed.F, S);
  std::vector<char> real(static_cast<size_t>(nf), 0);
  for (int f = 0; f < filled.original_faces; ++f) real[static_cast<size_t>(f)] = 1;
  SPHEREKIT_ASSIGN_OR_RETURN(SphereMapMetrics m, evaluate_sphere_map(unit, S, {}, &real));
  result.efficiency = m.efficiency;
  result.l2_stretch = m.l2_stretch;
  result.linf_stretch = m.linf;
  result.winding = m.winding;
  SPHEREKIT_RETURN_IF_ERROR(detail::require_finite_measures(m.efficiency, m.l2_stretch, m.linf));

  result.map.S = S.topRows(filled.original_vertices);
  result.map.provenance.library_version = kVersion;
  result.map.provenance.method = "unconstrained";
  result.map.provenance.options_digest = options_digest(options);
  result.map.provenance.seed = options.seed;
  result.times.total = seconds_since(t_start);
  return result;
}

}  // namespace spherekit
