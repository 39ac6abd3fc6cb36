// First and second derivatives of a small face's stretch energy with respect to its moving
// corner, for the optimizer's Newton steps (Praun & Hoppe 2003 §4 energy, as gram_energy in
// stretch_optimizer.cpp evaluates it with edge-frame anti-cruft terms).
//
// Why analytic: a Newton step from central differences needs five ring evaluations besides
// the trial point, and those were about 70% of the unconstrained stage's time (issue 20,
// perf on the generated limb shapes). The energy of a face depends on the moving corner x
// only through the three domain Gram entries E11 = |e1|^2, E22 = |e2|^2, E12 = e1.e2
// (e1 = qa - x, e2 = qb - x), whose x-gradients are -2 e1, -2 e2, -(e1 + e2) and whose
// x-Hessians are all 2 I. So the chain rule needs the gradient and Hessian of the energy in
// (E11, E22, E12) only (GramJet), and on the sphere's tangent plane every E_i's Hessian is
// a multiple of the identity (gram_jet_to_tangent). Plain scalar code: the derivative of a
// face must cost no more than about two evaluations to pay off (Eigen 3x3 temporaries did not).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "detail/sphere_state.h"

namespace spherekit::detail {

/// A scalar function of (E11, E22, E12) with its gradient g and symmetric Hessian
/// h = (00, 11, 22, 01, 02, 12) there.
struct GramJet {
  double v = 0;
  double g[3] = {0, 0, 0};
  double h[6] = {0, 0, 0, 0, 0, 0};
};

namespace gram_jet {

/// h += k a a^T
inline void add_outer(double* h, const double* a, double k) {
  h[0] += k * a[0] * a[0];
  h[1] += k * a[1] * a[1];
  h[2] += k * a[2] * a[2];
  h[3] += k * a[0] * a[1];
  h[4] += k * a[0] * a[2];
  h[5] += k * a[1] * a[2];
}

/// h += k (a b^T + b a^T)
inline void add_sym(double* h, const double* a, const double* b, double k) {
  h[0] += 2 * k * a[0] * b[0];
  h[1] += 2 * k * a[1] * b[1];
  h[2] += 2 * k * a[2] * b[2];
  h[3] += k * (a[0] * b[1] + a[1] * b[0]);
  h[4] += k * (a[0] * b[2] + a[2] * b[0]);
  h[5] += k * (a[1] * b[2] + a[2] * b[1]);
}

/// acc += k * (f(j)) for f with value f0 and derivatives f1, f2 at j.v (chain rule).
inline void add_composed(GramJet& acc, const GramJet& j, double f0, double f1, double f2, double k) {
  acc.v += k * f0;
  for (int i = 0; i < 3; ++i) acc.g[i] += k * f1 * j.g[i];
  for (int i = 0; i < 6; ++i) acc.h[i] += k * f1 * j.h[i];
  add_outer(acc.h, j.g, k * f2);
}

/// Q = E11 E22 - E12^2 = |e1 x e2|^2 (four times the squared domain area).
inline GramJet area_jet(double E11, double E22, double E12) {
  GramJet q;
  q.v = E11 * E22 - E12 * E12;
  q.g[0] = E22;
  q.g[1] = E11;
  q.g[2] = -2 * E12;
  q.h[3] = 1;   // d2/dE11 dE22
  q.h[2] = -2;  // d2/dE12^2
  return q;
}

}  // namespace gram_jet

/// Energy of one small face for one model as gram_energy computes it with edge-frame cruft
/// terms, w (T/2 + reg) + mips with T = scale N / Q, added to *acc with its derivatives.
/// `s` is the ring face's record (RingScratch::surf, fields SurfField). Returns
/// false (acc unchanged) where the energy is not finite.
inline bool add_gram_energy_jet(double E11, double E22, double E12, const double* s, double scale, double reg_weight,
                                GramJet* acc) {
  using namespace gram_jet;
  const double Q = E11 * E22 - E12 * E12;
  if (!(Q > 1e-24 * E11 * E22)) return false;
  const double iQ = 1 / Q;
  const double gQ[3] = {E22, E11, -2 * E12};  // Hessian of Q: d2/dE11dE22 = 1, d2/dE12^2 = -2
  const double gN[3] = {s[kSurfG22], s[kSurfG11], -2 * s[kSurfG12]};  // N = E22 D11 + E11 D22 - 2 E12 D12 is linear in E
  const double N = E22 * s[kSurfG11] + E11 * s[kSurfG22] - 2 * E12 * s[kSurfG12];
  // T Q = scale N, differentiated once and twice:
  //   grad T = (scale grad N - T grad Q) / Q,
  //   Hess T = -(grad T grad Q^T + grad Q grad T^T + T Hess Q) / Q.
  const double T = scale * N * iQ;
  const double gT[3] = {(scale * gN[0] - T * gQ[0]) * iQ, (scale * gN[1] - T * gQ[1]) * iQ,
                        (scale * gN[2] - T * gQ[2]) * iQ};
  double hT[6] = {0, 0, 0, 0, 0, 0};
  add_sym(hT, gT, gQ, -iQ);
  hT[3] -= T * iQ;
  hT[2] += 2 * T * iQ;
  const double w = s[kSurfWeight] * (s[kSurfArea] + s[kSurfFloor]);
  // Result = kT * (T's jet) + sum alpha_k dir_k (gradient) + sum beta_k dir_k dir_k^T
  // (Hessian) + outer products of the branches m_k = T - a_k.
  //
  // Anti-cruft along the three edges: a_k = scale |d_k|^2 / L_k with L_k = |e_k|^2 = dir_k . E
  // (|e3|^2 = E11 + E22 - 2 E12), so grad a_k = -a_k / L_k dir_k and Hess a_k =
  // 2 a_k / L_k^2 dir_k dir_k^T; m_k = min(a_k, T - a_k), the branch gram_energy takes; the
  // term is reg_weight / 3 * sum m_k^-3 (f1 = -3 m^-4, f2 = 12 m^-5).
  double v = w * (0.5 * T);
  double kT = 0.5 * w;
  double alpha[3], beta[3];
  double h[6] = {0, 0, 0, 0, 0, 0};
  const double L[3] = {E11, E22, E11 + E22 - 2 * E12};
  const double num[3] = {s[kSurfG11], s[kSurfG22], s[kSurfG11] + s[kSurfG22] - 2 * s[kSurfG12]};
  const double kr = w * reg_weight / 3;
  double reg = 0;
  // The reciprocals of the three L_k and of the three m_k each from one division (divisions
  // dominate this function's cost; 1/x1 = x2 x3 / (x1 x2 x3)).
  const double iLLL = 1 / (L[0] * L[1] * L[2]);
  const double inv_L[3] = {L[1] * L[2] * iLLL, L[0] * L[2] * iLLL, L[0] * L[1] * iLLL};
  double a_k[3], m_k[3];
  bool along_k[3];
  for (int k = 0; k < 3; ++k) {
    a_k[k] = scale * num[k] * inv_L[k];
    along_k[k] = !(T - a_k[k] < a_k[k]);
    m_k[k] = along_k[k] ? a_k[k] : T - a_k[k];
    if (!(m_k[k] > 0)) return false;
  }
  const double iMMM = 1 / (m_k[0] * m_k[1] * m_k[2]);
  const double inv_m[3] = {m_k[1] * m_k[2] * iMMM, m_k[0] * m_k[2] * iMMM, m_k[0] * m_k[1] * iMMM};
  for (int k = 0; k < 3; ++k) {
    const double iL = inv_L[k];
    const double a = a_k[k];
    const double ga = -a * iL, ha = 2 * a * iL * iL;  // along dir_k
    const bool along = along_k[k];
    const double im = inv_m[k], f = im * im * im, f1 = -3 * f * im, f2 = 12 * f * im * im;
    reg += f;
    if (along) {
      alpha[k] = kr * f1 * ga;
      beta[k] = kr * (f1 * ha + f2 * ga * ga);
    } else {
      kT += kr * f1;
      alpha[k] = -kr * f1 * ga;
      beta[k] = -kr * f1 * ha;
      const double gm[3] = {gT[0] - (k != 1 ? ga : 0), gT[1] - (k != 0 ? ga : 0), gT[2] - (k == 2 ? -2 * ga : 0)};
      add_outer(h, gm, kr * f2);
    }
  }
  v += kr * reg;
  double g[3] = {kT * gT[0] + alpha[0] + alpha[2], kT * gT[1] + alpha[1] + alpha[2], kT * gT[2] - 2 * alpha[2]};
  for (int i = 0; i < 6; ++i) h[i] += kT * hT[i];
  // dir_0 dir_0^T = e00, dir_1 dir_1^T = e11, dir_2 = (1, 1, -2).
  h[0] += beta[0] + beta[2];
  h[1] += beta[1] + beta[2];
  h[2] += 4 * beta[2];
  h[3] += beta[2];
  h[4] -= 2 * beta[2];
  h[5] -= 2 * beta[2];
  if (s[kSurfShape] != 0) {
    // MIPS T / (2 sqrt D) with D = (2 A_surf scale)^2 / Q, i.e. k N r with r = Q^-1/2:
    // grad r = -r/(2Q) grad Q, Hess r = 3r/(4Q^2) grad Q grad Q^T - r/(2Q) Hess Q.
    if (!(s[kSurfArea] > 0)) return false;
    const double k = s[kSurfShape] / (4 * s[kSurfArea]);
    const double r = std::sqrt(iQ);
    const double c1 = -0.5 * r * iQ;
    const double gr[3] = {c1 * gQ[0], c1 * gQ[1], c1 * gQ[2]};
    v += k * N * r;
    for (int i = 0; i < 3; ++i) g[i] += k * (N * gr[i] + r * gN[i]);
    add_outer(h, gQ, k * N * 0.75 * r * iQ * iQ);
    h[3] += k * N * c1;
    h[2] -= 2 * k * N * c1;
    add_sym(h, gN, gr, k);
  }
  if (!std::isfinite(v)) return false;
  acc->v += v;
  for (int i = 0; i < 3; ++i) acc->g[i] += g[i];
  for (int i = 0; i < 6; ++i) acc->h[i] += h[i];
  return true;
}

/// Adds the tangent gradient and Hessian at the unit point x, on the chart
/// y(u, w) = normalize(x + u t1 + w t2), of a face energy given as a GramJet in
/// (E11, E22, E12), e1 = qa - x, e2 = qb - x. With G_i the tangent components of grad E_i
/// (-2 e1, -2 e2, -(e1 + e2)) and d2y/du_i du_j = -delta_ij x at the origin:
/// Hess = sum phi_ij G_i G_j^T + sum phi_i (2 - grad E_i . x) I.
inline void gram_jet_to_tangent(const GramJet& j, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2,
                                const Eigen::Vector3d& x, const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                                Eigen::Vector2d* g, Eigen::Matrix2d* H) {
  const double a0 = t1.dot(e1), a1 = t2.dot(e1), b0 = t1.dot(e2), b1 = t2.dot(e2);
  const double G[3][2] = {{-2 * a0, -2 * a1}, {-2 * b0, -2 * b1}, {-(a0 + b0), -(a1 + b1)}};
  const double xa = x.dot(e1), xb = x.dot(e2);
  const double diag = j.g[0] * (2 + 2 * xa) + j.g[1] * (2 + 2 * xb) + j.g[2] * (2 + xa + xb);
  // Phi as a full 3x3 from the symmetric storage, then G Phi G^T.
  const double P[3][3] = {{j.h[0], j.h[3], j.h[4]}, {j.h[3], j.h[1], j.h[5]}, {j.h[4], j.h[5], j.h[2]}};
  double GP[2][3];
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) GP[r][c] = G[0][r] * P[0][c] + G[1][r] * P[1][c] + G[2][r] * P[2][c];
  const double h00 = GP[0][0] * G[0][0] + GP[0][1] * G[1][0] + GP[0][2] * G[2][0];
  const double h11 = GP[1][0] * G[0][1] + GP[1][1] * G[1][1] + GP[1][2] * G[2][1];
  const double h01 = GP[0][0] * G[0][1] + GP[0][1] * G[1][1] + GP[0][2] * G[2][1];
  (*g)(0) += j.g[0] * G[0][0] + j.g[1] * G[1][0] + j.g[2] * G[2][0];
  (*g)(1) += j.g[0] * G[0][1] + j.g[1] * G[1][1] + j.g[2] * G[2][1];
  (*H)(0, 0) += h00 + diag;
  (*H)(1, 1) += h11 + diag;
  (*H)(0, 1) += h01;
  (*H)(1, 0) += h01;
}

}  // namespace spherekit::detail
