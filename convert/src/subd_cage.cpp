// Catmull–Clark cages on the sphere domain: the cube lattice, Bfr limit stencils, and the
// least-squares fit of the control points (Lee, Moreton & Hoppe 2000, step 2: "optimize
// control-vertex positions so the limit surface fits the dense mesh"). Here the samples are
// not found by projection: the sphere map already pairs each limit-surface parameter with a
// mesh point, so the fit is one linear least-squares problem.
#include "spherekit/convert/subd_cage.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "spherekit/convert/cage_uv_atlas.h"
#include "spherekit/correspondence.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/geometry_image.h"

namespace spherekit::convert {
namespace {

namespace osd = OpenSubdiv;

// Cube face frames (normal, e1, e2) with e1 x e2 = normal, so cells traversed +e1 then +e2 are
// counter-clockwise seen from outside.
constexpr int kFrames[6][3][3] = {
    {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},   {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
    {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},   {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
    {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},   {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}},
};

int thread_count(int requested) { return requested > 0 ? requested : omp_get_max_threads(); }

}  // namespace

long long cube_lattice_points(int m) { return 6LL * m * m + 2; }

int cube_lattice_id(int m, int k, int i, int j) {
  // Twice the lattice point's coordinates in the cube [0, m]^3: integers in [0, 2m].
  int d[3];
  for (int c = 0; c < 3; ++c) d[c] = m + m * kFrames[k][0][c] + (2 * i - m) * kFrames[k][1][c] + (2 * j - m) * kFrames[k][2][c];
  const long long interior = 6LL * (m - 1) * (m - 1);
  if (i > 0 && i < m && j > 0 && j < m) return static_cast<int>(static_cast<long long>(k) * (m - 1) * (m - 1) + static_cast<long long>(j - 1) * (m - 1) + (i - 1));
  int fixed = 0, free_axis = -1;
  for (int c = 0; c < 3; ++c) {
    if (d[c] == 0 || d[c] == 2 * m) ++fixed;
    else free_axis = c;
  }
  if (fixed == 3)  // a cube corner
    return static_cast<int>(interior + 12LL * (m - 1) + (d[0] ? 4 : 0) + (d[1] ? 2 : 0) + (d[2] ? 1 : 0));
  // On a cube edge: the free axis and the two fixed sides name the edge; d[free] / 2 is the
  // position along it (1 .. m-1).
  const int a = (free_axis + 1) % 3, b = (free_axis + 2) % 3;
  const int edge = free_axis * 4 + (d[a] ? 2 : 0) + (d[b] ? 1 : 0);
  return static_cast<int>(interior + static_cast<long long>(edge) * (m - 1) + (d[free_axis] / 2 - 1));
}

Eigen::Vector3d cube_domain_point(int k, double s, double t) {
  const double quarter_pi = 0.78539816339744830962;
  const double a = std::tan((2 * s - 1) * quarter_pi), b = std::tan((2 * t - 1) * quarter_pi);
  Eigen::Vector3d p;
  for (int c = 0; c < 3; ++c) p[c] = kFrames[k][0][c] + a * kFrames[k][1][c] + b * kFrames[k][2][c];
  return p.normalized();
}

Eigen::Vector3d cage_domain_point(const CageDomain& domain, int f, double u, double v) {
  const std::array<int, 3>& c = domain.face_cell[static_cast<std::size_t>(f)];
  return cube_domain_point(c[0], (c[1] + u) / domain.n, (c[2] + v) / domain.n);
}

Result<CageDomain> cube_cage_domain(int n) {
  if (n < 1 || n > 4096) return Status(ErrorCode::InvalidArgument, "cage size " + std::to_string(n) + " is not in 1..4096");
  CageDomain d;
  d.n = n;
  d.sphere.resize(cube_lattice_points(n), 3);
  d.quads.reserve(static_cast<std::size_t>(6) * n * n);
  d.face_cell.reserve(d.quads.capacity());
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) d.sphere.row(cube_lattice_id(n, k, i, j)) = cube_domain_point(k, double(i) / n, double(j) / n).transpose();
  for (int k = 0; k < 6; ++k)
    for (int b = 0; b < n; ++b)
      for (int a = 0; a < n; ++a) {
        d.quads.push_back({cube_lattice_id(n, k, a, b), cube_lattice_id(n, k, a + 1, b),
                           cube_lattice_id(n, k, a + 1, b + 1), cube_lattice_id(n, k, a, b + 1)});
        d.face_cell.push_back({k, a, b});
      }
  return d;
}

// ---------------------------------------------------------------------------------------

struct CageLimit::Impl {
  std::unique_ptr<osd::Far::TopologyRefiner> refiner;
  std::vector<osd::Bfr::Surface<double>> surfaces;
  std::vector<std::vector<int>> indices;  // control points of each face's surface
};

CageLimit::CageLimit() : impl_(std::make_unique<Impl>()) {}
CageLimit::~CageLimit() = default;
CageLimit::CageLimit(CageLimit&&) noexcept = default;
CageLimit& CageLimit::operator=(CageLimit&&) noexcept = default;
int CageLimit::faces() const { return static_cast<int>(impl_->surfaces.size()); }

Result<CageLimit> CageLimit::create(const CageDomain& domain) {
  const int nv = static_cast<int>(domain.sphere.rows()), nf = static_cast<int>(domain.quads.size());
  if (nf == 0 || nv < 4) return Status(ErrorCode::InvalidArgument, "empty cage");
  std::vector<int> per_face(static_cast<std::size_t>(nf), 4), flat;
  flat.reserve(static_cast<std::size_t>(nf) * 4);
  for (const auto& q : domain.quads)
    for (int c : q) {
      if (c < 0 || c >= nv) return Status(ErrorCode::InvalidArgument, "cage quad index out of range");
      flat.push_back(c);
    }
  osd::Far::TopologyDescriptor desc;
  desc.numVertices = nv;
  desc.numFaces = nf;
  desc.numVertsPerFace = per_face.data();
  desc.vertIndicesPerFace = flat.data();
  osd::Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(osd::Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
  using Factory = osd::Far::TopologyRefinerFactory<osd::Far::TopologyDescriptor>;
  CageLimit out;
  out.impl_->refiner.reset(Factory::Create(desc, Factory::Options(osd::Sdc::SCHEME_CATMARK, sdc)));
  if (!out.impl_->refiner) return Status(ErrorCode::Internal, "OpenSubdiv rejected the cage topology");
  // Surfaces are built once, sequentially (the factory's cache is not thread-safe); evaluating
  // them afterwards is const and safe from any thread.
  // Bfr represents the irregular patches around the 8 valence-3 corners by refining them to
  // this level; its default (2) leaves them up to 5e-4 of the size away from the exact limit
  // surface that Blender, RenderMan and OpenSubdiv's patch tables evaluate (measured against
  // Blender 3.4: at 6 the cage + vector displacement agree to float precision, 1e-7).
  osd::Bfr::SurfaceFactory::Options fopt;
  fopt.SetApproxLevelSmooth(6);
  osd::Bfr::RefinerSurfaceFactory<> factory(*out.impl_->refiner, fopt);
  out.impl_->surfaces.resize(static_cast<std::size_t>(nf));
  out.impl_->indices.resize(static_cast<std::size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    osd::Bfr::Surface<double>& s = out.impl_->surfaces[static_cast<std::size_t>(f)];
    if (!factory.InitVertexSurface<double>(f, &s) || !s.IsValid())
      return Status(ErrorCode::Internal, "OpenSubdiv gave no limit surface for cage face " + std::to_string(f));
    std::vector<int>& idx = out.impl_->indices[static_cast<std::size_t>(f)];
    idx.resize(static_cast<std::size_t>(s.GetNumControlPoints()));
    s.GetControlPointIndices(idx.data());
  }
  return out;
}

void CageLimit::stencil(int f, double u, double v, Stencil& out) const {
  const auto& s = impl_->surfaces[static_cast<std::size_t>(f)];
  out.indices = impl_->indices[static_cast<std::size_t>(f)];
  const std::size_t n = out.indices.size();
  out.w.resize(n);
  out.wu.resize(n);
  out.wv.resize(n);
  const double uv[2] = {u, v};
  s.EvaluateStencil(uv, out.w.data(), out.wu.data(), out.wv.data());
}

void CageLimit::evaluate(const RowMat3d& points, int f, double u, double v, Eigen::Vector3d& position,
                         Eigen::Vector3d& normal) const {
  thread_local Stencil st;
  stencil(f, u, v, st);
  position.setZero();
  Eigen::Vector3d du = Eigen::Vector3d::Zero(), dv = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < st.indices.size(); ++k) {
    const Eigen::Vector3d p = points.row(st.indices[k]).transpose();
    position += st.w[k] * p;
    du += st.wu[k] * p;
    dv += st.wv[k] * p;
  }
  normal = du.cross(dv);
  const double len = normal.norm();
  if (len > 0) normal /= len;
}

// ---------------------------------------------------------------------------------------

Result<SubdCage> fit_subd_cage(const TriMesh& mesh, const RowMat3d& S, const CageLimit& limit,
                               const CageDomain& domain, const CageFitOptions& options, const ProgressFn& progress) {
  if (options.samples_per_edge < 1 || options.samples_per_edge > 256 || !(options.smoothness >= 0) ||
      !(options.hole_weight >= 0) || options.project_iterations < 0 || options.project_iterations > 20)
    return Status(ErrorCode::InvalidArgument, "cage fit: samples per edge must be 1..256, weights >= 0");
  if (mesh.F.rows() == 0 || mesh.V.rows() == 0) return Status(ErrorCode::InvalidInput, "cage fit: empty mesh");
  if (S.rows() != mesh.V.rows())
    return Status(ErrorCode::InvalidInput, "cage fit: sphere map and mesh differ in vertex count");
  if (limit.faces() != static_cast<int>(domain.quads.size()))
    return Status(ErrorCode::InvalidArgument, "cage fit: limit surface and domain differ");
  const int nf = static_cast<int>(domain.quads.size());
  const int nv = static_cast<int>(domain.sphere.rows());
  const int k = options.samples_per_edge;
  const int per_face = k * k;
  if (!report_progress(progress, "cage fit", 0, 0)) return Status(ErrorCode::Cancelled, "cancelled");

  // Samples: stencil and mesh target, computed in parallel into per-sample slots so the
  // assembly below (and so the result) does not depend on the thread count.
  const SphereLocator locator(mesh.F, S);
  std::vector<std::vector<int>> idx(static_cast<std::size_t>(nf));
  std::vector<std::vector<double>> w(static_cast<std::size_t>(nf) * per_face);
  RowMat3d targets(static_cast<Eigen::Index>(nf) * per_face, 3);
  std::vector<std::uint8_t> in_hole(static_cast<std::size_t>(nf) * per_face, 0);
#pragma omp parallel for schedule(dynamic, 8) num_threads(thread_count(options.threads))
  for (int f = 0; f < nf; ++f) {
    CageLimit::Stencil st;
    for (int s = 0; s < per_face; ++s) {
      const double u = (s % k + 0.5) / k, v = (s / k + 0.5) / k;
      limit.stencil(f, u, v, st);
      const std::size_t row = static_cast<std::size_t>(f) * per_face + s;
      w[row] = st.w;
      if (s == 0) idx[static_cast<std::size_t>(f)] = st.indices;
      const SphereLocation loc = locator.locate(cage_domain_point(domain, f, u, v));
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      if (loc.face >= 0)
        for (int c = 0; c < 3; ++c) p += loc.bary[c] * mesh.V.row(mesh.F(loc.face, c)).transpose();
      targets.row(static_cast<Eigen::Index>(row)) = p.transpose();
      in_hole[row] = loc.inside ? 0 : 1;
    }
  }
  if (!report_progress(progress, "cage fit", 0, 0.5)) return Status(ErrorCode::Cancelled, "cancelled");

  // Normal equations A^T A x = A^T b of the weighted samples plus the umbrella term.
  using Sparse = Eigen::SparseMatrix<double>;
  std::vector<Eigen::Triplet<double>> triplets;
  std::size_t nnz = 0;
  for (int f = 0; f < nf; ++f) nnz += idx[static_cast<std::size_t>(f)].size() * per_face;
  triplets.reserve(nnz + static_cast<std::size_t>(nv) * 6);
  const Eigen::Index rows = static_cast<Eigen::Index>(nf) * per_face + nv;
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(rows, 3);
  for (int f = 0; f < nf; ++f)
    for (int s = 0; s < per_face; ++s) {
      const std::size_t row = static_cast<std::size_t>(f) * per_face + s;
      const double sw = in_hole[row] ? std::sqrt(options.hole_weight) : 1.0;
      const std::vector<int>& ix = idx[static_cast<std::size_t>(f)];
      for (std::size_t c = 0; c < ix.size(); ++c)
        if (w[row][c] != 0) triplets.emplace_back(static_cast<int>(row), ix[c], sw * w[row][c]);
      b.row(static_cast<Eigen::Index>(row)) = sw * targets.row(static_cast<Eigen::Index>(row));
    }
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(nv));
  for (const auto& q : domain.quads)
    for (int c = 0; c < 4; ++c) {
      neighbours[static_cast<std::size_t>(q[c])].push_back(q[(c + 1) % 4]);
      neighbours[static_cast<std::size_t>(q[(c + 1) % 4])].push_back(q[c]);
    }
  const double lambda = std::sqrt(options.smoothness * per_face);
  for (int i = 0; i < nv; ++i) {
    std::vector<int>& nb = neighbours[static_cast<std::size_t>(i)];
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    if (lambda == 0 || nb.empty()) continue;
    const int row = nf * per_face + i;
    triplets.emplace_back(row, i, lambda);
    for (int j : nb) triplets.emplace_back(row, j, -lambda / static_cast<double>(nb.size()));
  }
  Sparse A(rows, nv);
  A.setFromTriplets(triplets.begin(), triplets.end());
  triplets.clear();
  triplets.shrink_to_fit();
  const Sparse At = A.transpose();
  const Sparse AtA = At * A;
  const Eigen::MatrixXd Atb = At * b;
  Eigen::SimplicialLDLT<Sparse> solver(AtA);
  if (solver.info() != Eigen::Success)
    return Status(ErrorCode::SolverFailed, "cage fit: the least-squares system is singular");
  Eigen::MatrixXd x = solver.solve(Atb);
  if (solver.info() != Eigen::Success || !x.allFinite())
    return Status(ErrorCode::SolverFailed, "cage fit: the least-squares solve failed");

