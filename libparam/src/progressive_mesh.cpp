// Progressive mesh by half-edge collapses at original positions.
//   Hoppe 1996, "Progressive meshes" (vertex split / edge collapse records);
//   Garland & Heckbert 1997/1998 (quadric error, n-D form, see detail/quadric.h);
//   Praun & Hoppe 2003 §4 (half-edge collapses to a tetrahedron as the base of the
//   coarse-to-fine spherical parameterization).
//
// Design: faces keep their ids for the whole run (dead faces are flagged), so a collapse is
// recorded as "these faces had vt replaced by vs" plus "these two faces were removed with
// these corners"; replaying the records backwards restores every intermediate mesh exactly.
// Costs live in a binary heap with lazy invalidation by per-vertex stamps: a vertex's stamp
// changes when its quadric does (it received a collapse), which is the only time the cost
// of its edges changes. Legality (link condition, fold-over) depends on the neighbourhood
// and is re-checked when an entry is popped; edges rejected then are retried by a full
// rebuild of the heap when it runs dry.
//
// Cost: O(F log F) time, O(V d^2) memory for the quadrics.
#include "spherekit/progressive_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <string>

#include "detail/parallel_jobs.h"
#include "detail/quadric.h"

namespace spherekit {
namespace {

struct HeapEntry {
  double cost;
  int vt, vs;
  std::uint32_t stamp_t, stamp_s;
};
struct HeapGreater {
  bool operator()(const HeapEntry& a, const HeapEntry& b) const {
    if (a.cost != b.cost) return a.cost > b.cost;
    if (a.vt != b.vt) return a.vt > b.vt;  // ties broken by ids: deterministic
    return a.vs > b.vs;
  }
};

// Min-heap of vertices keyed by each one's cheapest untried collapse, with positions, so a
// key can change in place (memoryless quadrics: see Simplifier::refresh).
class VertexHeap {
 public:
  void reset(int nv) {
    pos_.assign(static_cast<size_t>(nv), -1);
    heap_.clear();
  }
  bool empty() const { return heap_.empty(); }
  int top() const { return heap_.front(); }
  // Inserts v, or moves it to its new key's place.
  template <class Key>
  void update(int v, const Key& key) {
    int i = pos_[static_cast<size_t>(v)];
    if (i < 0) {
      i = static_cast<int>(heap_.size());
      heap_.push_back(v);
      pos_[static_cast<size_t>(v)] = i;
    }
    sift_down(sift_up(i, key), key);
  }
  template <class Key>
  void remove(int v, const Key& key) {
    const int i = pos_[static_cast<size_t>(v)];
    if (i < 0) return;
    pos_[static_cast<size_t>(v)] = -1;
    const int last = heap_.back();
    heap_.pop_back();
    if (last == v) return;
    heap_[static_cast<size_t>(i)] = last;
    pos_[static_cast<size_t>(last)] = i;
    sift_down(sift_up(i, key), key);
  }

 private:
  template <class Key>
  int sift_up(int i, const Key& key) {
    const int v = heap_[static_cast<size_t>(i)];
    while (i > 0) {
      const int parent = (i - 1) / 2;
      if (!HeapGreater()(key(heap_[static_cast<size_t>(parent)]), key(v))) break;
      place(i, heap_[static_cast<size_t>(parent)]);
      i = parent;
    }
    place(i, v);
    return i;
  }
  template <class Key>
  void sift_down(int i, const Key& key) {
    const int n = static_cast<int>(heap_.size());
    const int v = heap_[static_cast<size_t>(i)];
    for (;;) {
      int child = 2 * i + 1;
      if (child >= n) break;
      if (child + 1 < n && HeapGreater()(key(heap_[static_cast<size_t>(child)]), key(heap_[static_cast<size_t>(child) + 1])))
        ++child;
      if (!HeapGreater()(key(v), key(heap_[static_cast<size_t>(child)]))) break;
      place(i, heap_[static_cast<size_t>(child)]);
      i = child;
    }
    place(i, v);
  }
  void place(int i, int v) {
    heap_[static_cast<size_t>(i)] = v;
    pos_[static_cast<size_t>(v)] = i;
  }
  std::vector<int> heap_, pos_;
};

// Below this triangle quality a collapse may not make things worse (a quality-0.02 triangle
// has angles around 1 degree); the forced last-resort mode ignores it.
constexpr double kMinQuality = 0.02;

double quality(const Eigen::Vector3d* p, const Eigen::Vector3d& n) {
  double l2 = (p[1] - p[0]).squaredNorm() + (p[2] - p[1]).squaredNorm() + (p[0] - p[2]).squaredNorm();
  return l2 > 0 ? 2.0 * std::sqrt(3.0) * n.norm() / l2 : 0.0;
}

class Simplifier {
 public:
  // X: the quadric coordinates, if already made (a block's rows of the whole mesh's, whose
  // vertex normals see every face); frozen: vertices that neither move nor receive.
  Simplifier(const RowMatXd& P, const RowMat3i& F, const ProgressiveMeshOptions& opt, const RowMatXd* X = nullptr,
             std::vector<char> frozen = {}, const std::vector<double>* area = nullptr)
      : P_(P), opt_(opt), d_(static_cast<int>(P.cols())), nv_(static_cast<int>(P.rows())), frozen_(std::move(frozen)) {
    const int nf = static_cast<int>(F.rows());
    if (X) {
      X_ = *X;
      qd_ = static_cast<int>(X_.cols());
    } else {
      build_quadric_coordinates(F);
    }
    if (opt_.model_planes) {
      for (int b = 0; b + 2 < d_; b += 3) plane_blocks_.push_back({b, b + 3});
    } else {
      plane_blocks_.push_back({0, qd_});
    }
    faces_.resize(static_cast<size_t>(nf));
    face_alive_.assign(static_cast<size_t>(nf), 1);
    vf_.resize(static_cast<size_t>(nv_));
    for (int f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        faces_[f][k] = F(f, k);
        vf_[static_cast<size_t>(F(f, k))].push_back(f);
      }
    }
    vertex_alive_.assign(static_cast<size_t>(nv_), 1);
    stamp_.assign(static_cast<size_t>(nv_), 0);
    // Accumulated quadrics only where they are read (memoryless costs measure the current faces).
    if (!opt_.memoryless) quadric_.assign(static_cast<size_t>(nv_), detail::QuadricND(qd_));
    area_.assign(static_cast<size_t>(nv_), 0.0);
    for (int f = 0; f < nf; ++f) {
      double w = opt_.face_weights.empty() ? 1.0 : opt_.face_weights[static_cast<size_t>(f)];
      double area = face_area(faces_[f]) * w;
      if (!opt_.memoryless) {
        detail::QuadricND q(qd_);
        const double* x[3] = {X_.row(F(f, 0)).data(), X_.row(F(f, 1)).data(), X_.row(F(f, 2)).data()};
        if (opt_.model_planes) {
          for (int b = 0; b + 2 < d_; b += 3) q.add_triangle(x[0], x[1], x[2], w * block_area(faces_[f], b), b, b + 3);
        } else {
          q.add_triangle(x[0], x[1], x[2], area);
        }
        for (int k = 0; k < 3; ++k) quadric_[static_cast<size_t>(F(f, k))].add(q);
      }
      for (int k = 0; k < 3; ++k) area_[static_cast<size_t>(F(f, k))] += area / 3.0;
    }
    if (area) area_ = *area;  // a block's vertices carry what they have accumulated
    alive_count_ = nv_;
    path_nbr_.resize(static_cast<size_t>(nv_));
    for (const auto& e : opt_.constraint_edges) {
      path_nbr_[static_cast<size_t>(e[0])].push_back(e[1]);
      path_nbr_[static_cast<size_t>(e[1])].push_back(e[0]);
    }
  }

