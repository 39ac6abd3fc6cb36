// Correspondence refinement (see refine_correspondence.h): the template carried onto each
// member as rigidly as possible, through a bijection of the sphere.
#include "spherekit/refine_correspondence.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <utility>

#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "detail/feature_warp.h"
#include "detail/kernel_point.h"
#include "detail/parallel_jobs.h"
#include "detail/sphere_embedding.h"
#include "detail/sphere_locator.h"
#include "detail/stage_util.h"
#include "spherekit/correspondence.h"
#include "spherekit/fill_holes.h"
#include "spherekit/geometry_image.h"
#include "spherekit/metrics.h"
#include "spherekit/predicates.h"

namespace spherekit {
namespace {

using Vec3 = Eigen::Vector3d;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Faces around each vertex of a mesh (CSR).
struct VertexFaces {
  std::vector<int> start, face;
  explicit VertexFaces(const TriMesh& m) {
    const int nv = static_cast<int>(m.V.rows());
    start.assign(static_cast<size_t>(nv) + 1, 0);
    for (Eigen::Index f = 0; f < m.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) ++start[static_cast<size_t>(m.F(f, c)) + 1];
    for (int v = 0; v < nv; ++v) start[static_cast<size_t>(v) + 1] += start[static_cast<size_t>(v)];
    face.resize(static_cast<size_t>(start.back()));
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (Eigen::Index f = 0; f < m.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) face[static_cast<size_t>(fill[static_cast<size_t>(m.F(f, c))]++)] = static_cast<int>(f);
  }
};

// What the fit needs of the template, made once per call: symmetric spoke weights
// (cotangent, clamped to a small positive floor so that the system stays positive definite
// on poor triangulations), the spokes as CSR, lumped vertex areas, the faces around each
// vertex, and each face's rest metric (for the symmetric Dirichlet shape check).
struct TemplateMetric {
  explicit TemplateMetric(const TriMesh& m) : faces(m) {}
  VertexFaces faces;
  std::vector<Eigen::Matrix2d> rest_inv;  // inverse Gram matrix of the face's edge vectors
  std::vector<double> rest_det_inv, rest_area;
  std::vector<int> start;   // CSR over vertices
  std::vector<int> nbr;
  std::vector<double> w;
  std::vector<double> area;  // a third of the incident faces' areas
  double total_area = 0;
  double mean_diag = 0;      // mean of the Laplacian's diagonal
  double mean_area = 0;
};

TemplateMetric template_metric(const TriMesh& m) {
  const int nv = static_cast<int>(m.V.rows());
  std::map<std::pair<int, int>, double> cot;
  TemplateMetric t(m);
  t.area.assign(static_cast<size_t>(nv), 0.0);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Vec3 p[3] = {m.V.row(m.F(f, 0)).transpose(), m.V.row(m.F(f, 1)).transpose(),
                       m.V.row(m.F(f, 2)).transpose()};
    const double a2 = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    t.total_area += 0.5 * a2;
    for (int c = 0; c < 3; ++c) {
      t.area[static_cast<size_t>(m.F(f, c))] += a2 / 6.0;
      // The angle at corner c is opposite edge (c+1, c+2).
      const Vec3 u = p[(c + 1) % 3] - p[c], v = p[(c + 2) % 3] - p[c];
      const double s = u.cross(v).norm();
      const double ct = s > 0 ? u.dot(v) / s : 0.0;
      const int a = m.F(f, (c + 1) % 3), b = m.F(f, (c + 2) % 3);
      cot[{std::min(a, b), std::max(a, b)}] += 0.5 * ct;
    }
  }
  double mean_w = 0;
  for (const auto& [e, c] : cot) mean_w += std::abs(c);
  mean_w = cot.empty() ? 1.0 : mean_w / static_cast<double>(cot.size());
  const double floor = 1e-2 * mean_w;
  std::vector<std::vector<std::pair<int, double>>> adj(static_cast<size_t>(nv));
  for (const auto& [e, c] : cot) {
    const double wt = std::max(c, floor);
    adj[static_cast<size_t>(e.first)].push_back({e.second, wt});
    adj[static_cast<size_t>(e.second)].push_back({e.first, wt});
  }
  t.start.push_back(0);
  double diag = 0;
  for (int v = 0; v < nv; ++v) {
    std::sort(adj[static_cast<size_t>(v)].begin(), adj[static_cast<size_t>(v)].end());
    for (const auto& [j, wt] : adj[static_cast<size_t>(v)]) {
      t.nbr.push_back(j);
      t.w.push_back(wt);
      diag += wt;
    }
    t.start.push_back(static_cast<int>(t.nbr.size()));
  }
  t.mean_diag = nv > 0 ? diag / nv : 1.0;
  t.mean_area = nv > 0 ? t.total_area / nv : 1.0;
  const Eigen::Index nfaces = m.F.rows();
  t.rest_inv.resize(static_cast<size_t>(nfaces));
  t.rest_det_inv.resize(static_cast<size_t>(nfaces));
  t.rest_area.resize(static_cast<size_t>(nfaces));
  for (Eigen::Index f = 0; f < nfaces; ++f) {
    const Vec3 a = m.V.row(m.F(f, 0)).transpose();
    const Vec3 e1 = Vec3(m.V.row(m.F(f, 1)).transpose()) - a, e2 = Vec3(m.V.row(m.F(f, 2)).transpose()) - a;
    Eigen::Matrix2d G;
    G << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
    const double det = G.determinant();
    t.rest_area[static_cast<size_t>(f)] = 0.5 * std::sqrt(std::max(det, 0.0));
    t.rest_inv[static_cast<size_t>(f)] = det > 0 ? Eigen::Matrix2d(G.inverse()) : Eigen::Matrix2d::Zero();
    t.rest_det_inv[static_cast<size_t>(f)] = det > 0 ? 1.0 / det : 0.0;
  }
  return t;
}

// Walks on the surface from `p` to a point locally nearest to `target`: moves to the
// nearest point of the faces around the current face's corners while that is nearer.
SurfacePoint walk_to_nearest(const TriMesh& m, const VertexFaces& vf, SurfacePoint p, const Vec3& target) {
  auto closest = [&](int f, Vec3& bary) {
    return detail::closest_point_on_triangle(target, m.V.row(m.F(f, 0)).transpose(), m.V.row(m.F(f, 1)).transpose(),
                                             m.V.row(m.F(f, 2)).transpose(), bary);
  };
  Vec3 bary;
  double best = (closest(p.face, bary) - target).squaredNorm();
  p.bary = bary;
  for (int step = 0; step < 256; ++step) {
    int best_face = -1;
    Vec3 best_bary;
    for (int c = 0; c < 3; ++c) {
      const int v = m.F(p.face, c);
      for (int k = vf.start[static_cast<size_t>(v)]; k < vf.start[static_cast<size_t>(v) + 1]; ++k) {
        const int g = vf.face[static_cast<size_t>(k)];
        if (g == p.face) continue;
        const double d = (closest(g, bary) - target).squaredNorm();
        if (d < best * (1 - 1e-12) - 1e-300) best = d, best_face = g, best_bary = bary;
      }
    }
    if (best_face < 0) break;
    p.face = best_face;
    p.bary = best_bary;
  }
  return p;
}

Vec3 sphere_point(const TriMesh& m, const RowMat3d& S, const SurfacePoint& p) {
  Vec3 s = Vec3::Zero();
  for (int c = 0; c < 3; ++c) s += p.bary[c] * S.row(m.F(p.face, c)).transpose();
  const double n = s.norm();
  return n > 0 ? Vec3(s / n) : Vec3(S.row(m.F(p.face, 0)).transpose());
}

// One member fitted to the template.
class MemberFit {
 public:
  MemberFit(const TriMesh& tmpl, const RowMat3d& St, const TemplateMetric& metric, const std::vector<int>& tfeat,
            const TriMesh& mesh, const VertexFaces& mesh_faces, const RowMat3d& Si, const std::vector<int>& feat,
            const RefineCorrespondenceOptions& o)
      : t_(tmpl), St_(St), metric_(metric), m_(mesh), Si_(Si), vf_(mesh_faces), o_(o) {
    const int nv = static_cast<int>(t_.V.rows());
    q_.resize(static_cast<size_t>(nv));
    sp_.resize(static_cast<size_t>(nv));
    Y_.resize(nv, 3);
    fixed_.assign(static_cast<size_t>(nv), 0);
    const SphereLocator locator(m_.F, Si_);
    for (int v = 0; v < nv; ++v) {
      q_[static_cast<size_t>(v)] = St_.row(v).transpose();
      const SphereLocation loc = locator.locate(q_[static_cast<size_t>(v)]);
      sp_[static_cast<size_t>(v)] = SurfacePoint{loc.face, loc.bary};
      if (!loc.inside) fixed_[static_cast<size_t>(v)] = 1;  // in a hole of the member: no surface to move on
    }
    for (size_t k = 0; k < tfeat.size(); ++k) {
      const int v = tfeat[k];
      sp_[static_cast<size_t>(v)] = vertex_surface_point(m_, feat[k]);
      fixed_[static_cast<size_t>(v)] = 1;
    }
    for (int v = 0; v < nv; ++v) Y_.row(v) = surface_position(m_, sp_[static_cast<size_t>(v)]).transpose();
  }

