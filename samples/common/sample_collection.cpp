// The built-in sample collection: animal-like genus-0 surfaces with exact ground truth.
//
// Design (see samples_animal.h for the shape model, samples_tessellation.h for meshing):
// - The common template domain is the unit sphere. Member k is a smooth embedding
//   X_k: S^2 -> R^3 (body ellipsoid plus limb bumps at FIXED template directions, with
//   member-specific proportions and pose), so template point u on member j and on member
//   k are the same anatomical point: that is the ground-truth correspondence.
// - Each member is meshed with its own connectivity: a sphere tessellation of a different
//   kind per member (icosphere; cube sphere; Fibonacci points triangulated as their
//   convex hull; a coarser icosphere with jittered vertices), randomly rotated; then the
//   landmark template points are inserted as vertices, edges are bisected where the
//   surface needs samples (limbs get far more than their template area would), surface
//   Delaunay flips and tangential smoothing clean up, and member 4k+3 gets random
//   quality-preserving flips too.
//   Mesh vertex = X_k(template point); the template points are stored per vertex.
// - Members 4k+1 and 4k+3 get one hole (mouth, belly): the faces whose template
//   centroid lies in a small cap are removed.
// - Landmark vertex = the vertex whose template point is nearest the landmark's template
//   point; the landmark points are inserted as vertices, so it is exactly that point.
// Cost: about 60 ms per member at the default 3000 vertices (one core).
#include "sample_collection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "samples_animal.h"
#include "samples_tessellation.h"
#include "spherekit/check_mesh.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_io.h"