  Status run(ProgressiveMesh& pm, const ProgressFn& progress) {
    const int target = std::max(4, opt_.target_vertices);
    const int total = std::max(1, nv_ - target);
    bool forced = false;
    int last_report = -1;
    while (alive_count_ > target) {
      rebuild_heap();
      int collapsed_this_round = 0;
      while (alive_count_ > target && (opt_.memoryless ? !vheap_.empty() : !heap_.empty())) {
        if (opt_.memoryless) {
          const int vt = vheap_.top();
          const int vs = best_[static_cast<size_t>(vt)].vs;
          if (!collapse_if_legal(vt, vs, forced, pm)) {
            drop_candidate(vt, vs);
            continue;
          }
        } else {
          HeapEntry e = heap_.top();
          heap_.pop();
          if (!live(e)) continue;
          if (!collapse_if_legal(e.vt, e.vs, forced, pm)) continue;
        }
        ++collapsed_this_round;
        int done = nv_ - alive_count_;
        int pct = static_cast<int>(100.0 * done / total);
        if (pct != last_report) {
          last_report = pct;
          if (!report_progress(progress, "simplify", alive_count_, static_cast<double>(done) / total))
            return Status(ErrorCode::Cancelled, "cancelled during simplification");
        }
      }
      if (alive_count_ <= target) break;
      if (collapsed_this_round == 0) {
        // Nothing legal under the geometric checks: allow fold-overs as a last resort (the
        // sphere embedding does not depend on the 3D quality of coarse levels), keeping
        // the topological link condition, which alone guarantees a valid progressive mesh.
        if (forced)
          return Status(ErrorCode::SolverFailed,
                        "simplification stuck at " + std::to_string(alive_count_) +
                            " vertices (no legal edge collapse; is the mesh genus 0 and manifold?)");
        forced = true;
      }
    }
    for (int v = 0; v < nv_; ++v)
      if (vertex_alive_[v]) pm.base_vertices.push_back(v);
    for (size_t f = 0; f < faces_.size(); ++f)
      if (face_alive_[f]) pm.base_faces.push_back(static_cast<int>(f));
    return Status();
  }

