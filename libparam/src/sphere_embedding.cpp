// Coarse-to-fine embedding of a progressive mesh on the unit sphere.
//   Praun & Hoppe 2003, "Spherical parametrization and remeshing" §4: base tetrahedron on a
//   regular tetrahedron, vertex splits replayed one at a time, each new vertex placed in the
//   kernel of its spherical 1-ring, global stretch passes whenever #V grows by a factor.
//
// Invariant (checked by exact predicate at every placement and move): every alive face has
// det[S(a), S(b), S(c)] > 0. A vertex split changes only faces containing the new vertex vt,
// so placing vt strictly inside the kernel of its ring preserves the invariant; the kernel
// is non-empty in exact arithmetic (points next to vs between vl and vr are inside).
#include "detail/sphere_embedding.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "detail/metrics_stretch.h"
#include "detail/parallel_jobs.h"
#include "detail/worker_pool.h"
#include "spherekit/predicates.h"

namespace spherekit::detail {
namespace {

// Kernel "centroid" of v's ring: for each ring edge's great circle, the arc of it that lies
// in every other constraint half-space is a side of the (convex) kernel polygon; average
// the arcs' midpoints weighted by arc length, and normalize (Praun & Hoppe's approximation
// of the kernel centroid, here length-weighted so slivers of the boundary count little).
bool kernel_centroid(const RingScratch& ring, Eigen::Vector3d* out) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const size_t n = ring.faces.size();
  for (size_t i = 0; i < n; ++i) {
    const auto& fi = ring.faces[i];
    double nn = fi.n.norm();
    if (!(nn > 0)) continue;
    Eigen::Vector3d u = fi.qa;
    Eigen::Vector3d w = (fi.n / nn).cross(u);
    double wn = w.norm();
    if (!(wn > 0)) continue;
    w /= wn;
    bool have = false, empty = false;
    double lo = 0, hi = 0;
    for (size_t j = 0; j < n && !empty; ++j) {
      if (j == i) continue;
      const Eigen::Vector3d& m = ring.faces[j].n;
      double cu = m.dot(u), cw = m.dot(w);
      if (cu == 0 && cw == 0) continue;  // same great circle: no constraint along it
      double phi = std::atan2(cw, cu);
      if (!have) {
        lo = phi - M_PI / 2;
        hi = phi + M_PI / 2;
        have = true;
        continue;
      }
      double mid = 0.5 * (lo + hi);
      while (phi - mid > M_PI) phi -= 2 * M_PI;
      while (phi - mid < -M_PI) phi += 2 * M_PI;
      lo = std::max(lo, phi - M_PI / 2);
      hi = std::min(hi, phi + M_PI / 2);
      if (!(hi > lo)) empty = true;
    }
    if (!have || empty) continue;
    double t = 0.5 * (lo + hi);
    sum += (hi - lo) * (std::cos(t) * u + std::sin(t) * w);
  }
  double len = sum.norm();
  if (!(len > 0)) return false;
  *out = sum / len;
  return true;
}

// Fallback placement: maximize min_f n_f . x over unit x (the spherical Chebyshev centre of
// the kernel) by projected subgradient ascent from `start`. Used only when the centroid is
// not strictly inside by the exact test (very thin kernels).
bool kernel_chebyshev(const RingScratch& ring, const Eigen::Vector3d& start, Eigen::Vector3d* out) {
  std::vector<Eigen::Vector3d> nrm;
  for (const auto& rf : ring.faces) {
    double l = rf.n.norm();
    if (l > 0) nrm.push_back(rf.n / l);
  }
  Eigen::Vector3d x = start.normalized();
  double step = 0.25;
  for (int it = 0; it < 400; ++it) {
    double best = 1e300;
    int arg = -1;
    for (size_t k = 0; k < nrm.size(); ++k) {
      double s = nrm[k].dot(x);
      if (s < best) { best = s; arg = static_cast<int>(k); }
    }
    if (arg < 0) return false;
    if (best > 0 && ring_valid_exact(ring, x)) {
      *out = x;
      return true;
    }
    x = (x + step * nrm[static_cast<size_t>(arg)]).normalized();
    step *= 0.97;
  }
  return false;
}

// Last-resort placement next to vs: in exact arithmetic every point close enough to vs
// inside the wedge between vl and vr is in the kernel, so probe directions around vs at
// shrinking distances and keep the first point the exact predicate accepts.
bool kernel_near_vertex(const RingScratch& ring, const Eigen::Vector3d& vs, Eigen::Vector3d* out) {
  Eigen::Vector3d e1, e2;
  tangent_basis(vs, e1, e2);
  for (double eps = 1e-2; eps > 1e-15; eps *= 0.1)
    for (int k = 0; k < 64; ++k) {
      double t = 2 * M_PI * (k + 0.5) / 64;
      Eigen::Vector3d x = (vs + eps * (std::cos(t) * e1 + std::sin(t) * e2)).normalized();
      if (ring_valid_exact(ring, x)) {
        *out = x;
        return true;
      }
    }
  return false;
}

class Refiner {
 public:
  Refiner(const EmbedInput& in, const OptimizerSettings& s, const ProgressFn& progress, EmbedStats* stats)
      : in_(in), pm_(*in.pm), s_(s), progress_(progress), stats_(stats), pool_(resolve_threads(s.threads)) {}

