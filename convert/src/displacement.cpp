// Displacement sampling over a fitted Catmull–Clark cage and the displaced-surface mesh
// (layout and the ray rule in displacement.h).
#include "spherekit/convert/displacement.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "spherekit/correspondence.h"
#include "spherekit/geometry_image.h"

namespace spherekit::convert {
namespace {

int thread_count(int requested) { return requested > 0 ? requested : omp_get_max_threads(); }

// Lattice vertex of sample (r, c) of quad f, on the cube lattice with n(T-1) cells per edge.
int sample_lattice_id(const CageDomain& d, int tile, int f, int r, int c) {
  const std::array<int, 3>& cell = d.face_cell[static_cast<std::size_t>(f)];
  const int m = d.n * (tile - 1);
  return cube_lattice_id(m, cell[0], cell[1] * (tile - 1) + c, cell[2] * (tile - 1) + r);
}

}  // namespace

Result<DisplacementMap> sample_displacement(const TriMesh& mesh, const RowMat3d& S, const SubdCage& cage,
                                            const CageLimit& limit, const DisplacementOptions& options,
                                            const ProgressFn& progress) {
  if (options.tile < 2 || options.tile > 1025 || options.max_iterations < 0 || options.max_iterations > 100)
    return Status(ErrorCode::InvalidArgument, "displacement: tile must be 2..1025, iterations 0..100");
  if (mesh.F.rows() == 0 || S.rows() != mesh.V.rows())
    return Status(ErrorCode::InvalidInput, "displacement: empty mesh or sphere map of another size");
  const int nf = static_cast<int>(cage.domain.quads.size());
  if (limit.faces() != nf || cage.points.rows() != cage.domain.sphere.rows())
    return Status(ErrorCode::InvalidArgument, "displacement: cage and limit surface differ");
  const int T = options.tile;
  DisplacementMap map;
  map.cage_n = cage.domain.n;
  map.faces = nf;
  map.tile = T;
  map.kind = options.kind;
  const int ch = map.channels();
  const std::size_t samples = static_cast<std::size_t>(nf) * T * T;
  map.values.assign(samples * ch, 0.0f);
  map.in_hole.assign(samples, 0);

  const SphereLocator locator(mesh.F, S);
  std::unique_ptr<ClosestPointLocator> closest;
  if (options.kind == DisplacementKind::Scalar && options.max_iterations > 0)
    closest = std::make_unique<ClosestPointLocator>(mesh);
  std::vector<double> residual(samples, 0.0);
  const int chunk = std::max(1, nf / 20);
  bool cancelled = false;
  for (int f0 = 0; f0 < nf && !cancelled; f0 += chunk) {
    const int f1 = std::min(nf, f0 + chunk);
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count(options.threads))
    for (int f = f0; f < f1; ++f) {
      for (int r = 0; r < T; ++r)
        for (int c = 0; c < T; ++c) {
          const double u = double(c) / (T - 1), v = double(r) / (T - 1);
          const std::size_t s = (static_cast<std::size_t>(f) * T + r) * T + c;
          Eigen::Vector3d P, N;
          limit.evaluate(cage.points, f, u, v, P, N);
          const SphereLocation loc = locator.locate(cage_domain_point(cage.domain, f, u, v));
          Eigen::Vector3d x = Eigen::Vector3d::Zero();
          if (loc.face >= 0)
            for (int k = 0; k < 3; ++k) x += loc.bary[k] * mesh.V.row(mesh.F(loc.face, k)).transpose();
          map.in_hole[s] = loc.inside ? 0 : 1;
          if (options.kind == DisplacementKind::Vector) {
            const Eigen::Vector3d D = x - P;
            for (int k = 0; k < 3; ++k) map.values[s * 3 + k] = static_cast<float>(D[k]);
            continue;
          }
          double d = (x - P).dot(N);
          if (closest && !map.in_hole[s]) {
            // Fixed point of x <- closest(P + ((x - P)·N) N): where the normal line meets the
            // surface. Keep the iterate whose line point lies nearest to the surface.
            double best = std::numeric_limits<double>::infinity();
            for (int it = 0; it <= options.max_iterations; ++it) {
              const double t = (x - P).dot(N);
              const Eigen::Vector3d q = P + t * N;
              const Eigen::Vector3d y = surface_position(mesh, closest->closest(q));
              const double res = (y - q).norm();
              if (res < best) {
                best = res;
                d = t;
              }
              if ((y - x).norm() <= 1e-12 * (1 + std::abs(t))) break;
              x = y;
            }
            residual[s] = best;
          }
          map.values[s] = static_cast<float>(d);
        }
    }
    if (!report_progress(progress, "displacement", T, double(f1) / nf)) cancelled = true;
  }
  if (cancelled) return Status(ErrorCode::Cancelled, "cancelled");
  double sum = 0;
  long long counted = 0;
  for (std::size_t s = 0; s < samples; ++s) {
    double a = 0;
    for (int k = 0; k < ch; ++k) a += double(map.values[s * ch + k]) * map.values[s * ch + k];
    map.max_abs = std::max(map.max_abs, std::sqrt(a));
    if (map.in_hole[s]) {
      ++map.samples_in_holes;
    } else {
      sum += residual[s];
      ++counted;
    }
  }
  if (options.kind == DisplacementKind::Scalar && counted > 0) map.mean_ray_residual = sum / double(counted);
  return map;
}