  // Parallel fine levels (ProgressiveMeshOptions::block_vertices). Why it gives the same
  // collapses as the greedy would inside each block: a collapse vt -> vs reads and writes
  // only the faces around vt and vs and their vertices' entries, and its cost reads vt's
  // faces, vt's area and fixed positions. A vertex whose neighbours are all in its own block
  // has all its faces in that block's submesh, so a collapse between two such vertices sees
  // exactly what it would see in the whole mesh, and blocks touch disjoint data. Vertices
  // next to another block (frozen) neither move nor receive. The blocks' collapses are then
  // merged by cost (each block's order kept) and replayed here; the records are those of the
  // whole mesh. Rounds repeat on the vertices left, in blocks of the same size (so larger
  // regions: the previous round's frozen seams are inside them), while at least two blocks
  // remain. The blocks come from the positions alone (Morton order, equal counts), so the
  // result does not depend on the thread count.
  Status presimplify_blocks(ProgressiveMesh& pm, const ProgressFn& progress) {
    const int size = std::max(1, opt_.block_vertices);
    // Morton order of the first model's positions, 21 bits per axis, once for all rounds.
    const Eigen::RowVector3d lo = P_.leftCols(3).colwise().minCoeff(), hi = P_.leftCols(3).colwise().maxCoeff();
    const double extent = std::max((hi - lo).maxCoeff(), 1e-300);
    std::vector<std::pair<std::uint64_t, int>> order(static_cast<size_t>(nv_));
    for (int v = 0; v < nv_; ++v) {
      std::uint64_t key = 0;
      for (int a = 0; a < 3; ++a) {
        const double t = std::clamp((P_(v, a) - lo[a]) / extent, 0.0, 1.0);
        const std::uint64_t q = static_cast<std::uint64_t>(t * 2097151.0);
        for (int b = 0; b < 21; ++b) key |= ((q >> b) & 1ULL) << (3 * b + a);
      }
      order[static_cast<size_t>(v)] = {key, v};
    }
    std::sort(order.begin(), order.end());
    std::vector<int> block(static_cast<size_t>(nv_)), local(static_cast<size_t>(nv_));
    std::vector<char> frozen(static_cast<size_t>(nv_));
    // A mesh of 1.5 to 2 blocks' vertices is cut in two for its first round (igea decimated
    // to 13k vertices: its serial simplification was 11% of the one-thread time, 2-thread /
    // 1-thread wall 0.65); later rounds, and meshes of two blocks or more, as before.
    for (bool first = true;
         alive_count_ >= 2 * size || (first && 2 * static_cast<long long>(alive_count_) >= 3LL * size);
         first = false) {
      const int blocks = std::max(2, alive_count_ / size);
      std::vector<std::vector<int>> members(static_cast<size_t>(blocks)), faces(static_cast<size_t>(blocks));
      for (int k = 0, alive = 0; k < nv_; ++k) {
        const int v = order[static_cast<size_t>(k)].second;
        if (!vertex_alive_[static_cast<size_t>(v)]) continue;
        const int b = static_cast<int>(static_cast<long long>(alive++) * blocks / alive_count_);
        block[static_cast<size_t>(v)] = b;
        local[static_cast<size_t>(v)] = static_cast<int>(members[static_cast<size_t>(b)].size());
        members[static_cast<size_t>(b)].push_back(v);
        frozen[static_cast<size_t>(v)] = 0;
      }
      for (size_t f = 0; f < faces_.size(); ++f) {
        if (!face_alive_[f]) continue;
        const auto& c = faces_[f];
        const int b = block[static_cast<size_t>(c[0])];
        if (block[static_cast<size_t>(c[1])] == b && block[static_cast<size_t>(c[2])] == b) {
          faces[static_cast<size_t>(b)].push_back(static_cast<int>(f));
        } else {
          for (int v : c) frozen[static_cast<size_t>(v)] = 1;
        }
      }
      struct BlockCollapse {
        double cost;
        int vt, vs;
      };
      std::vector<std::vector<BlockCollapse>> done(static_cast<size_t>(blocks));
      std::vector<int> movable_count(static_cast<size_t>(blocks), 0);
      SPHEREKIT_RETURN_IF_ERROR(detail::run_parallel_jobs(
          blocks, opt_.threads, "simplify", progress, [&](int b, int, const std::function<bool()>& keep_going) -> Status {
            const auto& mv = members[static_cast<size_t>(b)];
            const auto& mf = faces[static_cast<size_t>(b)];
            const int n = static_cast<int>(mv.size());
            RowMatXd Pb(n, d_), Xb(n, qd_);
            std::vector<char> fb(static_cast<size_t>(n));
            std::vector<double> ab(static_cast<size_t>(n));
            int movable = 0;
            for (int i = 0; i < n; ++i) {
              const int v = mv[static_cast<size_t>(i)];
              Pb.row(i) = P_.row(v);
              Xb.row(i) = X_.row(v);
              ab[static_cast<size_t>(i)] = area_[static_cast<size_t>(v)];
              fb[static_cast<size_t>(i)] = frozen[static_cast<size_t>(v)];
              movable += fb[static_cast<size_t>(i)] ? 0 : 1;
            }
            RowMat3i Fb(static_cast<Eigen::Index>(mf.size()), 3);
            ProgressiveMeshOptions ob = opt_;
            ob.block_vertices = 0;
            if (!opt_.face_weights.empty()) ob.face_weights.resize(mf.size());
            for (size_t j = 0; j < mf.size(); ++j) {
              for (int k = 0; k < 3; ++k)
                Fb(static_cast<Eigen::Index>(j), k) = local[static_cast<size_t>(faces_[static_cast<size_t>(mf[j])][k])];
              if (!opt_.face_weights.empty()) ob.face_weights[j] = opt_.face_weights[static_cast<size_t>(mf[j])];
            }
            movable_count[static_cast<size_t>(b)] = movable;
            // Past the share kept below: the cut by cost decides how far each block goes.
            const int target = (n - movable) + static_cast<int>(std::ceil(0.25 * opt_.block_fraction * movable));
            Simplifier sb(Pb, Fb, ob, &Xb, std::move(fb), &ab);
            std::vector<BlockCollapse>& out = done[static_cast<size_t>(b)];
            return sb.run_block(target, keep_going, [&](double cost, int vt, int vs) {
              out.push_back({cost, mv[static_cast<size_t>(vt)], mv[static_cast<size_t>(vs)]});
            });
          }));
      // One cost cut for all blocks, as the greedy over the whole mesh has one cost level at
      // any moment: a block of thin limbs (costly collapses, kept to coarse levels by the
      // normal term) stops early, a flat one goes on. Each block keeps the prefix of its
      // collapses whose running maximum cost is below the cut, chosen so that the blocks
      // keep at most (1 - block_fraction) of their movable vertices' collapses in all. With
      // a share per block instead, a generated biped with holes lost 0.021 of efficiency.
      std::vector<double> levels;
      long long movable_total = 0;
      for (int b = 0; b < blocks; ++b) {
        movable_total += movable_count[static_cast<size_t>(b)];
        double running = -kInfCost;
        for (BlockCollapse& c : done[static_cast<size_t>(b)]) {
          running = std::max(running, c.cost);
          c.cost = running;  // from here on: the running maximum
          levels.push_back(running);
        }
      }
      const size_t goal = static_cast<size_t>(std::floor((1.0 - opt_.block_fraction) * static_cast<double>(movable_total)));
      if (goal < levels.size()) {
        std::nth_element(levels.begin(), levels.begin() + static_cast<std::ptrdiff_t>(goal), levels.end());
        const double cut = levels[goal];
        for (auto& d : done) {
          size_t keep = 0;
          while (keep < d.size() && d[keep].cost < cut) ++keep;
          d.resize(keep);
        }
      }
      // Merge by cost, each block's order kept (ties: the lower block first), and replay.
      std::vector<size_t> head(static_cast<size_t>(blocks), 0);
      const int before = alive_count_;
      replay_ = true;
      for (;;) {
        int best = -1;
        for (int b = 0; b < blocks; ++b) {
          const auto& d = done[static_cast<size_t>(b)];
          if (head[static_cast<size_t>(b)] >= d.size()) continue;
          if (best < 0 ||
              d[head[static_cast<size_t>(b)]].cost < done[static_cast<size_t>(best)][head[static_cast<size_t>(best)]].cost)
            best = b;
        }
        if (best < 0) break;
        const BlockCollapse& c = done[static_cast<size_t>(best)][head[static_cast<size_t>(best)]++];
        if (!collapse_if_legal(c.vt, c.vs, false, pm)) {
          replay_ = false;
          return Status(ErrorCode::SolverFailed, "simplification: a block's collapse is not legal in the whole mesh");
        }
      }
      replay_ = false;
      if (alive_count_ > before - before / 4) break;  // the blocks are mostly seams: leave the rest to the whole mesh
    }
    return Status();
  }

