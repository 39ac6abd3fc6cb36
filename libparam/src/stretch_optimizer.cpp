// Kernel-constrained stretch minimization on the sphere.
//   Sander, Snyder, Gortler, Hoppe 2001, "Texture mapping progressive meshes" (L2 stretch,
//     random-direction line searches constrained to the kernel);
//   Praun & Hoppe 2003, "Spherical parametrization and remeshing" §4 (the sphere -> surface
//     stretch on chord triangles, the anti-sliver regularizer, global passes per level);
//   Brent 1973, "Algorithms for minimization without derivatives" (the 1-D search).
//
// Energy of a face with sphere corners q0,q1,q2 (its chord triangle is the domain) and
// surface corners p0,p1,p2, per model with the surface rescaled to area 4 pi:
//   E_f = (A_f / A) * [ (a' + c')/2 + w * min(a', c')^-3 ]   (the last term averaged over
//   the three edge frames, see cruft_term)
// where a' = |dP/ds|^2, c' = |dP/dt|^2 in an orthonormal frame of the chord triangle.
// The first term is Sander et al.'s squared L2 stretch weighted by surface area (the
// quantity the efficiency measures); the second keeps sphere triangles from ballooning over
// tiny surface regions ("cruft"), as the 2003 paper's inverse-stretch regularizer does.
//
// Bijectivity: a move of vertex v is searched only inside its kernel (every ring face keeps
// det[x, qa, qb] > 0), and accepted only after the exact predicate confirms it. Moves in a
// round form an independent set (no two moved vertices share a face), so every face has at
// most one moving corner and the per-vertex checks are sufficient.
#include <algorithm>
#include <span>
#include <cmath>
#include <limits>

#include "detail/gram_derivatives.h"
#include "detail/sphere_state.h"
#include "detail/worker_pool.h"
#include "spherekit/predicates.h"