  Status run(RowMat3d* S) {
    init_base_level();
    SPHEREKIT_RETURN_IF_ERROR(place_base());
    const int total = static_cast<int>(pm_.collapses.size());
    // The base level is optimized as a coarse level only if finer levels follow; a mesh that
    // is its own base gets just the final pass below.
    if (total > 0) SPHEREKIT_RETURN_IF_ERROR(optimize_level());
    int threshold = next_threshold(st_.alive_vertices);
    int last_pct = -1;
    region_mark_.assign(static_cast<size_t>(pm_.num_vertices), 0);
    seen_mark_.assign(static_cast<size_t>(pm_.num_vertices), 0);
    rings_.resize(static_cast<size_t>(pool_.threads()));
    for (int i = total - 1; i >= 0;) {
      // The splits are replayed in order; a run of consecutive splits whose regions are
      // disjoint (claim_split_region) commute, so they are applied first and their new vertices
      // placed in parallel: the same positions as one split after another, for any number
      // of threads (the run's extent depends on the mesh only).
      batch_.clear();
      ++region_stamp_;
      while (i >= 0 && batch_.size() < kMaxBatch) {
        if (!claim_split_region(i)) break;
        apply_split(i);
        batch_.push_back(i);
        --i;
        if (st_.alive_vertices >= threshold) break;
      }
      SPHEREKIT_RETURN_IF_ERROR(place_batch());
      if (st_.alive_vertices >= threshold) {
        SPHEREKIT_RETURN_IF_ERROR(optimize_level());
        threshold = next_threshold(st_.alive_vertices);
      }
      int pct = static_cast<int>(100.0 * (total - 1 - i) / std::max(1, total));
      if (pct != last_pct) {
        last_pct = pct;
        if (!report_progress(progress_, "refine", st_.alive_vertices, static_cast<double>(total - 1 - i) / std::max(1, total)))
          return Status(ErrorCode::Cancelled, "cancelled during refinement");
      }
    }
    // Final pass at full resolution on the measured energy: every face on its chord
    // triangle, except a face whose chord plane passes within a quarter of the radius of the
    // centre (a spherical triangle wider than 75 degrees, wider than a regular
    // tetrahedron's faces: at full resolution, only a sliver lying along a great circle).
    // Such an "accordion" face has a fat chord triangle, so the measured stretch does not
    // see it collapse; without the split, generated limb shapes ended with faces of sphere
    // area ~1e-16 (degenerate for evalsphere.py), one step from a flip (issue 20).
    OptimizerSettings final_settings = s_;
    final_settings.split_distance = 0.25;
    final_settings.global_iter = s_.final_iter;
    final_settings.precise_vertices = 0;  // the coarse layout's precision (a small mesh's last level is not coarse)
    final_settings.fine_split_distance = 0;
    final_settings.area_floor_rel = OptimizerSettings{}.area_floor_rel;  // the measured objective
    // With measured_normalization the pass minimizes the measured efficiency itself: the
    // stretch normalized by the chord area the faces cover (SphereState::chord_area_penalty).
    st_.chord_area_penalty = s_.measured_normalization;
    SPHEREKIT_RETURN_IF_ERROR(optimize_level(final_settings));
    if (s_.outlier_polish) polish_outlier_faces();
    *S = st_.S;
    return Status();
  }