namespace spherekit::samples {
namespace {

using detail::Rng;
using detail::SphereTriangulation;
using detail::Tri;
using detail::Vec3;

// Eight hand-named members (sample_a..sample_h) for the demos; larger generated collections
// (the scale tests and benchmarks of issue 23) continue with letter names, up to 1000.
constexpr int kMaxMembers = 1000;
constexpr int kMinVertices = 200;      // below this the limbs cannot be resolved
constexpr int kMaxVertices = 200000;   // the hull and locate() are not built for more
constexpr int kCorrSamples = 500;      // template points offered for the .corr.txt files

// Kinds of template tessellation, by member index modulo 4.
enum class Tessellation { Icosphere, CubeSphere, Fibonacci, JitteredIcosphere };

std::uint64_t member_seed(std::uint64_t seed, int member) {
  Rng mix(seed ^ (0x5851F42D4C957F2Dull * static_cast<std::uint64_t>(member + 1)));
  return mix.next();
}

// Largest icosphere level with at most `n` vertices (10 * 4^level + 2), at least 0.
int icosphere_level(int n) {
  int level = 0;
  while (10 * (1 << (2 * (level + 1))) + 2 <= n) ++level;
  return level;
}

// The template tessellation with about `n` vertices, of the member's kind.
Result<SphereTriangulation> base_tessellation(Tessellation kind, int n, Rng& rng) {
  switch (kind) {
    case Tessellation::Icosphere:
      return detail::icosphere(std::max(1, icosphere_level(n)));
    case Tessellation::CubeSphere:
      return detail::cube_sphere(std::max(2, static_cast<int>(std::lround(std::sqrt((n - 2) / 6.0)))));
    case Tessellation::Fibonacci: {
      SphereTriangulation s;
      // Rounding can, in principle, break an incremental hull; another jitter fixes it.
      for (int attempt = 0; attempt < 4; ++attempt)
        if (detail::fibonacci_sphere(std::max(n, 12), rng, &s)) return s;
      return Status(ErrorCode::Internal, "sample collection: convex hull of the Fibonacci points failed");
    }
    case Tessellation::JitteredIcosphere: {
      // One level coarser than the plain icosphere member, so the two differ even where
      // refinement leaves the base alone.
      SphereTriangulation s = detail::icosphere(std::max(0, icosphere_level(n) - 1));
      detail::jitter(s, 0.3, rng);
      return s;
    }
  }
  return Status(ErrorCode::Internal, "sample collection: unknown tessellation");
}

// Removes the faces flagged in `remove`, then drops vertices no longer used (keeping
// order). Refuses (returns false, changing nothing) if that would drop a `fixed` vertex.
bool cut_faces(std::vector<Vec3>& U, std::vector<Vec3>& X, std::vector<Tri>& F, const std::vector<char>& remove,
               const std::vector<char>& fixed) {
  std::vector<Tri> kept;
  for (size_t f = 0; f < F.size(); ++f)
    if (!remove[f]) kept.push_back(F[f]);
  std::vector<int> new_id(U.size(), -1);
  for (const Tri& t : kept)
    for (int v : t) new_id[v] = 0;
  for (size_t v = 0; v < fixed.size() && v < U.size(); ++v)
    if (fixed[v] && new_id[v] < 0) return false;
  int next = 0;
  for (size_t v = 0; v < U.size(); ++v) {
    if (new_id[v] < 0) continue;
    new_id[v] = next;
    U[next] = U[v];
    X[next] = X[v];
    ++next;
  }
  U.resize(next);
  X.resize(next);
  for (Tri& t : kept)
    for (int& v : t) v = new_id[v];
  F = std::move(kept);
  return true;
}

TriMesh to_mesh(const std::vector<Vec3>& X, const std::vector<Tri>& F) {
  TriMesh m;
  m.V.resize(static_cast<Eigen::Index>(X.size()), 3);
  for (size_t v = 0; v < X.size(); ++v) m.V.row(static_cast<Eigen::Index>(v)) = X[v].transpose();
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (size_t f = 0; f < F.size(); ++f)
    for (int k = 0; k < 3; ++k) m.F(static_cast<Eigen::Index>(f), k) = F[f][k];
  return m;
}

// Cuts one hole at `cap`: the faces whose template centroid lies inside. If that set is
// empty (a cap smaller than the local faces), touches itself at a vertex (two loops or a
// pinched one) or would remove a landmark vertex (`fixed`), the hole is instead the one
// face containing the cap's centre: removing a single triangle from a closed genus-0
// mesh always leaves one simple loop.
Status cut_member_hole(std::vector<Vec3>& U, std::vector<Vec3>& X, std::vector<Tri>& F, const detail::Cap& cap,
                       const std::vector<char>& fixed) {
  const double cos_radius = std::cos(cap.radius);
  std::vector<char> in_cap(F.size(), 0);
  for (size_t f = 0; f < F.size(); ++f) {
    const Tri& t = F[f];
    in_cap[f] = (U[t[0]] + U[t[1]] + U[t[2]]).normalized().dot(cap.centre) >= cos_radius;
  }
  if (std::count(in_cap.begin(), in_cap.end(), 1) > 0) {
    std::vector<Vec3> u = U, x = X;
    std::vector<Tri> f = F;
    if (cut_faces(u, x, f, in_cap, fixed)) {
      const MeshCheck check = check_mesh(to_mesh(x, f));
      if (check.boundary_loops == 1 && check.genus == 0 && check.nonmanifold_vertices == 0) {
        U = std::move(u);
        X = std::move(x);
        F = std::move(f);
        return Status::ok_status();
      }
    }
  }
  std::vector<char> one(F.size(), 0);
  for (size_t f = 0; f < F.size(); ++f) {
    const Tri& t = F[f];
    if (detail::sphere_orient(U[t[0]], U[t[1]], cap.centre) >= 0 &&
        detail::sphere_orient(U[t[1]], U[t[2]], cap.centre) >= 0 &&
        detail::sphere_orient(U[t[2]], U[t[0]], cap.centre) >= 0 && cap.centre.dot(U[t[0]]) > 0) {
      one[f] = 1;
      break;
    }
  }
  if (std::count(one.begin(), one.end(), 1) == 1 && cut_faces(U, X, F, one, fixed)) return Status::ok_status();
  return Status(ErrorCode::Internal, "no face contains the hole centre");
}

// The vertex whose template point is nearest `u` (largest dot product).
int nearest_vertex(const RowMat3d& template_points, const Vec3& u) {
  Eigen::Index best = 0;
  (template_points * u).maxCoeff(&best);
  return static_cast<int>(best);
}

// sample_a .. sample_z, then sample_aa .. sample_zz, then three letters: k = 0..1000.
std::string member_name(int k) {
  int width = 1, count = 26;
  while (k >= count && width < 3) {
    k -= count;
    count *= 26;
    ++width;
  }
  std::string letters(static_cast<size_t>(width), 'a');
  for (int i = width - 1; i >= 0; --i) {
    letters[static_cast<size_t>(i)] = static_cast<char>('a' + k % 26);
    k /= 26;
  }
  return "sample_" + letters;
}

Result<SampleMesh> make_member(int k, const SampleCollectionOptions& options) {
  Rng rng(member_seed(options.seed, k));
  const detail::AnimalShape shape = detail::random_animal(rng);
  const auto kind = static_cast<Tessellation>(k % 4);

  // The base gets 40% of the vertex budget; refinement spends the rest where the surface
  // needs it (limbs, ears), which a uniform tessellation cannot do.
  SPHEREKIT_ASSIGN_OR_RETURN(SphereTriangulation base, base_tessellation(kind, (2 * options.target_vertices) / 5, rng));
  const Eigen::Matrix3d rotation = detail::random_rotation(rng);
  for (Vec3& u : base.U) u = rotation * u;

  detail::SurfaceMeshEditor editor(std::move(base), [&shape](const Vec3& u) { return shape(u); });
  const auto landmarks = detail::template_landmarks();
  std::vector<char> fixed;  // landmark vertices keep their exact template points
  for (const auto& lm : landmarks) {
    const int v = editor.insert_point(lm.u, fixed);
    if (v < 0) continue;
    if (fixed.size() <= static_cast<size_t>(v)) fixed.resize(static_cast<size_t>(v) + 1, 0);
    fixed[v] = 1;
  }
  editor.refine_to(options.target_vertices);
  // Flips fix the connectivity, smoothing the vertex distribution that bisection leaves
  // uneven around the limbs; alternating them brings the smallest angle from under a
  // degree to about 15 (rarely 5-10, next to a landmark, whose vertex cannot move). Eight
  // rounds: improvement has mostly stopped by then, at about 20 ms per member.
  editor.improve_by_flips(8);
  for (int round = 0; round < 8; ++round) {
    editor.smooth(fixed);
    editor.improve_by_flips(8);
  }
  if (kind == Tessellation::JitteredIcosphere) editor.random_flips(0.2, rng);

  std::vector<Vec3> U = editor.U(), X = editor.X();
  std::vector<Tri> F = editor.F();
  SampleMesh member;
  member.name = member_name(k);
  if (k % 2 == 1) {
    SPHEREKIT_RETURN_IF_ERROR(
        cut_member_hole(U, X, F, k % 4 == 1 ? detail::mouth_cap() : detail::belly_cap(), fixed)
            .with_context("sample collection: " + member.name));
    member.boundary_loops = 1;
  }
  member.mesh = to_mesh(X, F);
  member.template_points.resize(static_cast<Eigen::Index>(U.size()), 3);
  for (size_t v = 0; v < U.size(); ++v) member.template_points.row(static_cast<Eigen::Index>(v)) = U[v].transpose();
  for (const auto& lm : landmarks) member.landmarks.push_back({lm.name, nearest_vertex(member.template_points, lm.u)});

  // The generator's promise, checked rather than assumed: one manifold genus-0 piece with
  // the intended number of holes and no degenerate or zero-area faces.
  const MeshCheck check = check_mesh(member.mesh);
  SPHEREKIT_RETURN_IF_ERROR(require_genus0(check).with_context("sample collection: " + member.name));
  if (check.boundary_loops != member.boundary_loops || check.zero_area_faces > 0)
    return Status(ErrorCode::Internal, "sample collection: " + member.name + " has " +
                                           std::to_string(check.boundary_loops) + " boundary loops and " +
                                           std::to_string(check.zero_area_faces) + " zero-area faces");
  return member;
}

// Barycentric weights of `q` in the spherical triangle (a, b, c) under the gnomonic
// (central) projection: for the point p = t q on the triangle's plane,
// p = w0 a + w1 b + w2 c with w_i proportional to det[q, b, c], det[a, q, c], det[a, b, q].
// Their sum is q . ((b - a) x (c - a)): positive exactly when q points at the triangle's
// front, so the antipodal region (where the ratios are the same) is excluded. Returns
// false there.
bool gnomonic_barycentrics(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q, Eigen::Vector3d* w) {
  *w = Eigen::Vector3d(detail::sphere_orient(q, b, c), detail::sphere_orient(a, q, c), detail::sphere_orient(a, b, q));
  const double sum = w->sum();
  if (!(sum > 0)) return false;
  *w /= sum;
  return true;
}

// Fibonacci points: spread evenly over the sphere with no preferred direction.
std::vector<Vec3> corr_sample_points(int n) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(std::max(0.0, 1 - z * z));
    points.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return points;
}

// The face of m's template triangulation containing template point q (-1 if q is in a
// hole) and q's gnomonic barycentrics there. Brute force: ~30 flops per face, and
// ground_truth_point has no state to keep a search structure in.
int locate(const SampleMesh& m, const Vec3& q, Eigen::Vector3d* weights) {
  // Tolerance for points on an edge shared by two triangles: either may claim them.
  constexpr double kOnEdge = -1e-12;
  int best = -1;
  for (Eigen::Index f = 0; f < m.mesh.F.rows(); ++f) {
    const Vec3 a = m.template_points.row(m.mesh.F(f, 0)), b = m.template_points.row(m.mesh.F(f, 1)),
               c = m.template_points.row(m.mesh.F(f, 2));
    Eigen::Vector3d w;
    if (!gnomonic_barycentrics(a, b, c, q, &w) || w.minCoeff() < kOnEdge) continue;
    if (best >= 0 && w.minCoeff() <= weights->minCoeff()) continue;
    best = static_cast<int>(f);
    *weights = w;
  }
  return best;
}

std::string format_xyz(double x, double y, double z) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g\n", x, y, z);
  return buf;
}

}  // namespace