namespace spherekit::detail {
namespace {


constexpr double kFourPi = 4.0 * M_PI;
constexpr double kInf = std::numeric_limits<double>::infinity();

// SplitMix64: a stateless hash, so the random direction of a vertex depends only on
// (seed, pass, round, vertex) and never on thread scheduling.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double unit_random(std::uint64_t key) { return static_cast<double>(mix(key) >> 11) * 0x1.0p-53; }


// Brent's method (parabolic interpolation with golden-section fallback) on [lo, hi],
// starting from x0 with known f(x0). Returns the best point found within `max_eval`
// evaluations of f.
template <class Fn>
double brent_minimize(Fn&& f, double lo, double hi, double x0, double f0, int max_eval, double* fbest) {
  const double kGolden = 0.3819660112501051;  // (3 - sqrt 5) / 2
  const double tol_abs = 1e-4 * (hi - lo);     // x-tolerance relative to the interval
  double a = lo, b = hi;
  double x = x0, w = x0, v = x0, fx = f0, fw = f0, fv = f0;
  double d = 0, e = 0;
  for (int it = 0; it < max_eval; ++it) {
    double xm = 0.5 * (a + b);
    double tol1 = tol_abs, tol2 = 2 * tol1;
    if (std::abs(x - xm) <= tol2 - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol1) {
      double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      double etemp = e;
      e = d;
      if (!(std::abs(p) >= std::abs(0.5 * q * etemp) || p <= q * (a - x) || p >= q * (b - x))) {
        d = p / q;
        double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = xm >= x ? tol1 : -tol1;
        golden = false;
      }
    }
    if (golden) {
      e = x >= xm ? a - x : b - x;
      d = kGolden * e;
    }
    double u = std::abs(d) >= tol1 ? x + d : x + (d >= 0 ? tol1 : -tol1);
    double fu = f(u);
    if (fu <= fx) {
      if (u >= x) a = x; else b = x;
      v = w; fv = fw; w = x; fw = fx; x = u; fx = fu;
    } else {
      if (u < x) a = u; else b = u;
      if (fu <= fw || w == x) {
        v = w; fv = fw; w = u; fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u; fv = fu;
      }
    }
  }
  *fbest = fx;
  return x;
}

// Feasible interval (lo, hi) around t = 0 of x(t) = x0 cos t + d sin t for the ring's kernel
// constraints n . x(t) > 0. Each constraint n.x0 cos t + n.d sin t = R cos(t - phi) > 0
// allows t in (phi - pi/2, phi + pi/2); n.x0 > 0 at t = 0 puts phi in (-pi/2, pi/2).
bool feasible_interval(const RingScratch& ring, const Eigen::Vector3d& x0, const Eigen::Vector3d& d,
                       double* lo, double* hi) {
  // Face k allows the angles (phi_k - pi/2, phi_k + pi/2), phi_k = atan2(beta_k, alpha_k) with
  // alpha_k > 0, monotone in beta_k / alpha_k: the interval's ends come from the largest and
  // the smallest ratio (compared by cross-multiplication), with two arc tangents per call
  // instead of one per face.
  double amax = 1, bmax = -kInf, amin = 1, bmin = kInf;  // (alpha, beta) of the extreme ratios
  for (const auto& rf : ring.faces) {
    const double alpha = rf.n.dot(x0), beta = rf.n.dot(d);
    if (!(alpha > 0)) return false;  // current position not strictly inside (rounding)
    if (beta * amax > bmax * alpha) amax = alpha, bmax = beta;
    if (beta * amin < bmin * alpha) amin = alpha, bmin = beta;
  }
  const double l = std::max(-M_PI / 2, std::atan2(bmax, amax) - M_PI / 2);
  const double h = std::min(M_PI / 2, std::atan2(bmin, amin) + M_PI / 2);
  if (!(h > 0 && l < 0)) return false;
  // Pad inward by 1% at each end so no triangle can fully collapse (Praun & Hoppe's margin).
  double pad = 0.01 * (h - l);
  *lo = l + pad;
  *hi = h - pad;
  // A vertex already inside the margin (next to a squeezed face) may still move away from
  // the constraint it is close to: shrink the margin on that side instead of refusing the
  // whole direction, or the vertices of a squeezed face could never move again.
  if (!(*lo < 0)) *lo = 0.5 * l;
  if (!(*hi > 0)) *hi = 0.5 * h;
  return *lo < 0 && *hi > 0;
}

}  // namespace

void tangent_basis(const Eigen::Vector3d& x, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  Eigen::Vector3d a = std::abs(x.x()) < 0.6 ? Eigen::Vector3d::UnitX()
                      : std::abs(x.y()) < 0.6 ? Eigen::Vector3d::UnitY()
                                               : Eigen::Vector3d::UnitZ();
  e1 = (a - x * x.dot(a)).normalized();
  e2 = x.cross(e1);
}

void SphereState::update_areas() {
  model_area.assign(static_cast<size_t>(models), 0.0);
  for (size_t f = 0; f < F.size(); ++f) {
    if (!face_alive[f]) continue;
    for (int m = 0; m < models; ++m) {
      Eigen::Vector3d p0 = P->row(F[f][0]).segment<3>(3 * m).transpose();
      Eigen::Vector3d p1 = P->row(F[f][1]).segment<3>(3 * m).transpose();
      Eigen::Vector3d p2 = P->row(F[f][2]).segment<3>(3 * m).transpose();
      model_area[static_cast<size_t>(m)] += 0.5 * (p1 - p0).cross(p2 - p0).norm() * face_weight[f];
    }
  }
  int alive = 0;
  for (char a : face_alive) alive += a ? 1 : 0;
  area_floor.assign(static_cast<size_t>(models), 0.0);
  for (int m = 0; m < models; ++m) {
    double& a = model_area[static_cast<size_t>(m)];
    if (!(a > 0)) a = 1.0;  // a fully degenerate level (cannot happen for valid input)
    area_floor[static_cast<size_t>(m)] = area_floor_rel * a / std::max(1, alive);
  }
  average_face_area.resize(model_area.size());
  for (size_t m = 0; m < model_area.size(); ++m) average_face_area[m] = model_area[m] / std::max(1, alive);
  model_scale.resize(model_area.size());
  for (size_t m = 0; m < model_area.size(); ++m) model_scale[m] = kFourPi / model_area[m];
  update_hole_area_penalty();
}

void SphereState::update_hole_area_penalty() {
  // The measured efficiency of a mesh with holes is normalized by the sphere (chord) area its
  // real faces cover, E_norm = E_real * D_real: covering more of the sphere earns nothing.
  // The plain energy E_real instead rewards real faces for eating the hole's area, which
  // squeezes the rim circumferentially. Locally, d(E D) = D dE + E dD, so each real face also
  // pays lambda = E / D per unit of chord area (lambda held fixed during a level).
  // Without holes the same holds wherever the energy is the measured one (chord_area_penalty:
  // the full-resolution pass): the chord triangles of a closed map cover an area that is not
  // 4 pi (a spherical triangle's chord triangle is smaller, a sliver along a great circle has a
  // chord triangle larger than itself), and the plain energy is lowered by spreading chord
  // area that the measure takes back. Issue 20, on meshes with large triangles: skin_star
  // (Blender Skin modifier, 7.8k vertices) ended at 61.5 plain energy and chord area 13.45
  // (efficiency 0.1925) where the reference's map has 64.2 and 12.70 (0.1955).
  hole_area_penalty = 0;
  bool holes = false;
  for (size_t f = 0; f < face_shape_weight.size() && !holes; ++f) holes = face_alive[f] && face_shape_weight[f] > 0;
  if (!holes && !chord_area_penalty) return;
  double E = 0, D = 0;
  for (size_t f = 0; f < F.size(); ++f) {
    if (!face_alive[f] || (!face_shape_weight.empty() && face_shape_weight[f] > 0)) continue;
    Eigen::Vector3d q0 = S.row(F[f][0]).transpose(), q1 = S.row(F[f][1]).transpose(), q2 = S.row(F[f][2]).transpose();
    Eigen::Vector3d e1 = q1 - q0, e2 = q2 - q0;
    double E11 = e1.squaredNorm(), E22 = e2.squaredNorm(), E12 = e1.dot(e2);
    double four_a2 = E11 * E22 - E12 * E12;
    if (!(four_a2 > 0)) continue;
    D += 0.5 * std::sqrt(four_a2);
    for (int m = 0; m < models; ++m) {
      Eigen::Vector3d p0 = P->row(F[f][0]).segment<3>(3 * m).transpose();
      Eigen::Vector3d d1 = P->row(F[f][1]).segment<3>(3 * m).transpose() - p0;
      Eigen::Vector3d d2 = P->row(F[f][2]).segment<3>(3 * m).transpose() - p0;
      double T = gram_frobenius_numerator(E11, E22, E12, d1.squaredNorm(), d2.squaredNorm(), d1.dot(d2)) / four_a2 *
                 model_scale[static_cast<size_t>(m)];
      E += face_weight[f] * 0.5 * d1.cross(d2).norm() / model_area[static_cast<size_t>(m)] * 0.5 * T;
    }
  }
  if (D > 0) hole_area_penalty = E / D;
}

OptimizerSettings settings_for_effort(int effort) {
  // The reference implementation's presets (REFERENCE.md §2.5), with two measured changes:
  // vertex moves are safeguarded Newton steps (falling back to Brent searches along random
  // great circles), which reach the same efficiency with fewer energy evaluations, and so
  // effort 2 needs two passes per level instead of three (measured on the shared dev meshes:
  // same efficiency within 0.002, about 35% less work). Effort 2 also judges convergence
  // relative to the local triangle size alone (movetol_rel; no absolute cap, movetol = 1):
  // a vertex is converged when its moves are small against its own triangles, so coarse
  // levels (half the work before) stop at their own precision and the work goes where
  // triangles are small on the sphere (thin limbs). Issue 20, generated limb shapes: an
  // absolute cap of 5e-4 doubled the CPU time for the same efficiency (0.3529 vs 0.3530).
  OptimizerSettings s;
  s.newton = true;
  switch (std::clamp(effort, 0, 5)) {
    case 0: s.line_search_iter = 6;   s.vsplit_vt_iter = 1; s.vsplit_nei_iter = 0;  s.global_iter = 1;  s.movetol = 1e-2; s.nv_ratio = 1.7;  break;
    case 1: s.line_search_iter = 8;   s.vsplit_vt_iter = 1; s.vsplit_nei_iter = 0;  s.global_iter = 1;  s.movetol = 5e-3; s.nv_ratio = 1.25; break;
    case 2: s.line_search_iter = 10;  s.vsplit_vt_iter = 2; s.vsplit_nei_iter = 0;  s.global_iter = 2;  s.movetol = 1.0;  s.nv_ratio = 1.2;  s.movetol_rel = 0.02; break;
    case 3: s.line_search_iter = 40;  s.vsplit_vt_iter = 3; s.vsplit_nei_iter = 3;  s.global_iter = 5;  s.movetol = 1e-3; s.nv_ratio = 1.1;  break;
    case 4: s.line_search_iter = 100; s.vsplit_vt_iter = 5; s.vsplit_nei_iter = 5;  s.global_iter = 8;  s.movetol = 5e-4; s.nv_ratio = 1.05; break;
    default: s.line_search_iter = 200; s.vsplit_vt_iter = 5; s.vsplit_nei_iter = 20; s.global_iter = 20; s.movetol = 3e-4; s.nv_ratio = 1.04; break;
  }
  s.final_iter = s.global_iter;
  // Rounds by colour classes (optimize_all): measured side by side on gargoyle 4.2 -> 2.5 CPU s
  // at the same efficiency; on the generated limb shapes with holes, where the greedy rounds
  // wasted most moves, tentacles-holes 0.0899 -> 0.1577 in 63 -> 26 s.
  s.coloured_rounds = true;
  return s;
}

bool load_ring(const SphereState& st, int v, RingScratch& ring, const RingIndex* index) {
  const int* indexed_faces = nullptr;
  const int* indexed_corners = nullptr;
  size_t count;
  if (index) {
    const int b = index->start[static_cast<size_t>(v)];
    count = static_cast<size_t>(index->start[static_cast<size_t>(v) + 1] - b);
    indexed_faces = index->faces.data() + b;
    indexed_corners = index->corners.data() + 2 * static_cast<size_t>(b);
  } else {
    count = st.vf[static_cast<size_t>(v)].size();
  }
  ring.faces.resize(count);
  ring.surf.resize(count * static_cast<size_t>(st.models) * kSurfStride);
  const RowMatXd& P = *st.P;
  for (size_t i = 0; i < count; ++i) {
    auto& rf = ring.faces[i];
    if (index) {
      rf.f = indexed_faces[i];
      rf.a = indexed_corners[2 * i];
      rf.b = indexed_corners[2 * i + 1];
    } else {
      const int f = st.vf[static_cast<size_t>(v)][i];
      const auto& c = st.F[static_cast<size_t>(f)];
      const int k = c[0] == v ? 0 : c[1] == v ? 1 : 2;
      rf.f = f;
      rf.a = c[(k + 1) % 3];
      rf.b = c[(k + 2) % 3];
    }
    const int f = rf.f;
    rf.qa = st.S.row(rf.a).transpose();
    rf.qb = st.S.row(rf.b).transpose();
    rf.n = rf.qa.cross(rf.qb);
    rf.real = st.face_shape_weight.empty() || !(st.face_shape_weight[static_cast<size_t>(f)] > 0);
    for (int m = 0; m < st.models; ++m) {
      double* s = &ring.surf[(i * static_cast<size_t>(st.models) + static_cast<size_t>(m)) * kSurfStride];
      const Eigen::Vector3d pv = P.row(v).segment<3>(3 * m).transpose();
      const Eigen::Vector3d d1 = P.row(rf.a).segment<3>(3 * m).transpose() - pv;
      const Eigen::Vector3d d2 = P.row(rf.b).segment<3>(3 * m).transpose() - pv;
      s[kSurfWeight] = st.face_weight[static_cast<size_t>(f)] / st.model_area[static_cast<size_t>(m)];
      s[kSurfFloor] = st.area_floor[static_cast<size_t>(m)];
      s[kSurfG11] = d1.squaredNorm();
      s[kSurfG22] = d2.squaredNorm();
      s[kSurfG12] = d1.dot(d2);
      s[kSurfArea] = 0.5 * d1.cross(d2).norm();
      // The shape term has the weight of an average face of the level, whatever the hole
      // face's own area: a hole's filling can be as large as the model (a flat shape's
      // back) or tiny, and its pull must not depend on that. MIPS is scale-free, so the
      // hole may still shrink freely on the sphere.
      s[kSurfShape] = st.face_shape_weight.empty()
                          ? 0.0
                          : st.face_shape_weight[static_cast<size_t>(f)] * st.average_face_area[static_cast<size_t>(m)] /
                                st.model_area[static_cast<size_t>(m)];
    }
  }
  return count > 0;
}

namespace {

// Praun & Hoppe's anti-cruft term (REFERENCE.md §2.4): w * min(a, c)^-3, a and c the squared
// stretches along and across one edge of the domain triangle. The reference takes the frame
// of the face's first edge, so its term depends on how the face is numbered; here it is the
// mean over the three edge frames, which is independent of numbering (every corner of a face
// optimizes the same function) and of the reference's size. Along edge k, a_k = |d_k|^2 /
// |e_k|^2 (surface over domain edge length, squared) and c_k = T - a_k, since a + c = |J|_F^2
// = T in every orthonormal frame. Why not the smallest squared singular value g (used
// before): g <= min(a_k, c_k) for every k, so at the reference's weight g^-3 was a stronger
// term than the weight was chosen for, up to several times on anisotropic maps (thin limbs),
// where it held the sphere back from the measured optimum (issue 20, measured side by side
// with the reference at one thread: generated limb shapes standing 0.3359 -> 0.3454 and
// quadruped 0.3153 -> 0.3243, the reference 0.3352 and 0.3176; armadillo 0.4170 -> 0.4235,
// horse 0.3934 -> 0.4005, the reference 0.4127 and 0.3928).
// The three reciprocals come from one division (1/m1 = m2 m3 / (m1 m2 m3)): this term is
// evaluated for every face at every trial point, and divisions dominate its cost.
inline double cruft_term(double T, double a1, double a2, double a3, double reg_weight) {
  const double m1 = std::min(a1, T - a1), m2 = std::min(a2, T - a2), m3 = std::min(a3, T - a3);
  if (!(m1 > 0 && m2 > 0 && m3 > 0)) return kInf;
  const double inv = 1 / (m1 * m2 * m3);
  const double r1 = m2 * m3 * inv, r2 = m1 * m3 * inv, r3 = m1 * m2 * inv;
  return reg_weight * (r1 * r1 * r1 + r2 * r2 * r2 + r3 * r3 * r3) / 3;
}

// The anti-cruft term as the collection stages use it: w * g^-3, g the smallest squared
// singular value (2 D / (T + sqrt(T^2 - 4 D)), D = det J^T J), rotation-invariant and never
// below the edge-frame mean above. The constrained and consistent stages keep it: their
// feature paths, dense-set warps and Steiner removal were built and measured with it, and
// with the weaker term the shared faust5k 64-landmark collection no longer completed within
// minutes, and tosca_cat's correspondence fell (cat0 -> cat2 / cat5: 0.098 / 0.046 -> 0.113 /
// 0.065 mean, while faust5k 000 -> 013 improved 0.066 -> 0.051). Issue 20 is about the
// unconstrained stage; issue 19 decides the collection stages' energy.
inline double singular_cruft_term(double T, double D, double reg_weight) {
  const double disc = T * T - 4 * D;
  const double g = 2 * D / (T + std::sqrt(disc > 0 ? disc : 0.0));
  return g > 0 ? reg_weight / (g * g * g) : kInf;
}

// Energy of one triangle from the Gram entries of its edges, without forming the Jacobian:
// domain edges e1, e2, e3 = e2 - e1 (E11, E22, E12, E33) and surface edges d1, d2, d3
// (D11, D22, D12, D33), surface area `area`. For the affine map,
//   a + c = |J|_F^2 = (|e2|^2 |d1|^2 + |e1|^2 |d2|^2 - 2 (e1.e2)(d1.d2)) / (4 A_dom^2),
// and along edge k the squared stretch is |d_k|^2 / |e_k|^2 (the anti-cruft term's frames).
// The third edges are passed in rather than formed as E11 + E22 - 2 E12: the split halves
// below have them exactly (no cancellation on their slivers).
inline double gram_face_energy(double E11, double E22, double E12, double E33, double D11, double D22, double D12,
                               double D33, double area, double floor, double weight, double shape_weight,
                               double scale, double reg_weight, bool edge_frames) {
  const double four_a2 = E11 * E22 - E12 * E12;  // (2 A_dom)^2
  if (!(four_a2 > 1e-24 * E11 * E22)) return kInf;
  // 1 / four_a2 and 1 / (E11 E22 E33) from one division (this is evaluated for every face at
  // every trial point, and its divisions dominate its cost).
  const double E123 = E11 * E22 * E33;
  const double inv = scale / (four_a2 * E123);
  const double T = gram_frobenius_numerator(E11, E22, E12, D11, D22, D12) * (E123 * inv);
  double reg;
  if (edge_frames) {
    const double iE = four_a2 * inv;  // scale / (E11 E22 E33)
    reg = cruft_term(T, D11 * (E22 * E33 * iE), D22 * (E11 * E33 * iE), D33 * (E11 * E22 * iE), reg_weight);
  } else {
    reg = singular_cruft_term(T, 4 * area * area * (scale * scale / four_a2), reg_weight);
  }
  if (!std::isfinite(reg)) return kInf;
  double e = weight * (area + floor) * (0.5 * T + reg);
  // Scale-free shape term (MIPS, (s1^2 + s2^2) / (2 s1 s2) = T / (2 sqrt D), >= 1), D =
  // det(J^T J) = (A_surf / A_dom)^2.
  if (shape_weight != 0) {
    const double D = 4 * area * area * (scale * scale / four_a2);
    e += D > 0 ? shape_weight * (0.5 * T / std::sqrt(D)) : kInf;
  }
  return e;
}

// A large face's energy with Praun & Hoppe's split against "accordion" slivers: the vertex i
// opposite the longest chord edge (j,k) is projected onto the great circle through j,k
// (point m); the face is evaluated as the two chord triangles (i,j,m) and (i,m,k), with the
// surface point of m interpolated on edge jk where the chord jk meets the ray through m.
// A spherical triangle whose corners approach one great circle has m -> q_i, so both
// halves collapse and the energy grows without bound, although its own chord triangle
// would stay fat and cheap; for moderately large triangles it charges the bulge of the
// spherical triangle over its chord, which steers the coarse levels to good layouts.
// q: the face's sphere points (corner 0 the moving vertex); s: its RingScratch::surf record.
// The halves are evaluated from Gram entries: the surface point pm = t p_j + (1 - t) p_k
// makes every surface entry a polynomial in t of the face's own (constant) Gram entries, and
// the halves' surface areas are (1 - t) and t times the face's. So the split needs no surface
// vector arithmetic and no square root but m's normalization (issue 20: the central
// differences of split faces were a third of the CPU time on generated limb shapes, when
// each half formed its Jacobian and its area explicitly).
inline double split_face_energy(const Eigen::Vector3d* q, const double* s, double scale, double reg_weight,
                                bool edge_frames) {
  double L0 = (q[1] - q[2]).squaredNorm(), L1 = (q[2] - q[0]).squaredNorm(), L2 = (q[0] - q[1]).squaredNorm();
  int i = L0 >= L1 ? (L0 >= L2 ? 0 : 2) : (L1 >= L2 ? 1 : 2);
  int j = (i + 1) % 3, k = (i + 2) % 3;
  Eigen::Vector3d n = q[j].cross(q[k]);
  double nn = n.squaredNorm();
  if (!(nn > 0)) return kInf;
  Eigen::Vector3d m = q[i] - n * (n.dot(q[i]) / nn);
  double mlen = m.norm();
  if (!(mlen > 0)) return kInf;
  m /= mlen;
  // t: the chord q_k + t (q_j - q_k) meets the ray through m. Both lie in the plane
  // normal to n, so with w = m x n: (q_k + t (q_j - q_k)) . w = 0.
  const Eigen::Vector3d w = m.cross(n);
  const double den = (q[k] - q[j]).dot(w);
  if (!(den != 0)) return kInf;
  const double t = q[k].dot(w) / den, u = 1 - t;
  // Surface Gram entries at corner i (dj = p_j - p_i, dk = p_k - p_i) from the record's at
  // corner 0 (|p1 - p0|^2, |p2 - p0|^2, (p1 - p0).(p2 - p0)); G33 = |p2 - p1|^2.
  const double G11 = s[kSurfG11], G22 = s[kSurfG22], G12 = s[kSurfG12], G33 = G11 + G22 - 2 * G12;
  const double Gjj = i == 0 ? G11 : i == 1 ? G33 : G22;
  const double Gkk = i == 0 ? G22 : i == 1 ? G11 : G33;
  const double Gjk = i == 0 ? G12 : i == 1 ? G11 - G12 : G22 - G12;
  const double Gjk_edge = i == 0 ? G33 : i == 1 ? G22 : G11;  // |p_k - p_j|^2
  // Both halves are evaluated at their corner m, where their edges meet at nearly a right
  // angle (m is q_i's foot on the great circle): at corner i a thin half's two edges are
  // nearly parallel, and its Gram determinant loses the digits the central differences need.
  // On the surface, with dm = pm - p_i = t dj + u dk: |dm|^2, p_j - pm = u (p_j - p_k),
  // p_k - pm = t (p_k - p_j), and (p_i - pm).(p_j - p_k) = -(dm.dj - dm.dk).
  const double Dmm = t * t * Gjj + 2 * t * u * Gjk + u * u * Gkk;
  const double Dcross = t * (Gjj - Gjk) + u * (Gjk - Gkk);  // dm.(dj - dk)
  const Eigen::Vector3d ei = q[i] - m, ej = q[j] - m, ek = q[k] - m;
  const double Eii = ei.squaredNorm();
  const double floor = 0.5 * s[kSurfFloor], shape = 0.5 * s[kSurfShape];
  // Half (m, i, j): third edge q_j - q_i, on the surface dj.
  const double area = s[kSurfArea], weight = s[kSurfWeight];
  const double e1 = gram_face_energy(Eii, ej.squaredNorm(), ei.dot(ej), (q[j] - q[i]).squaredNorm(), Dmm,
                                     u * u * Gjk_edge, -u * Dcross, Gjj, std::abs(u) * area, floor, weight, shape, scale,
                                     reg_weight, edge_frames);
  // Half (m, k, i): third edge q_i - q_k, on the surface dk.
  const double e2 = gram_face_energy(ek.squaredNorm(), Eii, ek.dot(ei), (q[k] - q[i]).squaredNorm(),
                                     t * t * Gjk_edge, Dmm, t * Dcross, Gkk, std::abs(t) * area, floor, weight, shape, scale,
                                     reg_weight, edge_frames);
  return e1 + e2;
}

// Energy of a small face on its chord triangle: domain edges e1, e2 from the moving vertex,
// surface entries from the record.
inline double gram_energy(const Eigen::Vector3d& e1, const Eigen::Vector3d& e2, const double* s, double scale,
                          double reg_weight, bool edge_frames) {
  const double E11 = e1.squaredNorm(), E22 = e2.squaredNorm(), E12 = e1.dot(e2);
  const double D11 = s[kSurfG11], D22 = s[kSurfG22], D12 = s[kSurfG12];
  return gram_face_energy(E11, E22, E12, E11 + E22 - 2 * E12, D11, D22, D12, D11 + D22 - 2 * D12, s[kSurfArea],
                          s[kSurfFloor], s[kSurfWeight], s[kSurfShape], scale, reg_weight, edge_frames);
}

// A ring face with v at y: its domain edges from y and whether it takes the accordion split.
// Distance of the chord plane from the centre: 1 for tiny triangles, 1/3 for the faces of a
// regular tetrahedron, -> 0 when the corners approach one great circle. Large faces (chord
// plane closer than split_distance) take the split evaluation, the others the cheap Gram form.
struct FacePlace {
  Eigen::Vector3d e1, e2;  // qa - y, qb - y
  double cross2;           // |e1 x e2|^2
  bool large;
};

// False where y is outside the face's kernel (det[y, qa, qb] <= 0).
inline bool place_face(const RingScratch::Face& rf, const Eigen::Vector3d& y, double split_distance, FacePlace* out) {
  out->e1 = rf.qa - y;
  out->e2 = rf.qb - y;
  const double det = y.dot(rf.n);
  if (!(det > 0)) return false;
  // delta < split_distance, without a square root: det^2 < split^2 |e1 x e2|^2.
  out->cross2 = out->e1.cross(out->e2).squaredNorm();
  out->large = det * det < split_distance * split_distance * out->cross2;
  return true;
}

// One placed face's energy for one model (`s`: its record in RingScratch::surf).
inline double placed_face_energy(const SphereState& st, const RingScratch::Face& rf, const FacePlace& fp,
                                 const double* s, double scale, const Eigen::Vector3d& y, double reg_weight) {
  if (!fp.large) return gram_energy(fp.e1, fp.e2, s, scale, reg_weight, st.edge_frame_cruft);
  const Eigen::Vector3d q[3] = {y, rf.qa, rf.qb};
  return split_face_energy(q, s, scale, reg_weight, st.edge_frame_cruft);
}

// One ring face's energy for one model with v at y, without the hole-area term.
double face_model_energy(const SphereState& st, const RingScratch::Face& rf, const double* s, double scale,
                         const Eigen::Vector3d& y, double reg_weight, double split_distance) {
  FacePlace fp;
  if (!place_face(rf, y, split_distance, &fp)) return kInf;
  return placed_face_energy(st, rf, fp, s, scale, y, reg_weight);
}

}  // namespace

double ring_energy(const SphereState& st, const RingScratch& ring, const Eigen::Vector3d& x, double reg_weight,
                   double split_distance, double* face_energy) {
  double energy = 0;
  for (size_t i = 0; i < ring.faces.size(); ++i) {
    const auto& rf = ring.faces[i];
    FacePlace fp;
    if (!place_face(rf, x, split_distance, &fp)) return kInf;
    if (rf.real && st.hole_area_penalty > 0) energy += st.hole_area_penalty * 0.5 * std::sqrt(fp.cross2);
    for (int m = 0; m < st.models; ++m) {
      const size_t k = i * static_cast<size_t>(st.models) + static_cast<size_t>(m);
      const double e = placed_face_energy(st, rf, fp, &ring.surf[k * kSurfStride],
                                          st.model_scale[static_cast<size_t>(m)], x, reg_weight);
      if (face_energy) face_energy[k] = e;
      energy += e;
    }
    if (!std::isfinite(energy)) return kInf;
  }
  return energy;
}

bool ring_tangent_derivatives(const SphereState& st, const RingScratch& ring, const Eigen::Vector3d& x,
                              const Eigen::Vector3d& t1, const Eigen::Vector3d& t2, double h, double reg_weight,
                              double split_distance, const double* energy_at_x, Eigen::Vector2d* g,
                              Eigen::Matrix2d* H) {
  g->setZero();
  H->setZero();
  // Chart points of the difference stencil, formed at the first face that needs them.
  Eigen::Vector3d y[5];
  bool have_stencil = false;
  for (size_t i = 0; i < ring.faces.size(); ++i) {
    const auto& rf = ring.faces[i];
    FacePlace fp;
    if (!place_face(rf, x, split_distance, &fp)) return false;
    const Eigen::Vector3d& e1 = fp.e1;
    const Eigen::Vector3d& e2 = fp.e2;
    const bool large = fp.large;
    const double E11 = e1.squaredNorm(), E22 = e2.squaredNorm(), E12 = e1.dot(e2);
    GramJet face;
    if (rf.real && st.hole_area_penalty > 0) {
      // hole_area_penalty * area = hole_area_penalty / 2 * Q^(1/2)
      const GramJet Q = gram_jet::area_jet(E11, E22, E12);
      if (!(Q.v > 0)) return false;
      const double r = 1 / std::sqrt(Q.v);
      gram_jet::add_composed(face, Q, Q.v * r, 0.5 * r, -0.25 * r / Q.v, 0.5 * st.hole_area_penalty);
    }
    for (int m = 0; m < st.models; ++m) {
      const size_t k = i * static_cast<size_t>(st.models) + static_cast<size_t>(m);
      const double* s = &ring.surf[k * kSurfStride];
      const double scale = st.model_scale[static_cast<size_t>(m)];
      if (!large && add_gram_energy_jet(E11, E22, E12, s, scale, reg_weight, &face)) continue;
      // Faces of the accordion split (and points where the closed form fails): central
      // differences of this face alone, the stencil newton_move used for the whole ring.
      if (!have_stencil) {
        y[1] = (x + h * t1).normalized();
        y[2] = (x - h * t1).normalized();
        y[3] = (x + h * t2).normalized();
        y[4] = (x - h * t2).normalized();
        y[0] = (x + h * t1 + h * t2).normalized();
        have_stencil = true;
      }
      const double f0 = energy_at_x ? energy_at_x[k] : face_model_energy(st, rf, s, scale, x, reg_weight, split_distance);
      double f[5];
      for (int c = 0; c < 5; ++c) {
        f[c] = face_model_energy(st, rf, s, scale, y[c], reg_weight, split_distance);
        if (!std::isfinite(f[c])) return false;
      }
      if (!std::isfinite(f0)) return false;
      (*g)(0) += (f[1] - f[2]) / (2 * h);
      (*g)(1) += (f[3] - f[4]) / (2 * h);
      (*H)(0, 0) += (f[1] - 2 * f0 + f[2]) / (h * h);
      (*H)(1, 1) += (f[3] - 2 * f0 + f[4]) / (h * h);
      const double h12 = (f[0] - f[1] - f[3] + f0) / (h * h);
      (*H)(0, 1) += h12;
      (*H)(1, 0) += h12;
    }
    gram_jet_to_tangent(face, e1, e2, x, t1, t2, g, H);
  }
  return g->allFinite() && H->allFinite();
}

bool ring_valid_exact(const RingScratch& ring, const Eigen::Vector3d& x) {
  for (const auto& rf : ring.faces)
    if (orient3d_origin(x, rf.qa, rf.qb) <= 0) return false;
  return true;
}

namespace {

// One safeguarded Newton step in the tangent plane at x, on the gnomonic chart
// y = normalize(x + u e1 + w e2). The gradient and Hessian of the ring energy are analytic for
// the faces measured on their chord triangles (ring_tangent_derivatives) and central
// differences (step 1e-4 of the shortest chord to a neighbour: well inside the kernel and far
// above rounding) for the faces of the accordion split, and for the whole ring in the
// collection stages' energy. A positive-definite Hessian gives the step -H^-1 g, clipped to
// the kernel and shortened until the energy decreases and the exact test passes.
// ring.energy_here holds the faces' energies at x (kept current on acceptance).
// Returns false (x unchanged) when the model is not convex or no decrease is found.
bool newton_move(const SphereState& st, RingScratch& ring, const OptimizerSettings& s, Eigen::Vector3d& x,
                 double& ecur) {
  double hmin = kInf;
  for (const auto& rf : ring.faces) hmin = std::min(hmin, (rf.qa - x).norm());
  if (!(hmin > 0) || !std::isfinite(hmin) || !(ecur < std::numeric_limits<double>::max())) return false;
  Eigen::Vector3d e1, e2;
  tangent_basis(x, e1, e2);
  const double h = 1e-4 * hmin;
  double g1, g2, H11, H22, H12;
  if (st.edge_frame_cruft) {
    Eigen::Vector2d g;
    Eigen::Matrix2d H;
    if (!ring_tangent_derivatives(st, ring, x, e1, e2, h, s.regularizer_weight, s.split_distance,
                                  ring.energy_here.data(), &g, &H))
      return false;
    g1 = g(0), g2 = g(1), H11 = H(0, 0), H22 = H(1, 1), H12 = H(0, 1);
  } else {
    auto F = [&](double u, double w) {
      return ring_energy(st, ring, (x + u * e1 + w * e2).normalized(), s.regularizer_weight, s.split_distance);
    };
    const double fp1 = F(h, 0), fm1 = F(-h, 0), fp2 = F(0, h), fm2 = F(0, -h), fpp = F(h, h);
    if (!(std::isfinite(fp1) && std::isfinite(fm1) && std::isfinite(fp2) && std::isfinite(fm2) && std::isfinite(fpp)))
      return false;
    g1 = (fp1 - fm1) / (2 * h), g2 = (fp2 - fm2) / (2 * h);
    H11 = (fp1 - 2 * ecur + fm1) / (h * h), H22 = (fp2 - 2 * ecur + fm2) / (h * h);
    H12 = (fpp - fp1 - fp2 + ecur) / (h * h);
  }
  const double det = H11 * H22 - H12 * H12;
  if (!(H11 > 0 && det > 0)) return false;
  const double du = -(H22 * g1 - H12 * g2) / det, dw = -(H11 * g2 - H12 * g1) / det;
  const double len = std::sqrt(du * du + dw * dw);
  if (!(len > 0)) return false;
  Eigen::Vector3d d = (du * e1 + dw * e2) / len;
  double lo, hi;
  if (!feasible_interval(ring, x, d, &lo, &hi)) return false;
  double t = std::min(std::atan(len), hi);
  for (int tries = 0; tries < 4; ++tries, t *= 0.3) {
    Eigen::Vector3d y = (x * std::cos(t) + d * std::sin(t)).normalized();
    double ey = ring_energy(st, ring, y, s.regularizer_weight, s.split_distance, ring.energy_trial.data());
    if (ey < ecur && ring_valid_exact(ring, y)) {
      x = y;
      ecur = ey;
      ring.energy_here.swap(ring.energy_trial);
      return true;
    }
  }
  return false;
}

}  // namespace

void build_ring_index(const SphereState& st, WorkerPool* pool, RingIndex* index) {
  const int nv = static_cast<int>(st.S.rows());
  index->start.assign(static_cast<size_t>(nv) + 1, 0);
  // Ring sizes in parallel (reading every vertex's face list is cache misses), then the
  // offsets by a prefix sum over the one array.
  auto size = [&](int v, int) {
    index->start[static_cast<size_t>(v) + 1] =
        st.vertex_alive[static_cast<size_t>(v)] ? static_cast<int>(st.vf[static_cast<size_t>(v)].size()) : 0;
  };
  if (pool)
    pool->parallel_for(nv, 256, 1024, size);
  else
    for (int v = 0; v < nv; ++v) size(v, 0);
  for (int v = 0; v < nv; ++v) index->start[static_cast<size_t>(v) + 1] += index->start[static_cast<size_t>(v)];
  index->faces.resize(static_cast<size_t>(index->start.back()));
  index->corners.resize(2 * index->faces.size());
  auto fill = [&](int v, int) {
    if (!st.vertex_alive[static_cast<size_t>(v)]) return;
    const size_t b = static_cast<size_t>(index->start[static_cast<size_t>(v)]);
    int* faces = index->faces.data() + b;
    int* corners = index->corners.data() + 2 * b;
    for (int f : st.vf[static_cast<size_t>(v)]) {
      const auto& c = st.F[static_cast<size_t>(f)];
      const int k = c[0] == v ? 0 : c[1] == v ? 1 : 2;
      *faces++ = f;
      *corners++ = c[(k + 1) % 3];
      *corners++ = c[(k + 2) % 3];
    }
  };
  if (pool)
    pool->parallel_for(nv, 256, 1024, fill);
  else
    for (int v = 0; v < nv; ++v) fill(v, 0);
}

bool optimize_vertex(const SphereState& st, int v, std::uint64_t key, const OptimizerSettings& s,
                     RingScratch& ring, Eigen::Vector3d* out, int searches, const RingIndex* index) {
  if (!load_ring(st, v, ring, index)) return false;
  Eigen::Vector3d x = st.S.row(v).transpose();
  const size_t per_model = ring.faces.size() * static_cast<size_t>(st.models);
  ring.energy_here.resize(per_model);
  ring.energy_trial.resize(per_model);
  double e0 = ring_energy(st, ring, x, s.regularizer_weight, s.split_distance, ring.energy_here.data());
  if (!std::isfinite(e0)) e0 = std::numeric_limits<double>::max();
  double ecur = e0;
  bool improved = false;
  if (s.newton) {
    // Newton steps first; a random-direction search only where Newton cannot proceed
    // (non-convex neighbourhoods, e.g. near the regularizer's barrier).
    int done = 0;
    for (; done < searches; ++done)
      if (!newton_move(st, ring, s, x, ecur)) break;
    improved = done > 0;
    if (done == searches) {
      *out = x;
      return true;
    }
    searches = 1;
  }
  Eigen::Vector3d e1, e2;
  tangent_basis(x, e1, e2);
  double theta = 2 * M_PI * unit_random(key);
  Eigen::Vector3d d = std::cos(theta) * e1 + std::sin(theta) * e2;
  for (int k = 0; k < searches; ++k) {
    double lo, hi;
    if (feasible_interval(ring, x, d, &lo, &hi)) {
      auto f = [&](double t) {
        Eigen::Vector3d y = x * std::cos(t) + d * std::sin(t);
        return ring_energy(st, ring, y, s.regularizer_weight, s.split_distance);
      };
      double fbest;
      double t = brent_minimize(f, lo, hi, 0.0, ecur, s.line_search_iter, &fbest);
      if (t != 0.0 && fbest < ecur) {
        Eigen::Vector3d y = (x * std::cos(t) + d * std::sin(t)).normalized();
        if (ring_valid_exact(ring, y)) {
          double ey = ring_energy(st, ring, y, s.regularizer_weight, s.split_distance);
          if (ey < ecur) {
            // Keep the search direction continuous: transport d to the new point.
            Eigen::Vector3d dn = (d * std::cos(t) - x * std::sin(t));
            x = y;
            ecur = ey;
            d = dn;
            improved = true;
          }
        }
      }
    }
    // Next search along the perpendicular great circle (Praun & Hoppe 2003).
    d = x.cross(d).normalized();
  }
  if (improved) *out = x;
  return improved;
}

int optimize_all(SphereState& st, const OptimizerSettings& s, std::uint64_t pass_key,
                 const std::function<bool()>& keep_going, WorkerPool* pool, bool* work_exceeded,
                 RingIndex* ring_cache) {
  const int nv = static_cast<int>(st.S.rows());
  auto is_fixed = [&](int v) { return !st.fixed.empty() && st.fixed[static_cast<size_t>(v)]; };
  std::vector<double> credit(static_cast<size_t>(nv), 0.0);
  std::vector<int> active;
  for (int v = 0; v < nv; ++v)
    if (st.vertex_alive[static_cast<size_t>(v)] && !is_fixed(v)) {
      credit[static_cast<size_t>(v)] = 3.0;
      active.push_back(v);
    }
  struct Candidate {
    Eigen::Vector3d x;
    double dist;
    bool moved;
  };
  WorkerPool serial(1);
  WorkerPool& workers = pool ? *pool : serial;
  // The level's rings (built here unless the caller's cache holds this level's): the rounds
  // below visit each vertex's neighbours as its ring's other corners, from one contiguous
  // list (the face lists and the faces' corners were cache misses on the calling thread).
  RingIndex own_index;
  RingIndex& index = ring_cache ? *ring_cache : own_index;
  if (index.start.size() != static_cast<size_t>(nv) + 1) build_ring_index(st, &workers, &index);
  auto corners = [&](int v) {
    return std::span<const int>(index.corners.data() + 2 * static_cast<size_t>(index.start[static_cast<size_t>(v)]),
                                index.corners.data() + 2 * static_cast<size_t>(index.start[static_cast<size_t>(v) + 1]));
  };
  std::vector<RingScratch> rings(static_cast<size_t>(workers.threads()));
  std::vector<Candidate> cand;
  // Per-vertex marks instead of arrays cleared every round: a round costs time in
  // proportion to its active vertices, not to the mesh (late rounds have a few dozen).
  std::vector<int> locked_in(static_cast<size_t>(nv), -1), listed_in(static_cast<size_t>(nv), -1);
  std::vector<int> order, next, keep, colour;
  std::vector<int> colour_of(static_cast<size_t>(nv), -1), class_start;
  // Activity threshold: absolute (the reference's movetol), or relative to the vertex's
  // shortest chord to a neighbour, so that convergence is judged at the scale of the local
  // triangles: coarse levels stop sooner, compressed regions (thin legs) are refined longer.
  // A coarse level (precise_vertices) is judged more tightly in the first rounds of a pass
  // (rel_tol_of_round): the precision its global layout gets is then bounded in cost.
  const bool precise_level = s.precise_vertices > 0 && st.alive_vertices <= s.precise_vertices;
  double rel_tol = s.movetol_rel;
  auto rel_tol_of_round = [&](int r) {
    return precise_level && r < s.precise_rounds ? s.precise_movetol_rel : s.movetol_rel;
  };
  auto activity_tol = [&](int v) {
    double tol = s.movetol;
    if (rel_tol > 0) {
      double shortest = kInf;
      const Eigen::Vector3d x = st.S.row(v).transpose();
      for (int w : corners(v)) shortest = std::min(shortest, (st.S.row(w).transpose() - x).norm());
      tol = std::min(s.movetol, rel_tol * shortest);
    }
    return tol;
  };
  // The move of active[i] from the current positions into cand[i]; its random direction
  // depends on (pass, round, vertex) only.
  auto compute_candidate = [&](int i, int round, int thread) {
    const int v = active[static_cast<size_t>(i)];
    const std::uint64_t key =
        mix(pass_key ^ mix(static_cast<std::uint64_t>(round) * 0x100000001b3ULL + static_cast<std::uint64_t>(v)));
    Eigen::Vector3d y;
    Candidate& c = cand[static_cast<size_t>(i)];
    if (optimize_vertex(st, v, key, s, rings[static_cast<size_t>(thread)], &y, 2, &index)) {
      c.x = y;
      c.dist = (y - st.S.row(v).transpose()).norm();
      c.moved = true;
    }
  };
  // The work budget counts the vertex optimizations of the rounds (the active vertices), which
  // do not depend on the thread count: the pass ends at the same round for any count.
  auto pass_work = [&](double per_vertex) {  // 0: unbounded
    return per_vertex > 0 ? per_vertex * static_cast<double>(std::max<size_t>(active.size(), kMinPassWorkVertices))
                          : 0.0;
  };
  const double work_budget = pass_work(s.max_pass_work);
  // A pass that has done pass_work_cap optimizations per free vertex ends there (not an
  // error; the next level or pass goes on from its positions): see OptimizerSettings.
  const double work_cap = pass_work(s.pass_work_cap);
  double work = 0;
  if (work_exceeded) *work_exceeded = false;
  int round = 0;
  for (; round < s.max_rounds && !active.empty(); ++round) {
    rel_tol = rel_tol_of_round(round);
    if (keep_going && !keep_going()) return -1;
    work += static_cast<double>(active.size());
    if (work_budget > 0 && work > work_budget) {
      if (work_exceeded) *work_exceeded = true;
      break;
    }
    if (work_cap > 0 && work > work_cap) break;
    if (s.coloured_rounds) {
      // Colour the active vertices greedily (by id, smallest colour unused by an already
      // coloured active neighbour), then run the colour classes one after another: a class
      // is an independent set (no two of its vertices share a face), so every move computed
      // is applied, from positions that include the earlier classes' moves (Gauss-Seidel
      // by colour). The greedy set of the plain rounds keeps only about a quarter of the
      // moves of a full round and recomputes the others.
      const int na = static_cast<int>(active.size());
      colour.assign(active.size(), 0);
      int ncol = 0;
      for (int i = 0; i < na; ++i) {
        colour_of[static_cast<size_t>(active[static_cast<size_t>(i)])] = -1;
        listed_in[static_cast<size_t>(active[static_cast<size_t>(i)])] = round;
      }
      for (int i = 0; i < na; ++i) {
        const int v = active[static_cast<size_t>(i)];
        std::uint64_t used = 0;
        for (int w : corners(v))
          if (listed_in[static_cast<size_t>(w)] == round && colour_of[static_cast<size_t>(w)] >= 0 &&
              colour_of[static_cast<size_t>(w)] < 64)
            used |= std::uint64_t{1} << colour_of[static_cast<size_t>(w)];
        int c = 0;
        while (c < 64 && (used >> c & 1)) ++c;  // > 63 coloured neighbours: impossible in practice, 64 is safe
        colour_of[static_cast<size_t>(v)] = c;
        colour[static_cast<size_t>(i)] = c;
        ncol = std::max(ncol, c + 1);
      }
      cand.assign(active.size(), Candidate{Eigen::Vector3d::Zero(), 0.0, false});
      next.clear();
      for (int i = 0; i < na; ++i) next.push_back(active[static_cast<size_t>(i)]);
      // The classes as consecutive runs of `order` (a counting sort: ascending slots in each).
      class_start.assign(static_cast<size_t>(ncol) + 1, 0);
      for (int i = 0; i < na; ++i) ++class_start[static_cast<size_t>(colour[static_cast<size_t>(i)]) + 1];
      for (int c = 0; c < ncol; ++c) class_start[static_cast<size_t>(c) + 1] += class_start[static_cast<size_t>(c)];
      order.resize(active.size());
      for (int i = 0; i < na; ++i) order[static_cast<size_t>(class_start[static_cast<size_t>(colour[static_cast<size_t>(i)])]++)] = i;
      for (int c = ncol; c > 0; --c) class_start[static_cast<size_t>(c)] = class_start[static_cast<size_t>(c) - 1];
      class_start[0] = 0;
      // Class c's moves feed the credits and the next round's list (in class order, so
      // the sums are the same for any thread count). That bookkeeping reads only class c's
      // candidates and writes only credits and lists, which no vertex optimization reads, so
      // the calling thread does it while the workers start on class c + 1 (parallel_for's
      // side task): it is serial work that otherwise kept the workers waiting between classes.
      auto settle_class = [&](int c) {
        const int* cls = order.data() + class_start[static_cast<size_t>(c)];
        const int count = class_start[static_cast<size_t>(c) + 1] - class_start[static_cast<size_t>(c)];
        for (int j = 0; j < count; ++j) {
          const int i = cls[j];
          const int v = active[static_cast<size_t>(i)];
          credit[static_cast<size_t>(v)] = 0;  // evaluated at the current neighbourhood
          const Candidate& cd = cand[static_cast<size_t>(i)];
          if (!cd.moved) continue;
          for (int w : corners(v)) {
            credit[static_cast<size_t>(w)] += 0.3 * cd.dist / 2.0;
            if (!is_fixed(w) && listed_in[static_cast<size_t>(w)] != round) {
              listed_in[static_cast<size_t>(w)] = round;
              next.push_back(w);
            }
          }
        }
      };
      for (int c = 0; c < ncol; ++c) {
        const int* cls = order.data() + class_start[static_cast<size_t>(c)];
        const int count = class_start[static_cast<size_t>(c) + 1] - class_start[static_cast<size_t>(c)];
        // A class is an independent set: no member's ring holds another member, so each
        // move is written at once by the thread that computed it (no other member reads it).
        std::function<void()> settle_previous;
        if (c > 0) settle_previous = [&settle_class, c] { settle_class(c - 1); };
        // One item per chunk, from two items up: a vertex optimization costs 1-6 us, a chunk
        // one atomic increment, a loop ~3 us of hand-over; late rounds' classes have a few
        // items each (gargoyle, 2 threads: refinement 1.20 -> 1.16 s against chunks of 4
        // from 8 items, alternating runs; the same bytes).
        workers.parallel_for(
            count, 1, 2,
            [&](int j, int thread) {
              compute_candidate(cls[j], round, thread);
              const Candidate& cd = cand[static_cast<size_t>(cls[j])];
              if (cd.moved) st.S.row(active[static_cast<size_t>(cls[j])]) = cd.x.transpose();
            },
            settle_previous);
      }
      if (ncol > 0) settle_class(ncol - 1);
      keep.assign(next.size(), 0);
      workers.parallel_for(static_cast<int>(next.size()), 64, 256, [&](int j, int) {
        const int v = next[static_cast<size_t>(j)];
        keep[static_cast<size_t>(j)] = credit[static_cast<size_t>(v)] > activity_tol(v) ? 1 : 0;
      });
      active.clear();
      for (size_t j = 0; j < next.size(); ++j)
        if (keep[j]) active.push_back(next[j]);
      std::sort(active.begin(), active.end());
      continue;
    }
    const int na = static_cast<int>(active.size());
    cand.assign(active.size(), Candidate{Eigen::Vector3d::Zero(), 0.0, false});
    // Candidates are computed from the same positions by every thread: results do not
    // depend on the thread count or scheduling.
    workers.parallel_for(na, 16, 64, [&](int i, int thread) { compute_candidate(i, round, thread); });
    // Apply greedily as an independent set, largest displacement first (ties by id).
    order.clear();
    for (int i = 0; i < na; ++i)
      if (cand[static_cast<size_t>(i)].moved) order.push_back(i);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      if (cand[a].dist != cand[b].dist) return cand[a].dist > cand[b].dist;
      return active[a] < active[b];
    });
    next.clear();
    for (int i = 0; i < na; ++i) {
      const int v = active[static_cast<size_t>(i)];
      listed_in[static_cast<size_t>(v)] = round;
      next.push_back(v);
    }
    const int actives_listed = na;
    for (int i : order) {
      const int v = active[static_cast<size_t>(i)];
      if (locked_in[static_cast<size_t>(v)] == round) continue;  // a neighbour moved: retry next round
      credit[static_cast<size_t>(v)] = 0;
      st.S.row(v) = cand[static_cast<size_t>(i)].x.transpose();
      for (int w : corners(v)) {
        locked_in[static_cast<size_t>(w)] = round;
        // "Spatial fade": neighbours of a moved vertex gain credit (REFERENCE.md §2.5).
        credit[static_cast<size_t>(w)] += 0.3 * cand[static_cast<size_t>(i)].dist / 2.0;
        if (!is_fixed(w) && listed_in[static_cast<size_t>(w)] != round) {
          listed_in[static_cast<size_t>(w)] = round;
          next.push_back(w);  // may have gained enough credit
        }
      }
    }
    for (int i = 0; i < na; ++i) {
      const int v = active[static_cast<size_t>(i)];
      if (locked_in[static_cast<size_t>(v)] != round) credit[static_cast<size_t>(v)] = 0;  // moved, or converged
    }
    // Activity (activity_tol) judged in parallel (a ring walk per vertex) into per-slot flags.
    // An active vertex that was locked (its move not applied) stays active; a neighbour of a
    // mover joins only if its credit is above the threshold.
    keep.assign(next.size(), 0);
    workers.parallel_for(static_cast<int>(next.size()), 64, 256, [&](int j, int) {
      const int v = next[static_cast<size_t>(j)];
      if (j < actives_listed && locked_in[static_cast<size_t>(v)] == round) {
        keep[static_cast<size_t>(j)] = 1;
        return;
      }
      keep[static_cast<size_t>(j)] = credit[static_cast<size_t>(v)] > activity_tol(v) ? 1 : 0;
    });
    active.clear();
    for (size_t j = 0; j < next.size(); ++j)
      if (keep[j]) active.push_back(next[j]);
    std::sort(active.begin(), active.end());
  }
  return round;
}

}  // namespace spherekit::detail