 private:
  // The largest stretch of v's real faces with v at x, and their L2 stretch energy over the
  // sphere (chord area x (a + c) / 2).
  void ring_stretch(int v, const Eigen::Vector3d& x, double* worst, double* energy) const {
    *worst = 0, *energy = 0;
    for (int f : st_.vf[static_cast<size_t>(v)]) {
      if (!in_.face_weight.empty() && in_.face_weight[static_cast<size_t>(f)] < 1.0) continue;
      double s1, e;
      face_stretch(f, v, x, &s1, &e);
      *worst = std::max(*worst, s1);
      *energy += e;
    }
  }
  // Face f's largest singular value (map chord triangle -> surface) and L2 stretch energy
  // over the sphere, with v at x.
  void face_stretch(int f, int v, const Eigen::Vector3d& x, double* s1, double* energy) const {
    const auto& c = st_.F[static_cast<size_t>(f)];
    const double* q[3];
    for (int k = 0; k < 3; ++k) q[k] = c[k] == v ? x.data() : st_.S.row(c[k]).data();
    const StretchTerms t = stretch_terms(st_.P->row(c[0]).data(), st_.P->row(c[1]).data(), st_.P->row(c[2]).data(),
                                         q[0], q[1], q[2]);  // one model: a row is its 3 coordinates
    if (!(t.area_domain > 0)) {
      *s1 = *energy = std::numeric_limits<double>::infinity();
      return;
    }
    *s1 = std::sqrt(0.5 * (t.a + t.c + singular_disc(t)));
    *energy = t.area_domain * 0.5 * (t.a + t.c);
  }