  // A block's greedy (presimplify_blocks): memoryless, never forced, until `target`
  // vertices remain or no legal collapse is left; each collapse goes to `emit`.
  Status run_block(int target, const std::function<bool()>& keep_going,
                   const std::function<void(double, int, int)>& emit) {
    ProgressiveMesh scratch;
    rebuild_heap();
    int count = 0;
    while (alive_count_ > target && !vheap_.empty()) {
      const int vt = vheap_.top();
      const HeapEntry e = best_[static_cast<size_t>(vt)];
      if (!collapse_if_legal(vt, e.vs, false, scratch)) {
        drop_candidate(vt, e.vs);
        continue;
      }
      emit(e.cost, vt, e.vs);
      if (++count % 1024 == 0 && keep_going && !keep_going())
        return Status(ErrorCode::Cancelled, "cancelled during simplification");
    }
    return Status();
  }

 private:
  double face_area(const std::array<int, 3>& f) const {
    // Sum of the 3D areas of each model block (d = 3n): one weight for all models.
    double a = 0;
    for (int b = 0; b + 2 < d_; b += 3) a += block_area(f, b);
    return a;
  }
  // The 3D area of face f in the model block starting at column b.
  double block_area(const std::array<int, 3>& f, int b) const {
    Eigen::Vector3d p0 = P_.row(f[0]).segment<3>(b).transpose();
    Eigen::Vector3d p1 = P_.row(f[1]).segment<3>(b).transpose();
    Eigen::Vector3d p2 = P_.row(f[2]).segment<3>(b).transpose();
    return 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }

  // Quadric coordinates: the positions, and with normal_weight > 0 each model's unit vertex
  // normals times that weight (Garland & Heckbert 1998's attribute quadrics; Hoppe 1999's
  // normal term, which MeshSimplify's -minqem uses with 0.02 x the diagonal). Around a thin
  // limb the normals turn through every direction within a small distance, so collapsing it
  // costs about weight^2 instead of radius^2: limbs survive to coarse levels, where the
  // sphere layout is decided, instead of being re-inserted late into a tiny patch.
  void build_quadric_coordinates(const RowMat3i& F) {
    const int models = d_ / 3;
    const bool normals = opt_.normal_weight > 0;
    qd_ = normals ? 2 * d_ : d_;
    X_.resize(nv_, qd_);
    X_.leftCols(d_) = P_;
    if (!normals) return;
    RowMatXd N = RowMatXd::Zero(nv_, d_);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int m = 0; m < models; ++m) {
        Eigen::Vector3d p0 = P_.row(F(f, 0)).segment<3>(3 * m).transpose();
        Eigen::Vector3d p1 = P_.row(F(f, 1)).segment<3>(3 * m).transpose();
        Eigen::Vector3d p2 = P_.row(F(f, 2)).segment<3>(3 * m).transpose();
        const Eigen::RowVector3d n = (p1 - p0).cross(p2 - p0).transpose();  // area weighted
        for (int k = 0; k < 3; ++k) N.row(F(f, k)).segment<3>(3 * m) += n;
      }
    for (int v = 0; v < nv_; ++v)
      for (int m = 0; m < models; ++m) {
        auto n = N.row(v).segment<3>(3 * m);
        const double len = n.norm();
        if (len > 0) n /= len;
      }
    X_.rightCols(d_) = opt_.normal_weight * N;
  }

