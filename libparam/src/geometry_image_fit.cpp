// Least-squares geometry image positions.
//
// Point sampling puts every texel on the surface; the remesh then interpolates linearly
// between texels and, on a curved surface, lies entirely on one side of it (the chords of a
// convex patch are inside it). The remesh error is an RMS over the surface, so the texel
// values that minimize it are not the samples but the L2 projection of the surface onto the
// piecewise-linear functions of the image grid: for a curved patch the projection shifts the
// remesh halfway across the surface, which roughly halves the RMS distance for the same
// number of texels (Hoppe's geometry images store sampled values; fitting them is the
// standard finite-element view of "best texel values for a given grid").
//
// The objective, over the welded texel values T (the folded border's pairs are one unknown,
// so the fold identity survives):
//   sum over surface samples s of  w_s |sum_k beta_sk T_k - p_s|^2  +  lambda sum_t |T_t - T0_t|^2
// where p_s is a point of the mesh, beta_s the barycentrics, in the image grid's triangle,
// of its octahedral domain point (through the sphere map, exactly as the sampler goes the
// other way), w_s its share of surface area, and T0 the sampled values. The small lambda
// keeps texels that no sample reaches (the few texels between samples of a strongly expanded
// region) at their sampled value and makes the system positive definite.
//
// Hole texels (sphere point in a hole of the mesh) are held at their sampled values exactly:
// there is no surface inside a hole to fit, and the sampler puts them on the hole's rim (the
// nearest point of the nearest face). Left free, the samples just inside the rim pull them
// outwards, extrapolating the surface across the hole, and the faces that straddle the rim
// then stick out over it; held on the rim, those faces span exactly the band between the last
// surface texels and the rim (bunny at 257: 79.5 -> 82.7 dB with geometry_image_hole_faces).
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Sparse>
#include <Eigen/IterativeLinearSolvers>

#include "spherekit/geometry_image.h"