Result<std::vector<SampleMesh>> make_sample_collection(const SampleCollectionOptions& options) {
  if (options.members < 1 || options.members > kMaxMembers)
    return Status(ErrorCode::InvalidArgument, "sample collection: members must be in [1, " + std::to_string(kMaxMembers) + "], got " +
                                                  std::to_string(options.members));
  if (options.target_vertices < kMinVertices || options.target_vertices > kMaxVertices)
    return Status(ErrorCode::InvalidArgument, "sample collection: target_vertices must be in [" +
                                                  std::to_string(kMinVertices) + ", " + std::to_string(kMaxVertices) +
                                                  "], got " + std::to_string(options.target_vertices));
  std::vector<SampleMesh> collection;
  for (int k = 0; k < options.members; ++k) {
    SPHEREKIT_ASSIGN_OR_RETURN(SampleMesh member, make_member(k, options));
    collection.push_back(std::move(member));
  }
  return collection;
}

bool ground_truth_point(const SampleMesh& from, int v, const SampleMesh& to, Eigen::Vector3d* point) {
  if (point == nullptr || v < 0 || v >= from.template_points.rows()) return false;
  const Vec3 q = from.template_points.row(v).transpose();
  Eigen::Vector3d w;
  const int face = locate(to, q, &w);
  if (face < 0) return false;
  // A template point that is a vertex of `to` maps to exactly that vertex.
  for (int k = 0; k < 3; ++k) {
    const int corner = to.mesh.F(face, k);
    if (to.template_points.row(corner) == q.transpose()) {
      *point = to.mesh.V.row(corner).transpose();
      return true;
    }
  }
  *point = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) *point += w[k] * to.mesh.V.row(to.mesh.F(face, k)).transpose();
  return true;
}

