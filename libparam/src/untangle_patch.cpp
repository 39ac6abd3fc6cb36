// Patch untangling for spherical maps (see detail/untangle_patch.h).
//
// Why a planar chart: the gnomonic projection x -> x / (x . c) onto the tangent plane at c is
// a central projection, so for points in the open hemisphere about c the sign of
// orient3d(origin, a, b, d) equals the sign of the planar orientation of the projected
// points. Untangling the projected patch with its outline fixed therefore untangles the
// spherical one, and the planar problem has a robust solver: minimize
//   sum_t w_t (|J_t|^2 + lambda (det J_t^2 + 1)) / chi(det J_t, eps),
//   chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2,
// with eps driven to zero (Garanzha, Kaporin, Kudryavtseva, Protais, Ray, Sokolov 2021). For
// eps > 0 the energy is smooth and finite for inverted faces too; as eps shrinks, inverted
// faces become arbitrarily expensive and the minimizer leaves them.
#include "detail/untangle_patch.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <iterator>
#include <limits>

#include "spherekit/predicates.h"

namespace spherekit::detail {
namespace {

constexpr double kLambda = 0.1;       // weight of the area term against the shape term
constexpr double kMinCapCos = 0.26;   // patch must lie within ~75 degrees of its centre
constexpr int kMaxOuter = 60;
// Least relative decrease of eps per outer iteration. Garanzha et al. use 0.1; inverted
// slivers of a merged quad start far from valid (det J of -40 against the reference), and
// at 0.1 the barrier takes hundreds of rounds to bite.
constexpr double kMinSigma = 0.5;
constexpr int kMaxInner = 300;

struct PatchProblem {
  std::vector<std::array<int, 3>> face;  // local corner indices
  std::vector<Eigen::Matrix2d> M;        // inverse reference edge matrix, per face
  std::vector<double> w;                 // reference area weight, per face
  std::vector<Eigen::Vector2d> u;        // local positions (free ones are the unknowns)
  std::vector<int> var;                  // per local vertex: unknown index or -1
  int num_vars = 0;
};

// chi and its derivative, without the cancellation of d + sqrt(eps^2 + d^2) for d << -eps
// (which would make chi 0 and an inverted face's energy infinite).
double chi(double d, double eps) {
  const double root = std::sqrt(eps * eps + d * d);
  return d >= 0 ? 0.5 * (d + root) : 0.5 * eps * eps / (root - d);
}
double chi_derivative(double d, double eps) {
  const double root = std::sqrt(eps * eps + d * d);
  return d >= 0 ? 0.5 * (1 + d / root) : 0.5 * eps * eps / (root * (root - d));
}

// All local positions: the unknowns x for the free vertices, the fixed ones as they are.
std::vector<Eigen::Vector2d> positions(const PatchProblem& p, const Eigen::VectorXd& x) {
  std::vector<Eigen::Vector2d> u = p.u;
  for (size_t v = 0; v < u.size(); ++v)
    if (int k = p.var[v]; k >= 0) u[v] = x.segment<2>(2 * k);
  return u;
}

Eigen::Matrix2d jacobian(const PatchProblem& p, const std::vector<Eigen::Vector2d>& u, size_t t) {
  const auto& c = p.face[t];
  Eigen::Matrix2d du;
  du.col(0) = u[static_cast<size_t>(c[1])] - u[static_cast<size_t>(c[0])];
  du.col(1) = u[static_cast<size_t>(c[2])] - u[static_cast<size_t>(c[0])];
  return du * p.M[t];
}

// Energy and gradient at the unknowns x (2 per free vertex).
double energy(const PatchProblem& p, const Eigen::VectorXd& x, double eps, Eigen::VectorXd* grad) {
  const std::vector<Eigen::Vector2d> u = positions(p, x);
  if (grad) grad->setZero(x.size());
  double e = 0;
  for (size_t t = 0; t < p.face.size(); ++t) {
    const Eigen::Matrix2d J = jacobian(p, u, t);
    const double d = J.determinant();
    const double tr = J.squaredNorm();
    const double ch = chi(d, eps);
    const double num = tr + kLambda * (d * d + 1);
    const double f = num / ch;
    e += p.w[t] * f;
    if (!grad) continue;
    Eigen::Matrix2d cof;
    cof << J(1, 1), -J(1, 0), -J(0, 1), J(0, 0);
    const double dchi = chi_derivative(d, eps);
    const Eigen::Matrix2d G = ((2 * J + 2 * kLambda * d * cof) / ch - (f * dchi / ch) * cof) * p.w[t];
    const Eigen::Matrix2d GD = G * p.M[t].transpose();  // d f / d [u1 - u0, u2 - u0]
    const auto& c = p.face[t];
    const Eigen::Vector2d g1 = GD.col(0), g2 = GD.col(1);
    if (int k = p.var[static_cast<size_t>(c[1])]; k >= 0) grad->segment<2>(2 * k) += g1;
    if (int k = p.var[static_cast<size_t>(c[2])]; k >= 0) grad->segment<2>(2 * k) += g2;
    if (int k = p.var[static_cast<size_t>(c[0])]; k >= 0) grad->segment<2>(2 * k) -= g1 + g2;
  }
  return e;
}

double min_det(const PatchProblem& p, const Eigen::VectorXd& x) {
  const std::vector<Eigen::Vector2d> u = positions(p, x);
  double m = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < p.face.size(); ++t) m = std::min(m, jacobian(p, u, t).determinant());
  return m;
}

// Limited-memory BFGS with a backtracking (Armijo) line search; stops when the energy no
// longer decreases measurably.
void minimize(const PatchProblem& p, double eps, Eigen::VectorXd* x) {
  constexpr int kMemory = 8;
  std::deque<Eigen::VectorXd> s_hist, y_hist;
  Eigen::VectorXd g, g_new;
  double e = energy(p, *x, eps, &g);
  for (int it = 0; it < kMaxInner; ++it) {
    // Two-loop recursion for d = -H g.
    Eigen::VectorXd q = g;
    std::vector<double> alpha(s_hist.size());
    for (size_t i = s_hist.size(); i-- > 0;) {
      alpha[i] = s_hist[i].dot(q) / y_hist[i].dot(s_hist[i]);
      q -= alpha[i] * y_hist[i];
    }
    if (!s_hist.empty()) q *= s_hist.back().dot(y_hist.back()) / y_hist.back().squaredNorm();
    for (size_t i = 0; i < s_hist.size(); ++i) {
      const double beta = y_hist[i].dot(q) / y_hist[i].dot(s_hist[i]);
      q += s_hist[i] * (alpha[i] - beta);
    }
    Eigen::VectorXd d = -q;
    double slope = g.dot(d);
    if (!(slope < 0)) {
      d = -g;
      slope = -g.squaredNorm();
      s_hist.clear();
      y_hist.clear();
    }
    if (!(slope < 0)) return;  // stationary
    // A first step without curvature information moves the fastest vertex by 0.1 (the
    // patch has unit size).
    double step = s_hist.empty() ? std::min(1.0, 0.1 / d.cwiseAbs().maxCoeff()) : 1.0;
    Eigen::VectorXd x_new;
    double e_new = 0;
    bool accepted = false;
    for (int ls = 0; ls < 50; ++ls) {
      x_new = *x + step * d;
      e_new = energy(p, x_new, eps, &g_new);
      if (std::isfinite(e_new) && e_new <= e + 1e-4 * step * slope) {
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) return;
    Eigen::VectorXd s = x_new - *x, y = g_new - g;
    if (s.dot(y) > 1e-12 * s.norm() * y.norm()) {
      s_hist.push_back(std::move(s));
      y_hist.push_back(std::move(y));
      if (static_cast<int>(s_hist.size()) > kMemory) {
        s_hist.pop_front();
        y_hist.pop_front();
      }
    }
    const double drop = e - e_new;
    *x = std::move(x_new);
    g.swap(g_new);
    e = e_new;
    if (drop <= 1e-12 * std::abs(e)) return;
  }
}

}  // namespace

std::vector<int> grow_rings(const PatchMesh& mesh, std::vector<int> verts, int rings) {
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  // Ring by ring from the last ring's new vertices only (the neighbours of the others are in
  // the set already): the untangling sweeps grow up to 19 rings around every fold, which on a
  // small mesh is all of it, and re-sorting the whole set's neighbours each time was a third
  // of a failing constrained map's time (a 694-vertex member in the landmarks' sphere test).
  std::vector<int> frontier = verts, more, fresh, merged;
  for (int r = 0; r < rings && !frontier.empty(); ++r) {
    more.clear();
    for (int v : frontier)
      for (int f : (*mesh.vf)[static_cast<size_t>(v)])
        for (int w : (*mesh.F)[static_cast<size_t>(f)]) more.push_back(w);
    std::sort(more.begin(), more.end());
    more.erase(std::unique(more.begin(), more.end()), more.end());
    fresh.clear();
    std::set_difference(more.begin(), more.end(), verts.begin(), verts.end(), std::back_inserter(fresh));
    merged.clear();
    std::merge(verts.begin(), verts.end(), fresh.begin(), fresh.end(), std::back_inserter(merged));
    verts.swap(merged);
    frontier.swap(fresh);
  }
  return verts;
}

bool untangle_patch(const PatchMesh& mesh, const std::vector<Eigen::Vector3d>& X, const std::vector<char>& fixed,
                    const std::vector<int>& bad, int rings, RowMat3d* S, UntanglePatchStats* stats) {
  const auto& F = *mesh.F;
  const auto& vf = *mesh.vf;
  const size_t nv = vf.size();

  // The moving vertices: the bad faces' corners grown by `rings` face rings.
  std::vector<int> corners;
  for (int f : bad)
    for (int v : F[static_cast<size_t>(f)]) corners.push_back(v);
  const std::vector<int> grown = grow_rings(mesh, std::move(corners), rings);

  // Local numbering: the free vertices, then the other corners of their faces.
  std::vector<int> local(nv, -1), global;
  PatchProblem p;
  for (int v : grown)
    if (!fixed[static_cast<size_t>(v)]) {
      local[static_cast<size_t>(v)] = static_cast<int>(global.size());
      global.push_back(v);
    }
  p.num_vars = static_cast<int>(global.size());
  if (p.num_vars == 0) return false;
  std::vector<int> faces;
  for (int i = 0; i < p.num_vars; ++i)
    for (int f : vf[static_cast<size_t>(global[static_cast<size_t>(i)])])
      faces.push_back(f);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  for (int f : faces)
    for (int v : F[static_cast<size_t>(f)])
      if (local[static_cast<size_t>(v)] < 0) {
        local[static_cast<size_t>(v)] = static_cast<int>(global.size());
        global.push_back(v);
      }

  // Chart: gnomonic projection about the normalized centroid of the patch.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int v : global) c += S->row(v).transpose();
  if (!(c.norm() > 0)) return false;
  c.normalize();
  for (int v : global)
    if (!(S->row(v).dot(c) > kMinCapCos)) return false;
  Eigen::Vector3d e1 = std::abs(c.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  e1 = (e1 - e1.dot(c) * c).normalized();
  const Eigen::Vector3d e2 = c.cross(e1);
  std::vector<Eigen::Vector2d> u0(global.size());
  for (size_t i = 0; i < global.size(); ++i) {
    const Eigen::Vector3d s = S->row(global[i]).transpose();
    u0[i] = Eigen::Vector2d(s.dot(e1), s.dot(e2)) / s.dot(c);
  }
  // Unit size: total signed area of the patch in the chart is 1 (the outline is fixed, so
  // that area does not change while untangling).
  double area = 0;
  for (int f : faces) {
    const auto& q = F[static_cast<size_t>(f)];
    const Eigen::Vector2d a = u0[static_cast<size_t>(local[static_cast<size_t>(q[0])])];
    const Eigen::Vector2d b = u0[static_cast<size_t>(local[static_cast<size_t>(q[1])])];
    const Eigen::Vector2d d = u0[static_cast<size_t>(local[static_cast<size_t>(q[2])])];
    area += 0.5 * ((b - a).x() * (d - a).y() - (b - a).y() * (d - a).x());
  }
  if (!(area > 0)) return false;
  const double scale = 1 / std::sqrt(area);
  for (auto& q : u0) q *= scale;

  // Reference shapes from the mesh, scaled to the same total area.
  double ref_area = 0;
  std::vector<double> a3(faces.size());
  for (size_t t = 0; t < faces.size(); ++t) {
    const auto& q = F[static_cast<size_t>(faces[t])];
    const Eigen::Vector3d& x0 = X[static_cast<size_t>(q[0])];
    a3[t] = 0.5 * (X[static_cast<size_t>(q[1])] - x0).cross(X[static_cast<size_t>(q[2])] - x0).norm();
    ref_area += a3[t];
  }
  const double mean_area = faces.empty() ? 0 : ref_area / static_cast<double>(faces.size());
  if (!(mean_area > 0)) return false;
  // A degenerate reference face (a sliver of the input) is measured against an equilateral
  // triangle of the mean area instead.
  std::vector<Eigen::Matrix2d> R(faces.size());
  for (size_t t = 0; t < faces.size(); ++t) {
    const auto& q = F[static_cast<size_t>(faces[t])];
    if (a3[t] > 1e-6 * mean_area) {
      const Eigen::Vector3d x0 = X[static_cast<size_t>(q[0])];
      const Eigen::Vector3d a = X[static_cast<size_t>(q[1])] - x0, b = X[static_cast<size_t>(q[2])] - x0;
      const double la = a.norm();
      R[t] << la, a.dot(b) / la, 0, 2 * a3[t] / la;
    } else {
      a3[t] = mean_area;
      const double l = std::sqrt(4 * mean_area / std::sqrt(3.0));
      R[t] << l, 0.5 * l, 0, 0.5 * std::sqrt(3.0) * l;
    }
  }
  ref_area = 0;
  for (double a : a3) ref_area += a;
  const double ref_scale = 1 / std::sqrt(ref_area);
  for (size_t t = 0; t < faces.size(); ++t) {
    const auto& q = F[static_cast<size_t>(faces[t])];
    p.M.push_back((R[t] * ref_scale).inverse());
    p.w.push_back(a3[t] / ref_area);
    std::array<int, 3> lc{};
    for (int k = 0; k < 3; ++k) lc[static_cast<size_t>(k)] = local[static_cast<size_t>(q[static_cast<size_t>(k)])];
    p.face.push_back(lc);
  }
  p.u = u0;
  p.var.assign(global.size(), -1);
  Eigen::VectorXd x(2 * p.num_vars);
  for (int i = 0; i < p.num_vars; ++i) {
    p.var[static_cast<size_t>(i)] = i;
    x.segment<2>(2 * i) = u0[static_cast<size_t>(i)];
  }

  auto write_back = [&](const Eigen::VectorXd& sol, RowMat3d* out) {
    for (int i = 0; i < p.num_vars; ++i) {
      const Eigen::Vector2d q = sol.segment<2>(2 * i) / scale;
      out->row(global[static_cast<size_t>(i)]) = (c + q.x() * e1 + q.y() * e2).normalized().transpose();
    }
  };
  std::vector<int> check = faces;  // the faces around moved vertices, and the bad ones
  check.insert(check.end(), bad.begin(), bad.end());
  auto all_positive = [&](const RowMat3d& M) {
    for (int f : check) {
      const auto& q = F[static_cast<size_t>(f)];
      if (orient3d_origin(M.row(q[0]).data(), M.row(q[1]).data(), M.row(q[2]).data()) <= 0) return false;
    }
    return true;
  };

  if (stats) {
    stats->free_vertices = p.num_vars;
    stats->faces = static_cast<int>(faces.size());
  }
  double dmin = min_det(p, x);
  double eps = std::max(1e-4, 2 * std::abs(dmin));
  RowMat3d trial = *S;
  for (int outer = 0; outer < kMaxOuter; ++outer) {
    if (stats) stats->outer_iterations = outer + 1;
    const double e_before = energy(p, x, eps, nullptr);
    minimize(p, eps, &x);
    const double e_after = energy(p, x, eps, nullptr);
    dmin = min_det(p, x);
    if (dmin > 0) {
      write_back(x, &trial);
      if (all_positive(trial)) {
        *S = trial;
        return true;
      }
    }
    // The regularization update of Garanzha et al. (2021): shrink eps by the relative
    // energy decrease, faster while inverted faces remain.
    const double sigma = std::max(1 - e_after / e_before, kMinSigma);
    const double mu = (1 - sigma) * chi(dmin, eps);
    eps = dmin < mu ? std::max(2 * std::sqrt(mu * (mu - dmin)), 1e-13) : 1e-13;
  }
  return false;
}

}  // namespace spherekit::detail