TriMesh displaced_surface_mesh(const SubdCage& cage, const CageLimit& limit, const DisplacementMap* map, int tile,
                               std::vector<std::uint8_t>* hole_faces, int threads) {
  const CageDomain& d = cage.domain;
  const int T = map ? map->tile : tile;
  const int nf = static_cast<int>(d.quads.size());
  const int m = d.n * (T - 1);
  TriMesh out;
  out.V.resize(cube_lattice_points(m), 3);
  std::vector<std::uint8_t> vertex_hole(static_cast<std::size_t>(out.V.rows()), 0);
  // Each lattice vertex on a quad border is a sample of every quad that has it; all compute
  // the same point up to rounding. Samples are evaluated in parallel into their own slots and
  // scattered in quad order (the last quad wins), so the mesh does not depend on threads.
  const std::size_t samples = static_cast<std::size_t>(nf) * T * T;
  std::vector<Eigen::Vector3d> pos(samples);
#pragma omp parallel for schedule(dynamic, 4) num_threads(thread_count(threads))
  for (int f = 0; f < nf; ++f)
    for (int r = 0; r < T; ++r)
      for (int c = 0; c < T; ++c) {
        const std::size_t s = (static_cast<std::size_t>(f) * T + r) * T + c;
        Eigen::Vector3d P, N;
        limit.evaluate(cage.points, f, double(c) / (T - 1), double(r) / (T - 1), P, N);
        if (map) {
          if (map->kind == DisplacementKind::Scalar)
            P += double(map->values[s]) * N;
          else
            P += Eigen::Vector3d(map->values[s * 3], map->values[s * 3 + 1], map->values[s * 3 + 2]);
        }
        pos[s] = P;
      }
  for (int f = 0; f < nf; ++f)
    for (int r = 0; r < T; ++r)
      for (int c = 0; c < T; ++c) {
        const std::size_t s = (static_cast<std::size_t>(f) * T + r) * T + c;
        const int id = sample_lattice_id(d, T, f, r, c);
        out.V.row(id) = pos[s].transpose();
        if (map && map->in_hole[s]) vertex_hole[static_cast<std::size_t>(id)] = 1;
      }
  out.F.resize(static_cast<Eigen::Index>(nf) * (T - 1) * (T - 1) * 2, 3);
  if (hole_faces) hole_faces->assign(static_cast<std::size_t>(out.F.rows()), 0);
  Eigen::Index t = 0;
  for (int f = 0; f < nf; ++f)
    for (int r = 0; r + 1 < T; ++r)
      for (int c = 0; c + 1 < T; ++c) {
        const int a = sample_lattice_id(d, T, f, r, c), b = sample_lattice_id(d, T, f, r, c + 1),
                  e = sample_lattice_id(d, T, f, r + 1, c + 1), g = sample_lattice_id(d, T, f, r + 1, c);
        // Split along the shorter diagonal of the displaced quad (fewer slivers on curved parts).
        const bool ae = (out.V.row(a) - out.V.row(e)).squaredNorm() <= (out.V.row(b) - out.V.row(g)).squaredNorm();
        const int tri[2][3] = {{a, b, ae ? e : g}, {ae ? a : b, e, g}};
        for (const auto& tr : tri) {
          out.F.row(t) << tr[0], tr[1], tr[2];
          if (hole_faces && (vertex_hole[static_cast<std::size_t>(tr[0])] || vertex_hole[static_cast<std::size_t>(tr[1])] ||
                             vertex_hole[static_cast<std::size_t>(tr[2])]))
            (*hole_faces)[static_cast<std::size_t>(t)] = 1;
          ++t;
        }
      }
  return out;
}

long long stored_floats(const SubdCage& cage, const DisplacementMap& map) {
  return 3LL * cage.points.rows() + static_cast<long long>(map.values.size());
}

}  // namespace spherekit::convert