  double cost(int vt, int vs) const {
    const double* ps = P_.row(vs).data();
    const double* pt = P_.row(vt).data();
    const double* xs = X_.row(vs).data();
    // Accumulated quadrics only: memoryless costs come from prepare_memoryless / memoryless_cost.
    const double q = quadric_[vt].evaluate(xs) + quadric_[vs].evaluate(xs);
    double len2 = 0;
    for (int i = 0; i < d_; ++i) len2 += (ps[i] - pt[i]) * (ps[i] - pt[i]);
    return q + opt_.edge_length_weight * len2 * area_[vt];
  }

  // May vt collapse into vs under the path constraints?
  bool path_allows(int vt, int vs) const {
    if (!frozen_.empty() && (frozen_[static_cast<size_t>(vt)] || frozen_[static_cast<size_t>(vs)])) return false;
    const auto& pn = path_nbr_[static_cast<size_t>(vt)];
    if (pn.empty()) return true;
    return pn.size() == 2 && (pn[0] == vs || pn[1] == vs);
  }

  // Pushes the collapse vt -> vs, if vt may move at all.
  void push_half_edge(int vt, int vs) {
    const bool keep = !opt_.keep_vertices.empty() && opt_.keep_vertices[static_cast<size_t>(vt)];
    if (!keep && path_allows(vt, vs)) heap_.push({cost(vt, vs), vt, vs, stamp_[vt], stamp_[vs]});
  }
  void push_edge(int a, int b) {
    push_half_edge(a, b);
    push_half_edge(b, a);
  }

  // Is an entry of the lazy heap (accumulated quadrics) still current?
  bool live(const HeapEntry& e) const {
    return vertex_alive_[e.vt] && vertex_alive_[e.vs] && e.stamp_t == stamp_[e.vt] && e.stamp_s == stamp_[e.vs];
  }

  // Memoryless quadrics: the cost of vt -> vs reads only vt's faces, vt's area, vs's (fixed)
  // position and whether vt may move towards vs, which change only for the vertices of a
  // collapse's ring. So each vertex keeps its outgoing collapses' costs (refreshed when its
  // ring changes) and sits in a vertex heap under its cheapest one not yet found illegal.
  // Popping the heap gives the same (cost, vt, vs) order as a heap of every half-edge with
  // stale entries skipped, the same collapses, at a sixth of the heap traffic (the lazy
  // heap spent most of the simplification's time on cache misses of its stale entries).
  struct Candidate {
    double cost;
    int vs;
  };
  void refresh(int vt) {
    auto& list = cand_[static_cast<size_t>(vt)];
    list.clear();
    dropped_to_[static_cast<size_t>(vt)].clear();
    const bool keep = !opt_.keep_vertices.empty() && opt_.keep_vertices[static_cast<size_t>(vt)];
    if (!keep) {
      // Neighbours in face-walk order (the candidates' order does not matter: the cheapest
      // is chosen by the total order of (cost, vs)), without the sort of neighbours().
      ring_.clear();
      ++mark_stamp_;
      mark_[static_cast<size_t>(vt)] = mark_stamp_;
      for (int f : vf_[vt])
        for (int w : faces_[f])
          if (mark_[static_cast<size_t>(w)] != mark_stamp_) {
            mark_[static_cast<size_t>(w)] = mark_stamp_;
            ring_.push_back(w);
          }
      prepare_memoryless(vt);
      for (int vs : ring_)
        if (path_allows(vt, vs)) list.push_back({memoryless_cost(vt, vs), vs});
    }
    choose_best(vt);
  }

