// Measures of a sphere map, with the definitions of the independent evaluator
// shared/tools/evalsphere.py (docs: EVALUATION.md 1, ALGORITHM.md 1.2-1.3).
//
// Literature:
//   P. V. Sander, J. Snyder, S. J. Gortler, H. Hoppe, "Texture Mapping Progressive Meshes",
//     SIGGRAPH 2001: per-face L2 / Linf stretch from the Jacobian's metric tensor (a, b, c);
//     the mesh L2 norm weights faces by surface area; normalisation by the domain/surface
//     area ratio.
//   E. Praun, H. Hoppe, "Spherical Parametrization and Remeshing", SIGGRAPH 2003: stretch of
//     the map sphere -> surface; "stretch efficiency" = 1 / L2n^2.
//   A. Van Oosterom, J. Strackee, IEEE TBME 30(2), 1983: solid angle of a spherical triangle,
//     tan(E/2) = det / (1 + a.b + b.c + c.a).
//   A. Neumaier, ZAMM 54, 1974; D. E. Knuth, TAOCP 4.2.2: compensated summation with TwoSum
//     (sums over ~1e6 faces agree with numpy's pairwise sums to ~1e-15 relative).
//
// Design: one pass over the faces computes everything that needs no global total and keeps
// three doubles per considered face (surface area, domain area, Gamma/gamma); a second pass
// forms the area-normalised quantities; the 95th percentile is a weighted quickselect (O(n),
// the element numpy's argsort + cumsum + searchsorted would pick). Closedness counts edges
// with a bucket per smaller vertex id instead of sorting all 3F edges. Orientation is decided
// twice: by the exact predicate (validity) and by evalsphere's float test (reproduction).
#include "spherekit/metrics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "detail/metrics_stretch.h"
#include "spherekit/predicates.h"

namespace spherekit {
namespace {

constexpr double kPi = 3.14159265358979323846;
// evalsphere's constants, kept identical so the counts and clamps agree:
constexpr double kTinyDet = 1e-15;     // |det| at or below this counts as "degenerate" (float count)
constexpr double kFloor = 1e-300;      // floor for domain areas (faces at or below it are left out of
                                       // the stretch sums), gamma^2 and area ratios
constexpr double kP95 = 0.95;          // conformal percentile

/// Compensated sum (Kahan-Babuska-Neumaier family): every addition's rounding error is
/// recovered exactly by Knuth's branch-free TwoSum and accumulated, so the result is as
/// accurate as if computed in twice the precision, without data-dependent branches.
class CompensatedSum {
 public:
  void add(double x) {
    const double t = s_ + x;
    const double xv = t - s_;
    c_ += (s_ - (t - xv)) + (x - xv);
    s_ = t;
  }
  double value() const { return s_ + c_; }