  // Runs the rounds (q() then holds one unit vector per template vertex).
  // Each round: best rotations for the current surface points (local step), then one
  // Gauss-Newton step of the rigidity energy with every free point moving in the tangent
  // plane of the member's surface at it (two unknowns per point; the step stays on the
  // surface to first order, so low-frequency slides, which the energy penalizes only
  // weakly, are not lost to motion off the surface), Levenberg-damped by `damping`; each
  // point then walks on the surface to the point nearest its stepped position.
  Status run(const std::function<bool()>& keep_going, double* e_before, double* e_after, int* crushed_after) {
    const int nv = static_cast<int>(t_.V.rows());
    std::vector<int> index(static_cast<size_t>(nv), -1);
    int nf = 0;
    for (int v = 0; v < nv; ++v)
      if (!fixed_[static_cast<size_t>(v)]) index[static_cast<size_t>(v)] = nf++;
    const double mu = o_.damping * metric_.mean_diag / metric_.mean_area;
    std::vector<Eigen::Matrix3d> R(static_cast<size_t>(nv));
    *e_before = sd_total();
    std::vector<Eigen::Matrix<double, 3, 2>> T(static_cast<size_t>(nv));
    std::vector<Eigen::Triplet<double>> trip;
    Eigen::VectorXd g(2 * nf);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
    for (int it = 0; it < o_.iterations && nf > 0; ++it) {
      if (!keep_going()) return Status(ErrorCode::Cancelled, "cancelled");
      rotations(R);
      for (int v = 0; v < nv; ++v) T[static_cast<size_t>(v)] = tangent_basis(sp_[static_cast<size_t>(v)].face);
      trip.clear();
      g.setZero();
      for (int v = 0; v < nv; ++v) {
        const int iv = index[static_cast<size_t>(v)];
        if (iv >= 0) {
          const double d = mu * metric_.area[static_cast<size_t>(v)];
          trip.emplace_back(2 * iv, 2 * iv, d);
          trip.emplace_back(2 * iv + 1, 2 * iv + 1, d);
        }
        const Vec3 xv = t_.V.row(v).transpose(), yv = Y_.row(v).transpose();
        for (int k = metric_.start[static_cast<size_t>(v)]; k < metric_.start[static_cast<size_t>(v) + 1]; ++k) {
          const int j = metric_.nbr[static_cast<size_t>(k)];
          if (j < v) continue;  // each spoke once
          const int ij = index[static_cast<size_t>(j)];
          const double wt = metric_.w[static_cast<size_t>(k)];
          const Vec3 c = (yv - Y_.row(j).transpose()) -
                         0.5 * (R[static_cast<size_t>(v)] + R[static_cast<size_t>(j)]) * (xv - t_.V.row(j).transpose());
          const auto& Tv = T[static_cast<size_t>(v)];
          const auto& Tj = T[static_cast<size_t>(j)];
          if (iv >= 0) {
            for (int a = 0; a < 2; ++a) trip.emplace_back(2 * iv + a, 2 * iv + a, wt);
            g.segment<2>(2 * iv) += wt * Tv.transpose() * c;
          }
          if (ij >= 0) {
            for (int a = 0; a < 2; ++a) trip.emplace_back(2 * ij + a, 2 * ij + a, wt);
            g.segment<2>(2 * ij) -= wt * Tj.transpose() * c;
          }
          if (iv >= 0 && ij >= 0) {
            const Eigen::Matrix2d B = -wt * Tv.transpose() * Tj;
            for (int a = 0; a < 2; ++a)
              for (int b = 0; b < 2; ++b) {
                trip.emplace_back(2 * iv + a, 2 * ij + b, B(a, b));
                trip.emplace_back(2 * ij + b, 2 * iv + a, B(a, b));
              }
          }
        }
      }
      Eigen::SparseMatrix<double> H(2 * nf, 2 * nf);
      H.setFromTriplets(trip.begin(), trip.end());
      if (it == 0) solver.analyzePattern(H);
      solver.factorize(H);
      if (solver.info() != Eigen::Success) return Status(ErrorCode::SolverFailed, "rigidity system is not positive definite");
      const Eigen::VectorXd step = solver.solve(-g);
      // Move all points together (a slide of a whole region keeps the template's spherical
      // triangulation valid only if its points move at once); points of faces that would be
      // inverted go back, until every face is positive (exact predicate), and those then try
      // 1/2 .. 1/32 of their step one at a time, in vertex order (deterministic). Only
      // inversion sends a point back: a check that also refused moves making a face's
      // symmetric Dirichlet density pass 32 (thin faces) sent a fifth of the points back in
      // every iteration on the TOSCA cats, cascading through their neighbours, so coherent
      // slides stalled (issue 19: faust5k 0.034/0.071/0.035 -> 0.032/0.064/0.034 evalcorr).
      std::vector<SurfacePoint> sp_new(sp_);
      std::vector<Vec3> q_new(q_);
      for (int v = 0; v < nv; ++v) {
        const int iv = index[static_cast<size_t>(v)];
        if (iv < 0) continue;
        const Vec3 target = Y_.row(v).transpose() + T[static_cast<size_t>(v)] * step.segment<2>(2 * iv);
        sp_new[static_cast<size_t>(v)] = walk_to_nearest(m_, vf_, sp_[static_cast<size_t>(v)], target);
        q_new[static_cast<size_t>(v)] = sphere_point(m_, Si_, sp_new[static_cast<size_t>(v)]);
      }
      std::vector<char> back(static_cast<size_t>(nv), 0);
      for (bool changed = true; changed;) {
        changed = false;
        for (Eigen::Index f = 0; f < t_.F.rows(); ++f) {
          Vec3 p[3];
          for (int c = 0; c < 3; ++c) {
            const int u = t_.F(f, c);
            p[c] = back[static_cast<size_t>(u)] ? q_[static_cast<size_t>(u)] : q_new[static_cast<size_t>(u)];
          }
          if (orient3d_origin(p[0], p[1], p[2]) > 0) continue;
          for (int c = 0; c < 3; ++c) {
            const int u = t_.F(f, c);
            if (!back[static_cast<size_t>(u)] && index[static_cast<size_t>(u)] >= 0) back[static_cast<size_t>(u)] = 1, changed = true;
          }
        }
      }
      for (int v = 0; v < nv; ++v) {
        if (index[static_cast<size_t>(v)] < 0 || back[static_cast<size_t>(v)]) continue;
        sp_[static_cast<size_t>(v)] = sp_new[static_cast<size_t>(v)];
        q_[static_cast<size_t>(v)] = q_new[static_cast<size_t>(v)];
        Y_.row(v) = surface_position(m_, sp_[static_cast<size_t>(v)]).transpose();
      }
      for (int v = 0; v < nv; ++v) {
        const int iv = index[static_cast<size_t>(v)];
        if (iv < 0 || !back[static_cast<size_t>(v)]) continue;
        const Vec3 delta = T[static_cast<size_t>(v)] * step.segment<2>(2 * iv);
        for (double f : {0.5, 0.25, 0.125, 0.0625, 0.03125}) {
          const Vec3 target = Y_.row(v).transpose() + f * delta;
          const SurfacePoint cand = walk_to_nearest(m_, vf_, sp_[static_cast<size_t>(v)], target);
          const Vec3 qc = sphere_point(m_, Si_, cand);
          if (valid_at(v, qc)) {
            sp_[static_cast<size_t>(v)] = cand;
            q_[static_cast<size_t>(v)] = qc;
            Y_.row(v) = surface_position(m_, cand).transpose();
            break;
          }
        }
      }
    }
    *e_after = sd_total(crushed_after);
    return Status();
  }