  // Memoryless quadric (Lindstrom & Turk 1998; MeshSimplify -minqem): the area-weighted
  // squared distances of vs's point to the planes of the faces now around vt (those around
  // vs contain it). It measures the current level, not the original surface, so coarse
  // levels keep what is still visible at their scale. The per-face terms that do not depend
  // on vs (the edge Gram matrix and the area) are made once per refresh; a plane is the
  // face's 2-plane in R^qd, or with model_planes one per model block (plane_blocks_).
  struct PlaneTerm {
    const double *x0, *x1, *x2;
    double e1e1, e1e2, e2e2, det, area;
    int begin, end;  // the coordinates the plane lives in (plane_blocks_)
  };
  void prepare_memoryless(int vt) {
    planes_.clear();
    for (int f : vf_[vt]) {
      const auto& c = faces_[f];
      for (const auto& [begin, end] : plane_blocks_) {
        PlaneTerm t{X_.row(c[0]).data(), X_.row(c[1]).data(), X_.row(c[2]).data(), 0, 0, 0, 0, 0, begin, end};
        for (int i = begin; i < end; ++i) {
          const double e1 = t.x1[i] - t.x0[i], e2 = t.x2[i] - t.x0[i];
          t.e1e1 += e1 * e1, t.e1e2 += e1 * e2, t.e2e2 += e2 * e2;
        }
        t.det = t.e1e1 * t.e2e2 - t.e1e2 * t.e1e2;
        if (!(t.det > 1e-24 * t.e1e1 * t.e2e2)) continue;
        t.area = opt_.model_planes ? block_area(c, begin) : face_area(c);
        planes_.push_back(t);
      }
    }
  }
  // cost(vt, vs) with memoryless quadrics, from prepare_memoryless(vt).
  double memoryless_cost(int vt, int vs) const {
    const double* x = X_.row(vs).data();
    double sum = 0;
    for (const PlaneTerm& t : planes_) {
      double re1 = 0, re2 = 0, rr = 0;
      for (int i = t.begin; i < t.end; ++i) {
        const double e1 = t.x1[i] - t.x0[i], e2 = t.x2[i] - t.x0[i], r = x[i] - t.x0[i];
        re1 += r * e1, re2 += r * e2, rr += r * r;
      }
      const double proj = (t.e2e2 * re1 * re1 - 2 * t.e1e2 * re1 * re2 + t.e1e1 * re2 * re2) / t.det;
      sum += t.area * std::max(0.0, rr - proj);
    }
    const double* ps = P_.row(vs).data();
    const double* pt = P_.row(vt).data();
    double len2 = 0;
    for (int i = 0; i < d_; ++i) len2 += (ps[i] - pt[i]) * (ps[i] - pt[i]);
    return sum + opt_.edge_length_weight * len2 * area_[vt];
  }
  void drop_candidate(int vt, int vs) {
    auto& list = cand_[static_cast<size_t>(vt)];
    dropped_to_[static_cast<size_t>(vt)].push_back(vs);
    for (size_t i = 0; i < list.size(); ++i)
      if (list[i].vs == vs) {
        list.erase(list.begin() + static_cast<std::ptrdiff_t>(i));
        break;
      }
    choose_best(vt);
  }
  void choose_best(int vt) {
    const auto& list = cand_[static_cast<size_t>(vt)];
    HeapEntry best{kInfCost, vt, -1, 0, 0};
    for (const Candidate& c : list) {
      const HeapEntry e{c.cost, vt, c.vs, 0, 0};
      if (best.vs < 0 || HeapGreater()(best, e)) best = e;
    }
    best_[static_cast<size_t>(vt)] = best;
    auto key = [this](int v) -> const HeapEntry& { return best_[static_cast<size_t>(v)]; };
    if (best.vs < 0 || !vertex_alive_[vt]) vheap_.remove(vt, key);
    else vheap_.update(vt, key);
  }

  // Drops the lazy heap's entries made stale by later collapses: peak memory stays
  // proportional to the live edges.
  // The pop order is a total order on (cost, vt, vs), so the collapses are unchanged.
  void compact_heap() {
    std::vector<HeapEntry> current;
    while (!heap_.empty()) {
      const HeapEntry& e = heap_.top();
      if (live(e)) current.push_back(e);
      heap_.pop();
    }
    heap_ = decltype(heap_)(HeapGreater(), std::move(current));
    compact_at_ = std::max<size_t>(65536, 2 * heap_.size());
  }

  void rebuild_heap() {
    if (opt_.memoryless) {
      mark_.assign(static_cast<size_t>(nv_), 0);
      dropped_to_.assign(static_cast<size_t>(nv_), {});
      mark_stamp_ = 0;
      cand_.resize(static_cast<size_t>(nv_));
      best_.resize(static_cast<size_t>(nv_));
      vheap_.reset(nv_);
      for (int v = 0; v < nv_; ++v)
        if (vertex_alive_[v]) refresh(v);
      return;
    }
    heap_ = decltype(heap_)();
    for (size_t f = 0; f < faces_.size(); ++f) {
      if (!face_alive_[f]) continue;
      for (int k = 0; k < 3; ++k) {
        int a = faces_[f][k], b = faces_[f][(k + 1) % 3];
        if (a < b) push_edge(a, b);  // each undirected edge once (closed, oriented mesh)
      }
    }
  }