 private:
  double s_ = 0, c_ = 0;
};

/// evalsphere's closedness test: every undirected edge (as a sorted vertex pair) occurs in
/// exactly two faces. Edges are bucketed by their smaller vertex; buckets are tiny (about 3).
bool is_closed(const RowMat3i& F, Eigen::Index nv) {
  const Eigen::Index nf = F.rows();
  std::vector<std::int32_t> start(static_cast<size_t>(nv) + 1, 0);
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++start[static_cast<size_t>(std::min(F(f, k), F(f, (k + 1) % 3))) + 1];
  for (size_t v = 0; v < static_cast<size_t>(nv); ++v) start[v + 1] += start[v];
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  std::vector<std::int32_t> other(static_cast<size_t>(3 * nf));
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = F(f, k), b = F(f, (k + 1) % 3);
      other[static_cast<size_t>(fill[static_cast<size_t>(std::min(a, b))]++)] = std::max(a, b);
    }
  for (size_t v = 0; v < static_cast<size_t>(nv); ++v) {
    auto first = other.begin() + start[v], last = other.begin() + start[v + 1];
    std::sort(first, last);
    for (auto it = first; it != last;) {
      auto run = std::find_if(it, last, [&](std::int32_t x) { return x != *it; });
      if (run - it != 2) return false;
      it = run;
    }
  }
  return true;
}

/// evalsphere's percentile: order = argsort(conf), cw = cumsum(w[order]),
/// result = conf[order][min(searchsorted(cw, p), n-1)], searchsorted 'left' = the first index
/// whose cumulative weight reaches p. Found by quickselect on (conf, w) pairs: halve the range
/// around its median; the crossing lies left of the median iff the weight below it reaches p.
/// Ties in conf are ordered arbitrarily (as by numpy's unstable argsort): same value returned.
double weighted_percentile(std::vector<std::pair<double, double>>& cw, double p) {
  auto by_value = [](const std::pair<double, double>& x, const std::pair<double, double>& y) {
    return x.first < y.first;
  };
  size_t lo = 0, hi = cw.size();
  double below = 0;  // weight of the elements left of lo (all <= those in [lo, hi))
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    std::nth_element(cw.begin() + static_cast<std::ptrdiff_t>(lo), cw.begin() + static_cast<std::ptrdiff_t>(mid),
                     cw.begin() + static_cast<std::ptrdiff_t>(hi), by_value);
    double left = below;
    for (size_t i = lo; i < mid; ++i) left += cw[i].second;
    if (left >= p) {
      hi = mid;
    } else {
      below = left;
      lo = mid;
    }
  }
  return cw[lo].first;
}

Status invalid(std::string message) { return Status(ErrorCode::InvalidInput, std::move(message)); }

/// Input checks of evaluate_sphere_map; each message names the offending element.
Status check_inputs(const TriMesh& mesh, const RowMat3d& S, const std::vector<FeatureTarget>& targets,
                    const std::vector<char>* face_mask) {
  const Eigen::Index nv = mesh.V.rows(), nf = mesh.F.rows();
  if (S.rows() != nv)
    return invalid("sphere map has " + std::to_string(S.rows()) + " vertices, mesh " + std::to_string(nv));
  if (nf == 0) return invalid("mesh has no faces");
  if (face_mask && static_cast<Eigen::Index>(face_mask->size()) != nf)
    return invalid("face mask has " + std::to_string(face_mask->size()) + " entries, mesh " +
                   std::to_string(nf) + " faces");
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= nv)
        return invalid("face " + std::to_string(f) + " has vertex index " + std::to_string(mesh.F(f, k)) +
                       " out of range");
  for (Eigen::Index v = 0; v < nv; ++v) {
    if (!S.row(v).allFinite()) return invalid("non-finite sphere coordinates at vertex " + std::to_string(v));
    if (S.row(v).squaredNorm() == 0.0) return invalid("sphere point of vertex " + std::to_string(v) + " is zero");
    if (!mesh.V.row(v).allFinite()) return invalid("non-finite mesh coordinates at vertex " + std::to_string(v));
  }
  if (face_mask && std::none_of(face_mask->begin(), face_mask->end(), [](char m) { return m != 0; }))
    return invalid("face mask selects no face");
  for (size_t i = 0; i < targets.size(); ++i) {
    const FeatureTarget& t = targets[i];
    if (t.vertex < 0 || t.vertex >= nv)
      return invalid("feature target " + std::to_string(i) + " has vertex " + std::to_string(t.vertex) +
                     " out of range");
    if (!t.target.allFinite() || t.target.squaredNorm() == 0.0)
      return invalid("feature target " + std::to_string(i) + " is zero or not finite");
  }
  return Status::ok_status();
}

}  // namespace

FaceStretch face_stretch(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const Eigen::Vector3d& q2) {
  const detail::StretchTerms t =
      detail::stretch_terms(p0.data(), p1.data(), p2.data(), q0.data(), q1.data(), q2.data());
  FaceStretch r;
  r.a = t.a;
  r.b = t.b;
  r.c = t.c;
  r.area_domain = t.area_domain;
  r.area_surface = t.area_surface;
  return r;
}