  // Symmetric Dirichlet energy of template face f carried onto the member (Y), with vertex
  // v moved to y; infinite for a crushed image. tr(G) + tr(G^-1) of the image metric G in
  // the face's rest frame: 4 for an isometry, a barrier against collapse.
  double sd_face(int f, int v, const Vec3& y) const {
    Vec3 p[3];
    for (int c = 0; c < 3; ++c) {
      const int u = t_.F(f, c);
      p[c] = u == v ? y : Vec3(Y_.row(u).transpose());
    }
    return metric_.rest_area[static_cast<size_t>(f)] * sd_density(f, p);
  }
  // Area-weighted mean over the faces not crushed: a face over a member's hole pressed onto
  // its rim has infinite energy, and the fit lets a face's image thin out (only inversions
  // are refused), so a face squeezed below about 1/10 of its size across some direction or
  // stretched 10x along one (density above kCrushedDensity) is left out and counted
  // instead: the report stays a number and measures the bulk of the surface.
  static constexpr double kCrushedDensity = 100;
  double sd_total(int* crushed = nullptr) const {
    double e = 0, a = 0;
    int n = 0;
    for (Eigen::Index f = 0; f < t_.F.rows(); ++f) {
      const double ef = sd_face(static_cast<int>(f), -1, Vec3::Zero());
      if (!(ef <= kCrushedDensity * metric_.rest_area[static_cast<size_t>(f)])) {
        ++n;
        continue;
      }
      e += ef;
      a += metric_.rest_area[static_cast<size_t>(f)];
    }
    if (crushed) *crushed = n;
    return a > 0 ? e / a : 0.0;
  }