  void neighbours(int v, std::vector<int>& out) const {
    out.clear();
    for (int f : vf_[v])
      for (int k = 0; k < 3; ++k)
        if (faces_[f][k] != v) out.push_back(faces_[f][k]);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  // The link condition and, unless forced, the valence cap, fold-over and shape checks of
  // the collapse vt -> vs whose two shared faces are `shared`.
  bool legal_around(int vt, int vs, const int* shared, bool forced) {
    // Link condition (Dey et al.): the common neighbours of vt and vs must be exactly the two
    // opposite vertices, else the collapse pinches the surface.
    neighbours(vt, nt_);
    neighbours(vs, ns_);
    int common = 0;
    for (size_t i = 0, j = 0; i < nt_.size() && j < ns_.size();) {
      if (nt_[i] < ns_[j]) ++i;
      else if (nt_[i] > ns_[j]) ++j;
      else { ++common; ++i; ++j; }
    }
    if (common != 2) return false;
    if (!forced) {
      // Valence cap: very high valences make tiny spherical kernels at coarse levels.
      if (nt_.size() + ns_.size() - 4 > 24) return false;
      // Fold-over check per model: no face around vt may flip its normal when vt moves to vs.
      // Shape check: no new needle/cap worse than what was there (quality = 4 sqrt3 area /
      // sum of squared edges, 1 for equilateral). Degenerate coarse triangles give the
      // sphere embedding nearly empty kernels at the next splits.
      double q_old = 1.0, q_new = 1.0;
      for (int f : vf_[vt]) {
        if (f == shared[0] || f == shared[1]) continue;
        const auto& c = faces_[f];
        for (int b = 0; b + 2 < d_; b += 3) {
          Eigen::Vector3d p[3], q[3];
          for (int k = 0; k < 3; ++k) {
            p[k] = P_.row(c[k]).segment<3>(b).transpose();
            q[k] = c[k] == vt ? Eigen::Vector3d(P_.row(vs).segment<3>(b).transpose()) : p[k];
          }
          Eigen::Vector3d n0 = (p[1] - p[0]).cross(p[2] - p[0]);
          Eigen::Vector3d n1 = (q[1] - q[0]).cross(q[2] - q[0]);
          // Reject flips and near-degenerate results: cosine of the normal change > 0.
          if (opt_.degenerate_faces_free &&
              n0.norm() <= 1e-12 * ((p[1] - p[0]).squaredNorm() + (p[2] - p[1]).squaredNorm() +
                                     (p[0] - p[2]).squaredNorm()))
            continue;  // no orientation before: nothing to flip
          if (!(n0.dot(n1) > 0)) return false;
          q_old = std::min(q_old, quality(p, n0));
          q_new = std::min(q_new, quality(q, n1));
        }
      }
      if (q_new < kMinQuality && q_new < q_old) return false;
    }
    return true;
  }

  bool collapse_if_legal(int vt, int vs, bool forced, ProgressiveMesh& pm) {
    if (!path_allows(vt, vs)) return false;
    // The two faces sharing edge (vt, vs) and their third vertices.
    int shared[2] = {-1, -1}, third[2] = {-1, -1}, ns = 0;
    for (int f : vf_[vt]) {
      const auto& c = faces_[f];
      if (c[0] != vs && c[1] != vs && c[2] != vs) continue;
      if (ns == 2) return false;  // non-manifold edge
      shared[ns] = f;
      for (int k = 0; k < 3; ++k)
        if (c[k] != vt && c[k] != vs) third[ns] = c[k];
      ++ns;
    }
    if (ns != 2) return false;
    // A replayed block collapse was checked in its block, where it saw the same neighbourhood.
    if (!replay_ && !legal_around(vt, vs, shared, forced)) return false;
    // Commit.
    HalfEdgeCollapse rec;
    rec.vt = vt;
    rec.vs = vs;
    rec.vl = third[0];
    rec.vr = third[1];
    rec.removed = {shared[0], shared[1]};
    rec.moved_begin = static_cast<int>(pm.moved_faces.size());
    for (int s = 0; s < 2; ++s) {
      int f = shared[s];
      pm.removed_corners.push_back(faces_[f]);
      face_alive_[f] = 0;
      for (int k = 0; k < 3; ++k) {
        int v = faces_[f][k];
        if (v == vt) continue;
        auto& list = vf_[v];
        list.erase(std::find(list.begin(), list.end(), f));
      }
    }
    for (int f : vf_[vt]) {
      if (f == shared[0] || f == shared[1]) continue;
      for (int k = 0; k < 3; ++k)
        if (faces_[f][k] == vt) faces_[f][k] = vs;
      vf_[vs].push_back(f);
      pm.moved_faces.push_back(f);
    }
    rec.moved_end = static_cast<int>(pm.moved_faces.size());
    vf_[vt].clear();
    vertex_alive_[vt] = 0;
    --alive_count_;
    // Carry the path: vt's other path edge (vt, w) becomes (vs, w).
    auto& pt = path_nbr_[static_cast<size_t>(vt)];
    if (!pt.empty()) {
      int w = pt[0] == vs ? pt[1] : pt[0];
      for (int& x : path_nbr_[static_cast<size_t>(vs)])
        if (x == vt) x = w;
      for (int& x : path_nbr_[static_cast<size_t>(w)])
        if (x == vt) x = vs;
      pt.clear();
    }
    if (!opt_.memoryless) quadric_[vs].add(quadric_[vt]);
    area_[vs] += area_[vt];
    ++stamp_[vs];
    if (forced) ++pm.forced_collapses;
    pm.collapses.push_back(rec);
    if (replay_) return true;  // presimplify_blocks: the heap is built afterwards
    neighbours(vs, ns_);
    if (opt_.memoryless) {
      // The faces of vs's neighbours changed too: so did the costs of all their collapses.
      auto key = [this](int v) -> const HeapEntry& { return best_[static_cast<size_t>(v)]; };
      vheap_.remove(vt, key);
      cand_[static_cast<size_t>(vt)].clear();
      // The half-edge heap this replaces re-pushed every half-edge touching vs or its new
      // neighbours, so each of them is untried again (a collapse found illegal may have become
      // legal: the link condition and the valence cap read both ends). vs and vt's former
      // neighbours have new faces: all their collapses are recomputed. A neighbour of vs that
      // was not one of vt's kept its faces, so its collapses cost the same: it is refreshed
      // only if one of them was dropped. A vertex beyond gets back the collapse towards the
      // ring it had dropped, if any.
      refresh(vs);
      for (int w : ns_)
        if (!dropped_to_[static_cast<size_t>(w)].empty() || std::binary_search(nt_.begin(), nt_.end(), w)) refresh(w);
      ++mark_stamp_;
      mark_[static_cast<size_t>(vs)] = mark_stamp_;
      for (int w : ns_) mark_[static_cast<size_t>(w)] = mark_stamp_;
      const std::uint32_t ring_stamp = mark_stamp_;
      auto restore_towards = [&](int x) {
        for (int f : vf_[x])
          for (int w : faces_[f]) {
            auto& dropped = dropped_to_[static_cast<size_t>(w)];
            if (mark_[static_cast<size_t>(w)] == ring_stamp || dropped.empty()) continue;
            const auto it = std::find(dropped.begin(), dropped.end(), x);
            if (it == dropped.end()) continue;
            dropped.erase(it);
            prepare_memoryless(w);
            cand_[static_cast<size_t>(w)].push_back({memoryless_cost(w, x), x});
            choose_best(w);
          }
      };
      restore_towards(vs);
      for (int x : ns_) restore_towards(x);
    } else {
      for (int w : ns_) push_edge(vs, w);
    }
    if (!opt_.memoryless && heap_.size() > compact_at_) compact_heap();
    return true;
  }

  const RowMatXd& P_;
  const ProgressiveMeshOptions& opt_;
  int d_, nv_;
  std::vector<char> frozen_;  // a block's vertices next to another block (presimplify_blocks)
  bool replay_ = false;       // replaying the blocks' collapses: no heap to keep
  int qd_ = 0;   // quadric dimension: d_, or 2 d_ with normals
  // The coordinate ranges a plane lives in: all qd_ coordinates (the 2-plane in R^qd), or
  // each model's block of 3 (model_planes).
  std::vector<std::pair<int, int>> plane_blocks_;
  RowMatXd X_;   // quadric coordinates per vertex (positions, weighted normals)
  int alive_count_ = 0;
  std::vector<std::array<int, 3>> faces_;
  std::vector<char> face_alive_, vertex_alive_;
  std::vector<std::vector<int>> vf_;
  std::vector<std::uint32_t> stamp_;
  std::vector<detail::QuadricND> quadric_;
  std::vector<double> area_;
  std::vector<int> nt_, ns_, ring_;
  std::vector<PlaneTerm> planes_;  // prepare_memoryless
  std::vector<std::uint32_t> mark_;  // refresh: stamp of the vertices already listed
  std::vector<std::vector<int>> dropped_to_;  // memoryless: targets found illegal since the last refresh
  std::uint32_t mark_stamp_ = 0;
  std::vector<std::vector<int>> path_nbr_;  // per vertex: its neighbours along path edges
  std::priority_queue<HeapEntry, std::vector<HeapEntry>, HeapGreater> heap_;  // accumulated quadrics
  std::vector<std::vector<Candidate>> cand_;  // memoryless: per vertex, its collapses' costs
  std::vector<HeapEntry> best_;               // memoryless: per vertex, its cheapest candidate
  VertexHeap vheap_;
  static constexpr double kInfCost = std::numeric_limits<double>::infinity();
  size_t compact_at_ = 65536;  // heap size that triggers compact_heap
};

}  // namespace