Result<SphereMapMetrics> evaluate_sphere_map(const TriMesh& mesh, const RowMat3d& S,
                                             const std::vector<FeatureTarget>& targets,
                                             const std::vector<char>* face_mask) {
  SPHEREKIT_RETURN_IF_ERROR(check_inputs(mesh, S, targets, face_mask));
  const Eigen::Index nv = mesh.V.rows(), nf = mesh.F.rows();
  const RowMat3i& F = mesh.F;
  SphereMapMetrics m;
  m.vertices = static_cast<int>(nv);
  m.faces = static_cast<int>(nf);

  // Normalise like evalsphere (divide by the Euclidean norm) and report the deviation.
  RowMat3d Q(nv, 3);
  for (Eigen::Index v = 0; v < nv; ++v) {
    const double r = detail::norm3(S.row(v).data());
    m.radius_dev = std::max(m.radius_dev, std::fabs(r - 1.0));
    Q(v, 0) = S(v, 0) / r;
    Q(v, 1) = S(v, 1) / r;
    Q(v, 2) = S(v, 2) / r;
  }

  // Pass 1: orientation over all faces; per-face stretch terms over the considered faces.
  int det_pos = 0, det_neg = 0, det_below = 0, det_above = 0;
  CompensatedSum signed_area, abs_area;
  std::vector<double> area_surf, area_dom, conf;
  area_surf.reserve(static_cast<size_t>(nf));
  area_dom.reserve(static_cast<size_t>(nf));
  conf.reserve(static_cast<size_t>(nf));
  CompensatedSum sum_dom_ok, sum_surf_ok, sum_l2, sum_surf_all, sum_dom_all;
  double max_G2 = 0;
  bool any_ok = false;
  for (Eigen::Index f = 0; f < nf; ++f) {
    const double* q0 = Q.row(F(f, 0)).data();
    const double* q1 = Q.row(F(f, 1)).data();
    const double* q2 = Q.row(F(f, 2)).data();

    // Validity: exact sign on the input rows (positive scaling keeps the exact sign).
    const int s = orient3d_origin(S.row(F(f, 0)).data(), S.row(F(f, 1)).data(), S.row(F(f, 2)).data());
    if (s < 0) ++m.flipped;
    if (s == 0) ++m.degenerate;

    // evalsphere's float orientation and Van Oosterom-Strackee signed area.
    const double cx = q1[1] * q2[2] - q1[2] * q2[1];
    const double cy = q1[2] * q2[0] - q1[0] * q2[2];
    const double cz = q1[0] * q2[1] - q1[1] * q2[0];
    const double cross[3] = {cx, cy, cz};
    const double det = detail::einsum_dot3(q0, cross);
    const double den = 1.0 + detail::einsum_dot3(q0, q1) + detail::einsum_dot3(q1, q2) + detail::einsum_dot3(q2, q0);
    const double area = 2.0 * std::atan2(det, den);
    signed_area.add(area);
    abs_area.add(std::fabs(area));
    det_pos += det > 0;
    det_neg += det < 0;
    det_below += det < -kTinyDet;
    det_above += det > kTinyDet;
    m.degenerate_tol += std::fabs(det) <= kTinyDet;

    if (face_mask && !(*face_mask)[static_cast<size_t>(f)]) continue;
    const detail::StretchTerms t = detail::stretch_terms(mesh.V.row(F(f, 0)).data(), mesh.V.row(F(f, 1)).data(),
                                                         mesh.V.row(F(f, 2)).data(), q0, q1, q2);
    const bool ok = t.area_domain > kFloor;
    // Singular values of J: Gamma^2, gamma^2 = (a + c +- sqrt((a - c)^2 + 4 b^2)) / 2.
    const double disc = detail::singular_disc(t);
    const double G2 = 0.5 * (t.a + t.c + disc);
    const double g2 = std::max(0.5 * (t.a + t.c - disc), 0.0);
    double face_conf = std::numeric_limits<double>::infinity();
    if (ok) {
      any_ok = true;
      sum_dom_ok.add(t.area_domain);
      sum_surf_ok.add(t.area_surface);
      sum_l2.add(t.area_surface * 0.5 * (t.a + t.c));  // Sander 2001: L2(T)^2 weighted by 3D area
      max_G2 = std::max(max_G2, G2);
      face_conf = std::sqrt(G2 / std::max(g2, kFloor));
      if (std::isnan(face_conf)) face_conf = std::numeric_limits<double>::infinity();  // sorts last, like numpy
    }
    sum_surf_all.add(t.area_surface);
    sum_dom_all.add(t.area_domain);
    area_surf.push_back(t.area_surface);
    area_dom.push_back(t.area_domain);
    conf.push_back(face_conf);
  }

  // Majority orientation, ties counting as positive (evalsphere: sum(det>0) >= sum(det<0)).
  m.flipped_majority = det_pos >= det_neg ? det_below : det_above;
  m.closed = is_closed(F, nv);
  if (m.closed) {
    m.winding = signed_area.value() / (4 * kPi);
    m.fold_excess = (abs_area.value() - 4 * kPi) / (4 * kPi);
  }

  // Normalised L2 stretch: L2(M)^2 = sum A' L2(T)^2 / sum A', times sum A / sum A' so that the
  // domain is rescaled to the surface's area (ALGORITHM.md 1.2); efficiency = 1 / L2n^2.
  const double inf = std::numeric_limits<double>::infinity();
  if (any_ok) {
    const double scale = sum_dom_ok.value() / sum_surf_ok.value();
    const double L2sq = (sum_l2.value() / sum_surf_ok.value()) * scale;
    m.efficiency = L2sq > 0 ? 1.0 / L2sq : 0.0;
    m.l2_stretch = std::sqrt(L2sq);
    m.linf = std::sqrt(max_G2 * scale);
  } else {
    m.efficiency = 0;
    m.l2_stretch = inf;
    m.linf = inf;
  }

  // Pass 2: area-weighted statistics with w = A' / sum A' over the considered faces (all of
  // them, including the ones left out of the stretch sums, exactly as evalsphere).
  const double total_surf = sum_surf_all.value(), total_dom = sum_dom_all.value();
  const size_t n = area_surf.size();
  CompensatedSum wconf, wfinite, wlog;
  std::vector<std::pair<double, double>> conf_weight(n);
  for (size_t i = 0; i < n; ++i) {
    const double w = area_surf[i] / total_surf;
    if (std::isfinite(conf[i])) {
      wconf.add(w * conf[i]);
      wfinite.add(w);
    }
    conf_weight[i] = {conf[i], w};
    const double ratio = w / std::max(area_dom[i] / total_dom, kFloor);
    wlog.add(w * std::fabs(std::log(std::max(ratio, kFloor))));
  }
  m.conformal_mean = wconf.value() / std::max(wfinite.value(), kFloor);
  m.conformal_p95 = weighted_percentile(conf_weight, kP95);
  m.area_log_mean = wlog.value();

  if (!targets.empty()) {
    double worst = 0;
    for (const FeatureTarget& t : targets) {
      const Eigen::Vector3d s = Q.row(t.vertex).transpose();
      const Eigen::Vector3d d = t.target.normalized();
      worst = std::max(worst, std::atan2(s.cross(d).norm(), s.dot(d)));
    }
    m.feature_err_deg = worst * (180.0 / kPi);
  }
  return m;
}

int count_flipped_faces(const RowMat3i& F, const RowMat3d& S) {
  int count = 0;
  const Eigen::Index nv = S.rows();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const std::int32_t a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (a < 0 || b < 0 || c < 0 || a >= nv || b >= nv || c >= nv) {
      ++count;  // cannot be a valid face; there is no Status to report it in
      continue;
    }
    if (orient3d_origin(S.row(a).data(), S.row(b).data(), S.row(c).data()) <= 0) ++count;
  }
  return count;
}

}  // namespace spherekit