  const std::vector<Vec3>& q() const { return q_; }

 private:
  // Best rotation per template vertex for the current Y (the ARAP local step).
  void rotations(std::vector<Eigen::Matrix3d>& R) const {
    const int nv = static_cast<int>(t_.V.rows());
    for (int v = 0; v < nv; ++v) {
      // Kabsch on the weighted spokes, C = sum of w (x_v - x_j)(y_v - y_j)^T: R = V U^T.
      Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
      const Vec3 xv = t_.V.row(v).transpose(), yv = Y_.row(v).transpose();
      for (int k = metric_.start[static_cast<size_t>(v)]; k < metric_.start[static_cast<size_t>(v) + 1]; ++k) {
        const int j = metric_.nbr[static_cast<size_t>(k)];
        C += metric_.w[static_cast<size_t>(k)] * (xv - t_.V.row(j).transpose()) * (yv - Y_.row(j).transpose()).transpose();
      }
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::Matrix3d U = svd.matrixU();
      Eigen::Matrix3d Rv = svd.matrixV() * U.transpose();
      if (Rv.determinant() < 0) {
        U.col(2) = -U.col(2);
        Rv = svd.matrixV() * U.transpose();
      }
      R[static_cast<size_t>(v)] = Rv;
    }
  }

  // Symmetric Dirichlet density of template face f's image p: tr(G) + tr(G^-1) of the image
  // metric G in the face's rest frame (4 for an isometry, infinite for a crushed image).
  double sd_density(int f, const Vec3* p) const {
    const Eigen::Matrix2d& Gi = metric_.rest_inv[static_cast<size_t>(f)];
    const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    Eigen::Matrix2d Gy;
    Gy << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
    const double d = Gy.determinant() * metric_.rest_det_inv[static_cast<size_t>(f)];
    if (!(d > 0)) return std::numeric_limits<double>::infinity();
    const double t = (Gi * Gy).trace();
    return t + t / d;
  }
  // Orthonormal basis of the plane of member face f.
  Eigen::Matrix<double, 3, 2> tangent_basis(int f) const {
    const Vec3 a = m_.V.row(m_.F(f, 0)).transpose(), b = m_.V.row(m_.F(f, 1)).transpose(),
               c = m_.V.row(m_.F(f, 2)).transpose();
    Vec3 n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) n = Vec3::UnitZ();
    n.normalize();
    Vec3 u = (b - a) - (b - a).dot(n) * n;
    if (!(u.norm() > 0)) u = n.unitOrthogonal();
    u.normalize();
    Eigen::Matrix<double, 3, 2> T;
    T.col(0) = u;
    T.col(1) = n.cross(u);
    return T;
  }