  // Outlier faces after the final pass (issue 20's Linf rule): the L2 energy weighs a face by
  // its area (plus a floor), so a sliver of scan or iso-surface debris (area ~1e-7 of the
  // mean face) may keep a stretch hundreds of times the rest's wherever its cluster's L2
  // optimum happens to put it: generated quadruped_r96-holes gave Linf 29.5 or 1071 with
  // progressive meshes of equal quality. Each vertex of a face stretched more than 10x the
  // 99th percentile is moved, within its kernel (exact predicate), to lower its ring's
  // largest stretch, as long as the L2 stretch energy over the sphere (chord area x
  // stretch^2 over the real faces) grows by at most 1e-7 of the total over all moves.
  void polish_outlier_faces() {
    if (st_.models != 1) return;
    const int nf = static_cast<int>(st_.F.size());
    std::vector<double> sigma;
    std::vector<int> faces;
    double total = 0;
    for (int f = 0; f < nf; ++f) {
      if (!st_.face_alive[static_cast<size_t>(f)]) continue;
      if (!in_.face_weight.empty() && in_.face_weight[static_cast<size_t>(f)] < 1.0) continue;
      const int v = st_.F[static_cast<size_t>(f)][0];
      double s1, e;
      face_stretch(f, v, st_.S.row(v).transpose(), &s1, &e);
      sigma.push_back(s1);
      faces.push_back(f);
      total += e;
    }
    if (sigma.size() < 100 || !std::isfinite(total)) return;
    std::vector<double> sorted = sigma;
    const size_t k99 = sorted.size() * 99 / 100;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k99), sorted.end());
    const double limit = 10 * sorted[k99];
    std::vector<int> verts;
    for (size_t i = 0; i < sigma.size(); ++i)
      if (sigma[i] > limit)
        for (int v : st_.F[static_cast<size_t>(faces[i])])
          if (st_.fixed.empty() || !st_.fixed[static_cast<size_t>(v)]) verts.push_back(v);
    if (verts.empty()) return;
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    double budget = 1e-7 * total;
    RingScratch& ring = rings_[0];
    for (int iter = 0; iter < 8; ++iter)
      for (int v : verts) {
        if (!load_ring(st_, v, ring)) continue;
        const Eigen::Vector3d x0 = st_.S.row(v).transpose();
        double best_m, e0;
        ring_stretch(v, x0, &best_m, &e0);
        double best_e = e0;
        Eigen::Vector3d best = x0;
        double reach = std::numeric_limits<double>::infinity();
        for (int f : st_.vf[static_cast<size_t>(v)])
          for (int w : st_.F[static_cast<size_t>(f)])
            if (w != v) reach = std::min(reach, (st_.S.row(w).transpose() - x0).norm());
        Eigen::Vector3d e1, e2;
        tangent_basis(x0, e1, e2);
        for (double step = 0.5 * reach; step > 1e-6 * reach; step *= 0.25)
          for (int k = 0; k < 16; ++k) {
            const double a = 2 * M_PI * (k + 0.5 * (iter % 2)) / 16;
            const Eigen::Vector3d y = (best + step * (std::cos(a) * e1 + std::sin(a) * e2)).normalized();
            double m, e;
            ring_stretch(v, y, &m, &e);
            if (!(m < best_m) || !(e - e0 <= budget) || !ring_valid_exact(ring, y)) continue;
            best = y, best_m = m, best_e = e;
          }
        if (best != x0) {
          st_.S.row(v) = best.transpose();
          budget -= best_e - e0;  // a move that lowers the energy gives budget back
        }
      }
  }

  int next_threshold(int nv) const {
    // Extra optimization at coarse levels (ratio sqrt(r) up to 1000 vertices), as the
    // reference implementation does: coarse levels decide the global layout.
    double r = nv <= kCoarseLevelVertices ? std::sqrt(s_.nv_ratio) : s_.nv_ratio;
    return std::max(nv + 1, static_cast<int>(std::lround(nv * r)));
  }

  void init_base_level() {
    st_.edge_frame_cruft = s_.edge_frame_cruft;  // every level and the splits' local moves
    const int nv = pm_.num_vertices;
    const int nf = static_cast<int>(pm_.F.rows());
    st_.P = in_.P;
    st_.models = static_cast<int>(in_.P->cols() / 3);
    st_.F.resize(static_cast<size_t>(nf));
    for (int f = 0; f < nf; ++f) st_.F[static_cast<size_t>(f)] = {pm_.F(f, 0), pm_.F(f, 1), pm_.F(f, 2)};
    st_.face_alive.assign(static_cast<size_t>(nf), 1);
    st_.vertex_alive.assign(static_cast<size_t>(nv), 1);
    st_.face_weight = in_.face_weight.empty() ? std::vector<double>(static_cast<size_t>(nf), 1.0) : in_.face_weight;
    st_.face_shape_weight = in_.face_shape_weight;
    st_.fixed = in_.fixed;
    // The corners of the faces that close holes, at full resolution (update_hole_faces).
    hole_vertex_.assign(static_cast<size_t>(nv), 0);
    for (size_t f = 0; f < in_.face_weight.size(); ++f)
      if (in_.face_weight[f] < 1.0)
        for (int v : st_.F[f]) hole_vertex_[static_cast<size_t>(v)] = 1;
    // Replay the collapses forward to recover the base level's corners.
    for (const auto& c : pm_.collapses) {
      for (int f : c.removed) st_.face_alive[static_cast<size_t>(f)] = 0;
      for (int j = c.moved_begin; j < c.moved_end; ++j)
        for (int& v : st_.F[static_cast<size_t>(pm_.moved_faces[static_cast<size_t>(j)])])
          if (v == c.vt) v = c.vs;
      st_.vertex_alive[static_cast<size_t>(c.vt)] = 0;
    }
    st_.vf.assign(static_cast<size_t>(nv), {});
    for (int f = 0; f < nf; ++f)
      if (st_.face_alive[static_cast<size_t>(f)])
        for (int v : st_.F[static_cast<size_t>(f)]) st_.vf[static_cast<size_t>(v)].push_back(f);
    st_.alive_vertices = nv - static_cast<int>(pm_.collapses.size());
    st_.S = RowMat3d::Zero(nv, 3);
  }

  Status place_base() {
    if (in_.base_positions.rows() == st_.S.rows()) {
      for (int v : pm_.base_vertices) st_.S.row(v) = in_.base_positions.row(v).normalized();
    } else {
      if (pm_.base_vertices.size() != 4 || pm_.base_faces.size() != 4)
        return Status(ErrorCode::SolverFailed, "progressive mesh base is not a tetrahedron (" +
                                                   std::to_string(pm_.base_vertices.size()) + " vertices)");
      // Regular tetrahedron inscribed in the unit sphere; base face 0's corners get T0, T1,
      // T2 in ccw order with det[T0,T1,T2] > 0, so orientation is preserved.
      const double k = 1.0 / std::sqrt(3.0);
      Eigen::Vector3d T[4] = {{k, k, k}, {k, -k, -k}, {-k, k, -k}, {-k, -k, k}};
      if (orient3d_origin(T[0], T[1], T[2]) < 0) std::swap(T[1], T[2]);
      const auto& f0 = st_.F[static_cast<size_t>(pm_.base_faces[0])];
      int d = -1;
      for (int v : pm_.base_vertices)
        if (v != f0[0] && v != f0[1] && v != f0[2]) d = v;
      st_.S.row(f0[0]) = T[0].transpose();
      st_.S.row(f0[1]) = T[1].transpose();
      st_.S.row(f0[2]) = T[2].transpose();
      st_.S.row(d) = T[3].transpose();
    }
    for (int f : pm_.base_faces) {
      const auto& c = st_.F[static_cast<size_t>(f)];
      if (orient3d_origin(st_.S.row(c[0]).data(), st_.S.row(c[1]).data(), st_.S.row(c[2]).data()) <= 0)
        return Status(ErrorCode::SolverFailed, "base mesh is not consistently oriented on the sphere");
    }
    return Status();
  }

  void apply_split(int i) {
    const auto& c = pm_.collapses[static_cast<size_t>(i)];
    st_.vertex_alive[static_cast<size_t>(c.vt)] = 1;
    ++st_.alive_vertices;
    auto& vs_faces = st_.vf[static_cast<size_t>(c.vs)];
    for (int j = c.moved_begin; j < c.moved_end; ++j) {
      int f = pm_.moved_faces[static_cast<size_t>(j)];
      for (int& v : st_.F[static_cast<size_t>(f)])
        if (v == c.vs) v = c.vt;
      vs_faces.erase(std::find(vs_faces.begin(), vs_faces.end(), f));
      st_.vf[static_cast<size_t>(c.vt)].push_back(f);
    }
    for (int s = 0; s < 2; ++s) {
      int f = c.removed[static_cast<size_t>(s)];
      st_.F[static_cast<size_t>(f)] = pm_.removed_corners[2 * static_cast<size_t>(i) + static_cast<size_t>(s)];
      st_.face_alive[static_cast<size_t>(f)] = 1;
      for (int v : st_.F[static_cast<size_t>(f)]) st_.vf[static_cast<size_t>(v)].push_back(f);
    }
  }

  // Split i's region: the vertices within `radius` of vs before the split, and vt. Placing vt
  // reads vt's faces and its neighbours' positions and writes vt (radius 1); with neighbour
  // moves (vsplit_nei_iter) it reads vt's 2-ring and writes its 1-ring (radius 2). After the
  // split, vt's k-ring lies in vs's closed k-ring before it plus vt, and the split itself
  // changes only faces and face lists of vertices in vt's closed 1-ring. So two splits with
  // disjoint regions neither read nor write anything of each other's. Returns false (and
  // marks nothing) if split i's region meets one claimed since the last stamp; the first
  // split of a run always gets its region.
  bool claim_split_region(int i) {
    const auto& c = pm_.collapses[static_cast<size_t>(i)];
    const int radius = s_.vsplit_nei_iter > 0 ? 2 : 1;
    ++seen_stamp_;
    region_.clear();
    auto add = [&](int v) {
      if (seen_mark_[static_cast<size_t>(v)] == seen_stamp_) return;
      seen_mark_[static_cast<size_t>(v)] = seen_stamp_;
      region_.push_back(v);
    };
    add(c.vt);
    add(c.vs);
    size_t begin = 1;
    for (int r = 0; r < radius; ++r) {
      const size_t end = region_.size();
      for (size_t k = begin; k < end; ++k)
        for (int f : st_.vf[static_cast<size_t>(region_[k])])
          for (int w : st_.F[static_cast<size_t>(f)]) add(w);
      begin = end;
    }
    if (!batch_.empty())
      for (int v : region_)
        if (region_mark_[static_cast<size_t>(v)] == region_stamp_) return false;
    for (int v : region_) region_mark_[static_cast<size_t>(v)] = region_stamp_;
    return true;
  }

  // Places the new vertices of the splits in batch_ (already applied), in parallel; the
  // first failure in split order is returned.
  Status place_batch() {
    const int n = static_cast<int>(batch_.size());
    placed_.assign(static_cast<size_t>(n), 0);
    pool_.parallel_for(n, 1, 2, [&](int j, int thread) {
      placed_[static_cast<size_t>(j)] = place_new_vertex(batch_[static_cast<size_t>(j)], rings_[static_cast<size_t>(thread)]);
    });
    for (int j = 0; j < n; ++j) {
      if (placed_[static_cast<size_t>(j)] == 0)
        return Status(ErrorCode::SolverFailed,
                      "could not place vertex " + std::to_string(pm_.collapses[static_cast<size_t>(batch_[static_cast<size_t>(j)])].vt) +
                          " inside its spherical kernel");
      if (placed_[static_cast<size_t>(j)] == 2) ++stats_->fallback_placements;
    }
    return Status();
  }

  // Returns 0 if vt could not be placed, 1 if placed at the kernel centroid, 2 by a fallback.
  int place_new_vertex(int i, RingScratch& ring) {
    int result = 1;
    const int vt = pm_.collapses[static_cast<size_t>(i)].vt;
    load_ring(st_, vt, ring);
    Eigen::Vector3d x;
    bool ok = kernel_centroid(ring, &x) && ring_valid_exact(ring, x);
    if (!ok) {
      result = 2;
      Eigen::Vector3d start = st_.S.row(pm_.collapses[static_cast<size_t>(i)].vs).transpose();
      Eigen::Vector3d c;
      if (kernel_centroid(ring, &c)) start = c;
      ok = kernel_chebyshev(ring, start, &x) ||
           kernel_near_vertex(ring, st_.S.row(pm_.collapses[static_cast<size_t>(i)].vs).transpose(), &x);
    }
    if (!ok) return 0;
    st_.S.row(vt) = x.transpose();
    std::uint64_t key = s_.seed * 0x9e3779b97f4a7c15ULL + static_cast<std::uint64_t>(i);
    for (int k = 0; k < s_.vsplit_vt_iter; ++k) {
      Eigen::Vector3d y;
      if (optimize_vertex(st_, vt, key + static_cast<std::uint64_t>(k) * 7919, s_, ring, &y, 2))
        st_.S.row(vt) = y.transpose();
    }
    if (s_.vsplit_nei_iter > 0) {
      load_ring(st_, vt, ring);
      std::vector<int> nbrs;
      for (const auto& rf : ring.faces) nbrs.push_back(rf.a);
      for (int k = 0; k < s_.vsplit_nei_iter; ++k)
        for (int w : nbrs) {
          if (!st_.fixed.empty() && st_.fixed[static_cast<size_t>(w)]) continue;
          Eigen::Vector3d y;
          if (optimize_vertex(st_, w, key ^ (static_cast<std::uint64_t>(w) << 20) ^ static_cast<std::uint64_t>(k), s_, ring, &y, 2))
            st_.S.row(w) = y.transpose();
        }
    }
    return result;
  }

  Status optimize_level() { return optimize_level(s_); }

  // Faces that close holes keep their low weight (and shape term) only while they lie in a
  // hole: all three corners on a hole's rim or its centre. At coarse levels the progressive
  // mesh can replace a rim corner by a vertex of the surface around it; such a face then
  // spans real surface, and treated as nearly free (and, with the hole-area penalty, paid
  // for taking sphere area from the real faces) it let coarse levels give whole regions' share
  // of the sphere to it: generated shapes with many small holes on thin limbs ended with
  // limbs squeezed, at an efficiency that changed with the seed by a factor of 1.7 (issue 20).
  void update_hole_faces() {
    if (in_.face_weight.empty()) return;
    for (size_t f = 0; f < st_.F.size(); ++f) {
      if (!(in_.face_weight[f] < 1.0) || !st_.face_alive[f]) continue;
      bool inside = true;
      for (int v : st_.F[f]) inside = inside && hole_vertex_[static_cast<size_t>(v)];
      st_.face_weight[f] = inside ? in_.face_weight[f] : 1.0;
      if (!st_.face_shape_weight.empty())
        st_.face_shape_weight[f] = inside ? in_.face_shape_weight[f] : 0.0;
    }
  }

  Status optimize_level(const OptimizerSettings& level_settings) {
    // Above the coarse levels (fine_split_vertices: kCoarseLevelVertices) only faces wider
    // than about 18 degrees take the accordion split (fine_split_distance). There the layout
    // is set and the faces the 0.99 test still splits are mostly small obtuse ones, whose
    // split energy equals their chord energy to second order in their size, at ten times the
    // cost of its central differences: on the generated tentacle shape the split faces were
    // half of the CPU time (issue 20: tentacles_r96-holes 14.1 -> 9.6 s, efficiency 0.1862 ->
    // 0.1848 against the reference implementation's 0.1566, with the boundary at the precise
    // layout's 3000 vertices). The boundary is now the coarse levels' own (session 45): on
    // limb shapes of 4-5k vertices the levels from 1000 to 3000 were 60% of the time, at 2.5x
    // the cost per vertex of the levels above (CPU -10 to -25%, tentacles_r48-holes 5.5 ->
    // 4.2 s; efficiency within -0.006..+0.001 on 73 meshes, all still above the reference).
    OptimizerSettings s = level_settings;
    if (s.fine_split_distance > 0 && st_.alive_vertices > s.fine_split_vertices)
      s.split_distance = s.fine_split_distance;
    update_hole_faces();
    // The levels weight each face by its area plus a share of the mean face area
    // (area_floor_rel; 3% with precise_layout), the final pass by its area alone. With the
    // area alone, faces of tiny surface area (decimation slivers, scan debris) cost nothing
    // however far they are squeezed on the sphere, and the layout could settle around them:
    // bunny_planar's Linf went 4.1-10 with any change of schedule (one sliver of 1.3% of the
    // mean area), and head_s4_dec4000 kept a basin at 0.780 (the reference 0.830). Measured
    // with the floor (issue 20): 0.835 and Linf 4.1 (the reference's 4.04), the 40 meshes of
    // the stress tables and the 18 shared meshes all still above the reference.
    st_.area_floor_rel = s.area_floor_rel;
    st_.update_areas();
    RingIndex rings;  // this level's: the passes below do not change the connectivity
    for (int g = 0; g < s.global_iter; ++g) {
      std::uint64_t pass_key = s_.seed * 0xd1b54a32d192ed03ULL + static_cast<std::uint64_t>(stats_->passes) * 0x8cb92ba72f3d8dd7ULL;
      bool exceeded = false;
      int rounds = optimize_all(
          st_, s, pass_key, [&] { return report_progress(progress_, "optimize", st_.alive_vertices, -1.0); },
          &pool_, &exceeded, &rings);
      if (rounds < 0) return Status(ErrorCode::Cancelled, "cancelled during optimization");
      if (exceeded)
        return Status(ErrorCode::SolverFailed,
                      "the stretch optimization did not converge (a pass over " + std::to_string(st_.alive_vertices) +
                          " vertices needed more than " + std::to_string(static_cast<int>(s.max_pass_work)) +
                          " moves per vertex; normal maps need at most about 31)");
      ++stats_->passes;
      stats_->rounds += rounds;
    }
    return Status();
  }

  const EmbedInput& in_;
  const ProgressiveMesh& pm_;
  const OptimizerSettings& s_;
  const ProgressFn& progress_;
  EmbedStats* stats_;
  SphereState st_;
  std::vector<RingScratch> rings_;  // one per thread
  static constexpr size_t kMaxBatch = 256;
  std::vector<int> batch_, region_;
  std::vector<char> placed_;
  std::vector<std::uint32_t> region_mark_, seen_mark_;  // stamps: claimed by the run; in region_
  std::uint32_t region_stamp_ = 0, seen_stamp_ = 0;
  std::vector<char> hole_vertex_;  // corners of the faces that close holes, at full resolution
  WorkerPool pool_;  // one set of threads for every pass of the run
};

}  // namespace

Status embed_coarse_to_fine(const EmbedInput& in, const OptimizerSettings& s, const ProgressFn& progress,
                            RowMat3d* S, EmbedStats* stats) {
  EmbedStats local;
  if (!stats) stats = &local;
  Refiner r(in, s, progress, stats);
  return r.run(S);
}

Status optimize_in_place(const RowMatXd& P, const RowMat3i& F, const std::vector<double>& face_weight,
                         const std::vector<double>& shape_weight, const std::vector<char>& fixed,
                         const OptimizerSettings& s, const ProgressFn& progress, RowMat3d* S) {
  ProgressiveMesh pm;
  pm.num_vertices = static_cast<int>(P.rows());
  pm.F = F;
  for (int v = 0; v < pm.num_vertices; ++v) pm.base_vertices.push_back(v);
  for (int f = 0; f < F.rows(); ++f) pm.base_faces.push_back(f);
  EmbedInput in;
  in.P = &P;
  in.pm = &pm;
  in.face_weight = face_weight;
  in.face_shape_weight = shape_weight;
  in.base_positions = *S;
  in.fixed = fixed;
  return embed_coarse_to_fine(in, s, progress, S, nullptr);
}

}  // namespace spherekit::detail