namespace spherekit {
namespace {

// Barycentric coordinates of domain point (u, v) in the image grid's triangle containing it,
// with the grid's split rule (geometry_image_grid_faces): the triangle and the weights of its
// corners, in the corner order of that face.
// `tri` gets the triangle's index in geometry_image_grid_faces (two per cell, same order).
void grid_triangle(double u, double v, int n, int& tri, std::array<double, 3>& w) {
  const int m = n - 1, half = m / 2;
  const double x = (u + 1) * 0.5 * m, y = (v + 1) * 0.5 * m;
  const int j = std::clamp(static_cast<int>(std::floor(x)), 0, m - 1);
  const int i = std::clamp(static_cast<int>(std::floor(y)), 0, m - 1);
  const double s = std::clamp(x - j, 0.0, 1.0), t = std::clamp(y - i, 0.0, 1.0);
  // Corners A (i,j), B (i,j+1), C (i+1,j+1), D (i+1,j); faces ABD, BCD or ABC, ACD.
  const int cell = 2 * (i * m + j);
  if ((j >= half) == (i >= half)) {
    if (s + t <= 1) tri = cell, w = {1 - s - t, s, t};
    else tri = cell + 1, w = {1 - t, s + t - 1, 1 - s};
  } else {
    if (s >= t) tri = cell, w = {1 - s, s - t, t};
    else tri = cell + 1, w = {1 - t, s, t - s};
  }
}

// Centroids of the m^2 sub-triangles of a triangle cut m times along each side, as
// barycentrics: a stratified sample that covers the face evenly.
void lattice_barycentrics(int m, std::vector<Eigen::Vector3d>& out) {
  out.clear();
  for (int a = 0; a < m; ++a)
    for (int b = 0; a + b < m; ++b) {
      out.emplace_back((a + 1.0 / 3) / m, (b + 1.0 / 3) / m, 0);
      if (a + b + 1 < m) out.emplace_back((a + 2.0 / 3) / m, (b + 2.0 / 3) / m, 0);
    }
  for (auto& q : out) q.z() = 1 - q.x() - q.y();
}

}  // namespace

Status fit_geometry_image_positions(const TriMesh& mesh, const RowMat3d& S, GeometryImage* image) {
  const int n = image->size;
  if (!is_geometry_image_size(n) || image->positions.size() != static_cast<std::size_t>(n) * n * 3)
    return Status(ErrorCode::InvalidArgument, "not a sampled geometry image");
  if (S.rows() != mesh.V.rows()) return Status(ErrorCode::InvalidInput, "sphere map and mesh differ in size");
  int unknowns = 0;
  const std::vector<int> id = geometry_image_welded_ids(n, &unknowns);
  const auto nu = static_cast<std::size_t>(unknowns);

  // Samples: per face, a lattice dense enough for about 16 samples per grid triangle both
  // where the surface is and where the sphere is (a face the map expands gets more).
  const Eigen::Index nf = mesh.F.rows();
  std::vector<double> surface_area(static_cast<std::size_t>(nf)), sphere_area(static_cast<std::size_t>(nf));
  double total_surface = 0, total_sphere = 0;
  for (Eigen::Index f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d qa = S.row(mesh.F(f, 0)), qb = S.row(mesh.F(f, 1)), qc = S.row(mesh.F(f, 2));
    surface_area[static_cast<std::size_t>(f)] = 0.5 * (b - a).cross(c - a).norm();
    sphere_area[static_cast<std::size_t>(f)] = 0.5 * (qb - qa).cross(qc - qa).norm();
    total_surface += surface_area[static_cast<std::size_t>(f)];
    total_sphere += sphere_area[static_cast<std::size_t>(f)];
  }
  if (!(total_surface > 0) || !(total_sphere > 0)) return Status();  // nothing to fit: keep the samples
  const double target = 16.0 * 2.0 * (n - 1) * (n - 1);

  // Normal equations, accumulated per grid triangle (its 3 x 3 block and right-hand sides)
  // and assembled once: memory in grid triangles, not in samples.
  const RowMat3i grid = geometry_image_grid_faces(n);
  std::vector<std::array<double, 9>> block(static_cast<std::size_t>(grid.rows()), std::array<double, 9>{});
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(unknowns, 3);
  std::vector<Eigen::Vector3d> lattice;
  int last_m = -1;
  for (Eigen::Index f = 0; f < nf; ++f) {
    const auto fi = static_cast<std::size_t>(f);
    const double k = target * std::max(surface_area[fi] / total_surface, sphere_area[fi] / total_sphere);
    const int m = std::clamp(static_cast<int>(std::ceil(std::sqrt(k))), 1, 64);
    if (m != last_m) lattice_barycentrics(m, lattice), last_m = m;
    const double w = surface_area[fi] / static_cast<double>(lattice.size());
    if (!(w > 0)) continue;
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d qa = S.row(mesh.F(f, 0)), qb = S.row(mesh.F(f, 1)), qc = S.row(mesh.F(f, 2));
    for (const Eigen::Vector3d& beta : lattice) {
      // The sampler's gnomonic barycentrics, inverted: the chord-plane point, normalized.
      const Eigen::Vector3d q = beta.x() * qa + beta.y() * qb + beta.z() * qc;
      if (!(q.norm() > 0)) continue;
      const Eigen::Vector2d uv = sphere_to_octahedral(q);
      int tri = 0;
      std::array<double, 3> gw;
      grid_triangle(uv.x(), uv.y(), n, tri, gw);
      const Eigen::Vector3d p = beta.x() * a + beta.y() * b + beta.z() * c;
      auto& blk = block[static_cast<std::size_t>(tri)];
      for (int r = 0; r < 3; ++r) {
        const double wr = w * gw[static_cast<std::size_t>(r)];
        rhs.row(id[static_cast<std::size_t>(grid(tri, r))]) += wr * p.transpose();
        for (int col = 0; col < 3; ++col) blk[static_cast<std::size_t>(3 * r + col)] += wr * gw[static_cast<std::size_t>(col)];
      }
    }
  }
  // Anchor values, and the pinned unknowns (hole texels; fold pairs share their hole flag, as
  // they share their sphere point).
  Eigen::MatrixXd anchor(unknowns, 3);
  std::vector<std::uint8_t> pinned(nu, 0);
  const bool holes = image->in_hole.size() == static_cast<std::size_t>(n) * n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::size_t t = static_cast<std::size_t>(i) * n + j;
      for (int d = 0; d < 3; ++d) anchor(id[t], d) = image->positions[3 * t + static_cast<std::size_t>(d)];
      if (holes && image->in_hole[t]) pinned[static_cast<std::size_t>(id[t])] = 1;
    }
  // A pinned unknown is a constant: its row becomes T = anchor, and its column moves to the
  // right-hand side of the free rows (the matrix stays symmetric).
  std::vector<Eigen::Triplet<double>> triplets;
  std::vector<double> diag(nu, 0.0);
  for (Eigen::Index t = 0; t < grid.rows(); ++t) {
    const auto& blk = block[static_cast<std::size_t>(t)];
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) {
        const double v = blk[static_cast<std::size_t>(3 * r + col)];
        if (v == 0) continue;
        const int row = id[static_cast<std::size_t>(grid(t, r))], cid = id[static_cast<std::size_t>(grid(t, col))];
        if (pinned[static_cast<std::size_t>(row)]) continue;
        if (pinned[static_cast<std::size_t>(cid)]) rhs.row(row) -= v * anchor.row(cid);
        else if (row == cid) diag[static_cast<std::size_t>(row)] += v;
        else triplets.emplace_back(row, cid, v);
      }
  }
  block.clear();
  block.shrink_to_fit();
  // Anchor weight: lambda relative to the mean data weight per free texel.
  double mean_diag = 0;
  std::size_t free_count = 0;
  for (std::size_t u = 0; u < nu; ++u)
    if (!pinned[u]) mean_diag += diag[u], ++free_count;
  mean_diag /= static_cast<double>(std::max<std::size_t>(free_count, 1));
  const double lambda = 1e-3 * mean_diag;
  for (std::size_t u = 0; u < nu; ++u) {
    const auto row = static_cast<Eigen::Index>(u);
    if (pinned[u]) {
      triplets.emplace_back(static_cast<int>(u), static_cast<int>(u), 1.0);
      rhs.row(row) = anchor.row(row);
    } else {
      triplets.emplace_back(static_cast<int>(u), static_cast<int>(u), diag[u] + lambda);
      rhs.row(row) += lambda * anchor.row(row);
    }
  }
  Eigen::SparseMatrix<double> A(unknowns, unknowns);
  A.setFromTriplets(triplets.begin(), triplets.end());
  triplets.clear();
  triplets.shrink_to_fit();

  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(1e-10);
  cg.setMaxIterations(4 * n + 200);
  cg.compute(A);
  if (cg.info() != Eigen::Success) return Status(ErrorCode::SolverFailed, "geometry image fit: factorization failed");
  Eigen::MatrixXd T(unknowns, 3);
  for (int d = 0; d < 3; ++d) {
    T.col(d) = cg.solveWithGuess(rhs.col(d), anchor.col(d));
    if (!T.col(d).allFinite()) return Status(ErrorCode::SolverFailed, "geometry image fit: the solve diverged");
  }
  for (std::size_t t = 0; t < static_cast<std::size_t>(n) * n; ++t)
    for (int d = 0; d < 3; ++d) image->positions[3 * t + static_cast<std::size_t>(d)] = static_cast<float>(T(id[t], d));
  return Status();
}

}  // namespace spherekit