  // Every template face around v stays positively oriented with v at qc (exact predicate).
  bool valid_at(int v, const Vec3& qc) const {
    for (int k = metric_.faces.start[static_cast<size_t>(v)]; k < metric_.faces.start[static_cast<size_t>(v) + 1]; ++k) {
      const int f = metric_.faces.face[static_cast<size_t>(k)];
      Vec3 p[3];
      for (int c = 0; c < 3; ++c) {
        const int u = t_.F(f, c);
        p[c] = u == v ? qc : q_[static_cast<size_t>(u)];
      }
      if (orient3d_origin(p[0], p[1], p[2]) <= 0) return false;
    }
    return true;
  }

  const TriMesh& t_;
  const RowMat3d& St_;
  const TemplateMetric& metric_;
  const TriMesh& m_;
  const RowMat3d& Si_;
  const VertexFaces& vf_;
  const RefineCorrespondenceOptions& o_;
  std::vector<Vec3> q_;
  std::vector<SurfacePoint> sp_;
  RowMat3d Y_;
  std::vector<char> fixed_;
};

// Member i's map composed with psi^-1, where psi sends the template's sphere points St to
// Q (both triangulated by the template's faces). Features get their exact F.
// `inside[w]` is 0 where member vertex w falls in a hole of the template (no template face
// covers its sphere point there; its row is then only the nearest face's nearest point).
RowMat3d compose(const TriMesh& tmpl, const RowMat3d& St, const RowMat3d& Q, const RowMat3d& Si,
                 const std::vector<int>& feat, const std::vector<int>& tfeat, std::vector<char>* inside) {
  const SphereLocator locator(tmpl.F, Q);
  RowMat3d out(Si.rows(), 3);
  inside->assign(static_cast<size_t>(Si.rows()), 1);
  for (Eigen::Index w = 0; w < Si.rows(); ++w) {
    const SphereLocation loc = locator.locate(Si.row(w).transpose());
    (*inside)[static_cast<size_t>(w)] = loc.inside ? 1 : 0;
    Vec3 s = Vec3::Zero();
    for (int c = 0; c < 3; ++c) s += loc.bary[c] * St.row(tmpl.F(loc.face, c)).transpose();
    out.row(w) = s.normalized().transpose();
  }
  for (size_t k = 0; k < feat.size(); ++k) out.row(feat[k]) = St.row(tfeat[k]);
  return out;
}