  if (options.project_iterations > 0) {
    const ClosestPointLocator closest(mesh);
    for (int it = 0; it < options.project_iterations; ++it) {
      if (!report_progress(progress, "cage fit", it + 1, 0.5 + 0.5 * (it + 1) / (options.project_iterations + 1)))
        return Status(ErrorCode::Cancelled, "cancelled");
#pragma omp parallel for schedule(dynamic, 8) num_threads(thread_count(options.threads))
      for (int f = 0; f < nf; ++f) {
        const std::vector<int>& ix = idx[static_cast<std::size_t>(f)];
        CageLimit::Stencil st;
        for (int s = 0; s < per_face; ++s) {
          const std::size_t row = static_cast<std::size_t>(f) * per_face + s;
          if (in_hole[row]) continue;
          limit.stencil(f, (s % k + 0.5) / k, (s / k + 0.5) / k, st);
          Eigen::Vector3d P = Eigen::Vector3d::Zero(), du = Eigen::Vector3d::Zero(), dv = Eigen::Vector3d::Zero();
          for (std::size_t c = 0; c < ix.size(); ++c) {
            const Eigen::Vector3d q = x.row(ix[c]).transpose();
            P += st.w[c] * q;
            du += st.wu[c] * q;
            dv += st.wv[c] * q;
          }
          const SurfacePoint y = closest.closest(P);
          if (y.face < 0) continue;
          const Eigen::Vector3d va = mesh.V.row(mesh.F(y.face, 0)), vb = mesh.V.row(mesh.F(y.face, 1)),
                                vc = mesh.V.row(mesh.F(y.face, 2));
          if ((vb - va).cross(vc - va).dot(du.cross(dv)) <= 0) continue;
          targets.row(static_cast<Eigen::Index>(row)) = surface_position(mesh, y).transpose();
        }
      }
      for (Eigen::Index row = 0; row < static_cast<Eigen::Index>(nf) * per_face; ++row)
        if (!in_hole[static_cast<std::size_t>(row)]) b.row(row) = targets.row(row);
      x = solver.solve(At * b);
      if (solver.info() != Eigen::Success || !x.allFinite())
        return Status(ErrorCode::SolverFailed, "cage fit: the least-squares solve failed");
    }
  }