Status write_sample_collection(const std::string& dir, const std::vector<SampleMesh>& collection) {
  namespace fs = std::filesystem;
  if (collection.empty()) return Status(ErrorCode::InvalidArgument, "sample collection: nothing to write");
  for (const SampleMesh& m : collection)
    if (m.template_points.rows() != m.mesh.V.rows())
      return Status(ErrorCode::InvalidArgument, m.name + ": template_points and vertices differ in count");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Status(ErrorCode::IoError, dir + ": cannot create directory: " + ec.message());

  // Correspondence samples: Fibonacci points (even, member-independent) covered by every
  // member (those in a hole are skipped), so line k of every .corr.txt is the vertex
  // nearest the same template point.
  std::vector<Vec3> samples;
  for (const Vec3& q : corr_sample_points(kCorrSamples)) {
    bool everywhere = true;
    Eigen::Vector3d unused;
    for (const SampleMesh& m : collection) everywhere = everywhere && locate(m, q, &unused) >= 0;
    if (everywhere) samples.push_back(q);
  }

  for (const SampleMesh& m : collection) {
    const std::string stem = (fs::path(dir) / m.name).string();
    SPHEREKIT_RETURN_IF_ERROR(formats::write_mesh(stem + ".obj", m.mesh));

    std::string landmarks;
    for (const Landmark& lm : m.landmarks) landmarks += lm.name + " " + std::to_string(lm.vertex) + "\n";
    SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(stem + ".lm.txt", landmarks));

    std::string points;
    for (Eigen::Index v = 0; v < m.template_points.rows(); ++v)
      points += format_xyz(m.template_points(v, 0), m.template_points(v, 1), m.template_points(v, 2));
    SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(stem + ".template.txt", points));

    std::string corr;
    for (const Vec3& q : samples) corr += std::to_string(nearest_vertex(m.template_points, q)) + "\n";
    SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(stem + ".corr.txt", corr));
  }
  return Status::ok_status();
}

}  // namespace spherekit::samples