// The stretch polish after a flow: the flow is smooth at the scale of its samples, and
// between them it leaves the member's map with stretch the member's own optimum did not
// have (FAUST members fell from 0.27-0.29 to 0.20-0.25 efficiency without it). A few final
// passes of the stretch optimizer (Praun & Hoppe 2003 §4, features fixed) take it out: they
// move vertices within their kernels only, so the result stays bijective, and converge
// locally, so the large-scale agreement the fit made stays (measured: the correspondence
// error does not grow). Holes are closed for the passes as the constrained stage closes
// them (fill_holes, low-weight fan faces, each centre in its fan's kernel); a hole whose loop
// is not star-shaped on the sphere (empty kernel) leaves the map unpolished (false).
// `closed` is fill_holes of the member, made once per member.
Result<bool> polish_stretch(const Result<FilledMesh>& closed, const std::vector<int>& feat, int passes,
                            const std::function<bool()>& keep_going, RowMat3d* S) {
  if (!closed.ok()) return closed.status();
  const FilledMesh& filled = *closed;
  const TriMesh& c = filled.mesh;
  RowMat3d Sc(c.V.rows(), 3);
  Sc.topRows(S->rows()) = *S;
  // Each hole's centre goes to a point of its fan's kernel (the fan's faces all positive).
  std::vector<std::vector<std::array<int, 2>>> rings(static_cast<size_t>(filled.holes));
  for (Eigen::Index f = filled.original_faces; f < c.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (c.F(f, k) >= filled.original_vertices)
        rings[static_cast<size_t>(c.F(f, k) - filled.original_vertices)].push_back({c.F(f, (k + 1) % 3), c.F(f, (k + 2) % 3)});
  for (int h = 0; h < filled.holes; ++h) {
    Vec3 mean = Vec3::Zero();
    for (int v : filled.loops[static_cast<size_t>(h)]) mean += S->row(v).transpose();
    Vec3 x;
    if (!(mean.norm() > 0) || !detail::kernel_point(Sc, rings[static_cast<size_t>(h)], mean, &x)) return false;
    Sc.row(filled.original_vertices + h) = x.transpose();
  }
  // The unconstrained stage's hole weights and effort preset, the collection stages' anti-cruft weight.
  const SphereParamOptions so = collection_sphere_options();
  detail::OptimizerSettings settings = detail::optimizer_settings(so);
  settings.final_iter = passes;
  settings.threads = 1;  // members are refined in parallel
  std::vector<double> w(static_cast<size_t>(c.F.rows()), 1.0), sw(static_cast<size_t>(c.F.rows()), 0.0);
  for (Eigen::Index f = filled.original_faces; f < c.F.rows(); ++f) {
    w[static_cast<size_t>(f)] = so.hole_weight;
    sw[static_cast<size_t>(f)] = so.hole_shape_weight;
  }
  std::vector<char> fixed(static_cast<size_t>(c.V.rows()), 0);
  for (int v : feat) fixed[static_cast<size_t>(v)] = 1;
  const RowMatXd P = c.V;
  SPHEREKIT_RETURN_IF_ERROR(detail::optimize_in_place(P, c.F, w, sw, fixed, settings,
                                                      [&](const ProgressEvent&) { return keep_going(); }, &Sc));
  *S = Sc.topRows(S->rows());
  return true;
}

constexpr int kMinSamples = 32;
constexpr double kMinEfficiencyRatio = 0.8;

std::string format_fixed(double x, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}

// Up to `count` well-spread vertices of the mesh in farthest-point order (straight distance,
// starting from the features, which are not returned): any prefix is itself the farthest-
// point sample of its size.
std::vector<int> surface_samples(const TriMesh& m, const std::vector<int>& feat, int count) {
  const Eigen::Index nv = m.V.rows();
  std::vector<double> d(static_cast<size_t>(nv), std::numeric_limits<double>::infinity());
  auto take = [&](int s) {
    for (Eigen::Index v = 0; v < nv; ++v) d[static_cast<size_t>(v)] = std::min(d[static_cast<size_t>(v)], (m.V.row(v) - m.V.row(s)).squaredNorm());
  };
  for (int f : feat) take(f);
  if (feat.empty()) take(0);
  std::vector<int> out;
  while (static_cast<int>(out.size()) < std::min<Eigen::Index>(count, nv - static_cast<Eigen::Index>(feat.size()))) {
    const int next = static_cast<int>(std::max_element(d.begin(), d.end()) - d.begin());
    if (!(d[static_cast<size_t>(next)] > 0)) break;
    out.push_back(next);
    take(next);
  }
  return out;
}

}  // namespace