Result<ProgressiveMesh> build_progressive_mesh(const RowMatXd& P, const RowMat3i& F,
                                               const ProgressiveMeshOptions& options,
                                               const ProgressFn& progress) {
  if (P.cols() < 3 || P.cols() % 3 != 0)
    return Status(ErrorCode::InvalidArgument, "vertex coordinates must have 3n columns");
  if (F.rows() < 4 || P.rows() < 4)
    return Status(ErrorCode::InvalidInput, "mesh has fewer than 4 vertices or faces");
  if (!options.face_weights.empty() && options.face_weights.size() != static_cast<size_t>(F.rows()))
    return Status(ErrorCode::InvalidArgument, "face_weights must have one entry per face");
  if (!options.keep_vertices.empty() && options.keep_vertices.size() != static_cast<size_t>(P.rows()))
    return Status(ErrorCode::InvalidArgument, "keep_vertices must have one entry per vertex");
  if (options.model_planes && options.normal_weight > 0)
    return Status(ErrorCode::InvalidArgument, "model_planes measures positions only (normal_weight must be 0)");
  for (const auto& e : options.constraint_edges)
    if (e[0] < 0 || e[1] < 0 || e[0] >= P.rows() || e[1] >= P.rows() || e[0] == e[1])
      return Status(ErrorCode::InvalidArgument, "constraint edge index out of range");
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= P.rows())
        return Status(ErrorCode::InvalidInput, "face index out of range");
  ProgressiveMesh pm;
  pm.num_vertices = static_cast<int>(P.rows());
  pm.F = F;
  pm.collapses.reserve(static_cast<size_t>(P.rows()));
  Simplifier s(P, F, options);
  if (options.block_vertices > 0 && options.memoryless && options.constraint_edges.empty() &&
      options.keep_vertices.empty() && 2 * P.rows() >= 3 * static_cast<Eigen::Index>(options.block_vertices))
    SPHEREKIT_RETURN_IF_ERROR(s.presimplify_blocks(pm, progress));
  SPHEREKIT_RETURN_IF_ERROR(s.run(pm, progress));
  return pm;
}

CollapseReplay::CollapseReplay(const ProgressiveMesh& pm)
    : pm_(&pm), parent_(static_cast<std::size_t>(pm.num_vertices)), alive_(static_cast<std::size_t>(pm.F.rows()), 1) {
  for (int v = 0; v < pm.num_vertices; ++v) parent_[static_cast<std::size_t>(v)] = v;
}

void CollapseReplay::advance_to(std::size_t count) {
  for (; done_ < count && done_ < pm_->collapses.size(); ++done_) {
    const HalfEdgeCollapse& c = pm_->collapses[done_];
    parent_[static_cast<std::size_t>(c.vt)] = c.vs;
    for (int f : c.removed) alive_[static_cast<std::size_t>(f)] = 0;
  }
}

int CollapseReplay::find(int v) const {
  while (parent_[static_cast<std::size_t>(v)] != v) v = parent_[static_cast<std::size_t>(v)];
  return v;
}

}  // namespace spherekit