  SubdCage cage;
  cage.domain = domain;
  cage.points = x;
  cage.fit_samples = nf * per_face;
  double sum = 0;
  long long counted = 0;
  for (int f = 0; f < nf; ++f)
    for (int s = 0; s < per_face; ++s) {
      const std::size_t row = static_cast<std::size_t>(f) * per_face + s;
      if (in_hole[row]) continue;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      const std::vector<int>& ix = idx[static_cast<std::size_t>(f)];
      for (std::size_t c = 0; c < ix.size(); ++c) p += w[row][c] * cage.points.row(ix[c]).transpose();
      sum += (p - targets.row(static_cast<Eigen::Index>(row)).transpose()).squaredNorm();
      ++counted;
    }
  cage.fit_rms = counted > 0 ? std::sqrt(sum / static_cast<double>(counted)) : 0;
  if (!report_progress(progress, "cage fit", 0, 1)) return Status(ErrorCode::Cancelled, "cancelled");
  return cage;
}

Status write_cage_obj(const std::string& path, const SubdCage& cage, const std::string& comment,
                      const CageUvAtlas* uv) {
  const int nf = static_cast<int>(cage.domain.quads.size());
  if (uv && uv->faces != nf)
    return Status(ErrorCode::InvalidArgument, path + ": the UV atlas is for another number of quads");
  std::string out;
  out.reserve(static_cast<std::size_t>(cage.points.rows()) * 40 + cage.domain.quads.size() * 32);
  out += "# Catmull-Clark cage (spherekit): cube domain, " + std::to_string(cage.domain.n) + " x " +
         std::to_string(cage.domain.n) + " quads per cube face\n";
  if (!comment.empty()) out += "# " + comment + "\n";
  char line[128];
  for (Eigen::Index i = 0; i < cage.points.rows(); ++i) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", cage.points(i, 0), cage.points(i, 1), cage.points(i, 2));
    out += line;
  }
  if (uv) {
    // Corner k of a quad is the limit-surface parameter (0,0), (1,0), (1,1), (0,1).
    const double corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int f = 0; f < nf; ++f)
      for (const auto& c : corner) {
        const Eigen::Vector2d t = uv->uv(f, c[0], c[1]);
        std::snprintf(line, sizeof line, "vt %.9g %.9g\n", t.x(), t.y());
        out += line;
      }
  }
  for (int f = 0; f < nf; ++f) {
    const auto& q = cage.domain.quads[static_cast<std::size_t>(f)];
    if (uv)
      std::snprintf(line, sizeof line, "f %d/%d %d/%d %d/%d %d/%d\n", q[0] + 1, 4 * f + 1, q[1] + 1, 4 * f + 2,
                    q[2] + 1, 4 * f + 3, q[3] + 1, 4 * f + 4);
    else
      std::snprintf(line, sizeof line, "f %d %d %d %d\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    out += line;
  }
  return formats::write_file_atomic(path, out);
}

}  // namespace spherekit::convert