Result<RefineCorrespondenceResult> refine_correspondence(const std::vector<TriMesh>& meshes,
                                                         const std::vector<std::vector<int>>& features,
                                                         std::vector<RowMat3d>& maps,
                                                         const RefineCorrespondenceOptions& options,
                                                         const ProgressFn& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  const int n = static_cast<int>(meshes.size());
  if (features.size() != meshes.size() || maps.size() != meshes.size())
    return Status(ErrorCode::InvalidArgument, "need one feature list and one map per mesh");
  const int t = options.template_mesh;
  if (t < 0 || t >= n) return Status(ErrorCode::InvalidArgument, "template " + std::to_string(t) + " is not a mesh index");
  if (options.iterations < 0 || !(options.damping > 0) || options.stretch_passes < 0 || options.snap_sweeps < 0 ||
      options.sample_growth < 1 || options.vertices_per_sample < 1)
    return Status(ErrorCode::InvalidArgument,
                  "iterations, stretch passes and snap sweeps must be >= 0, damping > 0, the sample growth and vertices "
                  "per sample >= 1");
  for (int i = 0; i < n; ++i) {
    if (maps[static_cast<size_t>(i)].rows() != meshes[static_cast<size_t>(i)].V.rows())
      return Status(ErrorCode::InvalidArgument, "mesh " + std::to_string(i) + ": map and mesh sizes differ");
    if (features[static_cast<size_t>(i)].size() != features[static_cast<size_t>(t)].size())
      return Status(ErrorCode::InvalidArgument, "mesh " + std::to_string(i) + ": feature count differs");
    for (int v : features[static_cast<size_t>(i)])
      if (v < 0 || v >= meshes[static_cast<size_t>(i)].V.rows())
        return Status(ErrorCode::InvalidArgument, "mesh " + std::to_string(i) + ": feature vertex out of range");
  }
  RefineCorrespondenceResult result;
  result.members.resize(static_cast<size_t>(n));
  result.members[static_cast<size_t>(t)].note = "template";
  const TriMesh& tmpl = meshes[static_cast<size_t>(t)];
  const TemplateMetric metric = template_metric(tmpl);
  const RowMat3d& St = maps[static_cast<size_t>(t)];
  std::vector<int> others;
  for (int i = 0; i < n; ++i)
    if (i != t) others.push_back(i);
  SPHEREKIT_ASSIGN_OR_RETURN(const SphereMapMetrics tm, evaluate_sphere_map(tmpl, St));
  const double template_efficiency = tm.efficiency;
  std::vector<RowMat3d> refined(static_cast<size_t>(n));
  const Status s = detail::run_parallel_jobs(
      static_cast<int>(others.size()), options.threads, "refine correspondence", progress,
      [&](int j, int, const std::function<bool()>& keep_going) -> Status {
        const int i = others[static_cast<size_t>(j)];
        const auto t0 = std::chrono::steady_clock::now();
        RefinedMember& rep = result.members[static_cast<size_t>(i)];
        const TriMesh& mi = meshes[static_cast<size_t>(i)];
        const std::vector<int>& fi = features[static_cast<size_t>(i)];
        RowMat3d cur = maps[static_cast<size_t>(i)];
        SPHEREKIT_ASSIGN_OR_RETURN(const SphereMapMetrics m0, evaluate_sphere_map(mi, cur));
        rep.efficiency_before = rep.efficiency_after = m0.efficiency;
        // The member's own unconstrained efficiency where known: measured from the step-6 map,
        // a member already at 0.81x its own lost another 0.8x (a generated creature's member
        // ended at 0.70x its own unconstrained efficiency, session 50).
        const double own = std::ssize(options.own_efficiency) > i && options.own_efficiency[static_cast<size_t>(i)] > 0
                               ? options.own_efficiency[static_cast<size_t>(i)]
                               : m0.efficiency;
        const double bar = std::min(own, template_efficiency);
        const VertexFaces mi_faces(mi);
        const Result<FilledMesh> mi_closed = fill_holes(mi);  // the polish's and the flow's relaxation's
        // Each round after the first flows onto sample_growth times as many samples as the
        // round before carried, up to max_samples (256, 512, 512): it starts from a map that
        // already agrees at the coarser scale, and its fit, closer than the last, holds finer
        // detail the flow can now carry (issue 19: every pair of five measured families 1-12%
        // lower error, 12-25% more time on FAUST and the cats, none on the others; 1024 in the
        // third round was better again where its flows went through, but on FAUST (all three
        // members) and the cats (two) they failed after 20-40 s each and 512 took over, 3x the
        // time). A round whose flow fails at its count halves it, as before, and the next grows
        // from what it carried. At most one sample per vertices_per_sample vertices: 512 of a
        // 700-vertex member's vertices failed to flow in every round and made the collection 5x
        // slower (1.8 -> 9.0 s) for nothing (FAUST's 1024 of 5k failed too; 512 of 5k and 1024
        // of 10-12.5k went through).
        const long long top = std::max<long long>(
            options.samples, std::min<long long>(options.max_samples, mi.V.rows() / options.vertices_per_sample));
        auto grown = [&](long long carried) { return std::min(carried * options.sample_growth, top); };
        long long most = options.samples;
        for (int r = 1; r < options.rounds; ++r) most = std::min(grown(most), static_cast<long long>(mi.V.rows()));
        const std::vector<int> spread = surface_samples(mi, fi, static_cast<int>(std::max<long long>(most, options.samples)));
        // (no more than the member has: a count beyond it would only take all of them twice)
        const long long have = std::max<long long>(options.samples, std::ssize(spread));
        int samples = options.samples;
        for (int round = 0; round < options.rounds; ++round) {
          if (round > 0) samples = static_cast<int>(std::min(grown(samples), have));
          MemberFit fit(tmpl, St, metric, features[static_cast<size_t>(t)], mi, mi_faces, cur, fi, options);
          double e0 = 0, e1 = 0;
          int crushed = 0;
          SPHEREKIT_RETURN_IF_ERROR(fit.run(keep_going, &e0, &e1, &crushed));
          if (round == 0) rep.energy_before = rep.energy_after = e0;
          RowMat3d Q(St.rows(), 3);
          for (Eigen::Index v = 0; v < St.rows(); ++v) Q.row(v) = fit.q()[static_cast<size_t>(v)].transpose();
          // The fitted correspondence, exact but rough at the template's triangle scale
          // (each point is stopped where a move would invert a face), is taken
          // at well-spread samples only, and the member's map flows onto those targets
          // smoothly (the feature warp: compactly supported radial-basis flow, every step
          // checked with the exact predicate), the features standing still. A flow that
          // cannot finish (a sliver it cannot carry) is tried again with half the samples.
          std::vector<char> inside;
          const RowMat3d Sc = compose(tmpl, St, Q, cur, fi, features[static_cast<size_t>(t)], &inside);
          Status st;
          RowMat3d S;
          const int round_samples = samples;
          int left_out = 0;
          int round_relaxations = 0;
          auto finished = [&] { return st.ok() || st.code() == ErrorCode::Cancelled || !keep_going(); };
          for (int attempt = 0; attempt < 2; ++attempt) {
            if (attempt == 1) {
              // The flow failed at every sample count. Where the fit folds the member's map
              // (composed faces inverted: the fit stops each point where a move would invert
              // a template face, not a member face) its partners ask for a fold no flow can
              // make, whichever samples carry them; those samples are left out and the counts
              // tried again. Only after a failure: on the shared families every flow succeeds,
              // and leaving these samples out always cost there (faust5k 0.022/0.034/0.020 ->
              // 0.025/0.036/0.022), while on a random creature family two of three members
              // kept their step-6 maps without it (0.057/0.063/0.058 -> 0.044/0.051/0.058).
              left_out = detail::leave_out_folded_samples(mi.F, Sc, spread, &inside);
              if (left_out == 0) break;
              samples = round_samples;
            }
            for (; samples >= kMinSamples; samples /= 2) {
              std::vector<int> W(spread.begin(), spread.begin() + std::min<std::ptrdiff_t>(samples, std::ssize(spread)));
              std::sort(W.begin(), W.end());
              std::vector<int> fv(fi);
              std::vector<Vec3> targets;
              for (int v : fv) targets.push_back(cur.row(v).transpose());
              for (int w : W)  // a sample in a hole of the template (or left out) has no partner: it is not a target
                if (inside[static_cast<size_t>(w)]) fv.push_back(w), targets.push_back(Sc.row(w).transpose());
              S = cur;
              // Where the flow stalls (a sliver it cannot carry however small the step), one
              // stretch pass with the features and samples held where they are spreads the
              // mesh out and the flow goes on, as the constrained stage's dense features do.
              const detail::WarpRelaxFn relax = [&](RowMat3d* R) -> Status {
                const Result<bool> r = polish_stretch(mi_closed, fv, 1, keep_going, R);
                if (!r.ok()) return r.status();
                return *r ? Status() : Status(ErrorCode::SolverFailed, "a hole's loop is not star-shaped on the sphere");
              };
              detail::WarpStats ws;
              st = detail::warp_features_to_targets(mi.V, mi.F, fv, targets, {}, &S, &ws, relax);
              round_relaxations = ws.relaxed;
              if (finished()) break;
            }
            if (finished()) break;
          }
          if (!keep_going()) return Status(ErrorCode::Cancelled, "cancelled");
          if (!st.ok()) {
            rep.note = "round " + std::to_string(round + 1) + ": " + st.message();
            break;
          }
          // The warp lands features on their normalized targets, which can differ from
          // the given unit vectors in the last bit: features stay exactly where they were
          // (also after the stretch passes, which hold them still).
          for (int v : fi) S.row(v) = cur.row(v);
          // Between the samples the flow's map is only a smooth blend of their moves, and the
          // stretch passes converge to the nearest local optimum: every vertex first steps
          // toward its own fitted partner (issue 19, session 50: faust5k 0.0205/0.0336/0.0193 ->
          // 0.0184/0.0319/0.0179 mean error, tosca_cat 0.0388/0.0169/0.0293 ->
          // 0.0375/0.0163/0.0287, ict_heads 0.0054/0.0072/0.0062 -> 0.0049/0.0068/0.0053,
          // efficiency within 2.6%; without the half-size floor one ICT member's first
          // round ended at 0.06 efficiency, slivers the passes could not open).
          int round_snaps = 0;
          if (options.snap_sweeps > 0) {
            std::vector<char> movable(inside);
            for (int v : fi) movable[static_cast<size_t>(v)] = 0;
            round_snaps = detail::snap_toward_targets(mi.F, Sc, movable, options.snap_sweeps, &S);
          }
          if (options.stretch_passes > 0) {
            RowMat3d Sp = S;
            const Result<bool> polished = polish_stretch(mi_closed, fi, options.stretch_passes, keep_going, &Sp);
            if (!keep_going()) return Status(ErrorCode::Cancelled, "cancelled");
            if (polished.ok() && *polished) {
              S = std::move(Sp);
              for (int v : fi) S.row(v) = cur.row(v);
            } else {  // the flow's map is valid as it is: taken unpolished, and said so
              rep.note = "round " + std::to_string(round + 1) + " not polished: " +
                         (polished.ok() ? std::string("a hole's loop is not star-shaped on the sphere") : polished.status().message());
            }
          }
          // Stretch is what the member's geometry image and every asset sample through: a
          // round that leaves less than kMinEfficiencyRatio of the starting efficiency is not
          // taken. The start is the lower of the member's and the template's: maps that agree
          // carry the template's distortion, so no member can be expected to end better
          // than the template is.
          SPHEREKIT_ASSIGN_OR_RETURN(const SphereMapMetrics m1, evaluate_sphere_map(mi, S));
          if (m1.flipped != 0 || m1.efficiency < kMinEfficiencyRatio * bar) {
            rep.note = "round " + std::to_string(round + 1) + " not taken: efficiency " + format_fixed(m1.efficiency, 4) +
                       " below 0.8 x " + format_fixed(bar, 4);
            break;
          }
          cur = std::move(S);
          rep.refined = true;
          rep.rounds = round + 1;
          rep.samples = samples;
          rep.folded_samples_left_out = left_out;
          rep.flow_relaxations += round_relaxations;
          rep.snap_moves += round_snaps;
          rep.energy_after = e1;
          rep.crushed_faces = crushed;
          rep.efficiency_after = m1.efficiency;
        }
        if (rep.refined) refined[static_cast<size_t>(i)] = std::move(cur);
        rep.seconds = seconds_since(t0);
        return Status();
      });
  SPHEREKIT_RETURN_IF_ERROR(s);
  for (int i : others)
    if (result.members[static_cast<size_t>(i)].refined) maps[static_cast<size_t>(i)] = std::move(refined[static_cast<size_t>(i)]);
  result.seconds = seconds_since(t_start);
  return result;
}

}  // namespace spherekit
