// Octahedral geometry images (Praun & Hoppe 2003; Gu, Gortler & Hoppe 2002): the octahedral
// map (Cigolle et al. 2014 / Draco's normal_compression_utils.h, with z as the "up" axis),
// resampling through a sphere map with gnomonic barycentrics, the remesh of an image, and the
// remesh PSNR (Metro-style symmetric sampling, Cignoni et al. 1998).
#include "spherekit/geometry_image.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "detail/check_topology.h"
#include "detail/sphere_locator.h"
#include "spherekit/remove_faces.h"

namespace spherekit {
namespace {

double sign_of(double x) { return x >= 0 ? 1.0 : -1.0; }

int thread_count(int requested) { return requested > 0 ? requested : omp_get_max_threads(); }

}  // namespace

// ---------------------------------------------------------------------------------------
// Octahedral map

Eigen::Vector3d octahedral_to_sphere(double u, double v) {
  const double z = 1.0 - std::abs(u) - std::abs(v);
  double x = u, y = v;
  if (z < 0) {
    x = (1.0 - std::abs(v)) * sign_of(u);
    y = (1.0 - std::abs(u)) * sign_of(v);
  }
  // "+ 0.0" turns -0.0 into +0.0 so that folded texel pairs give bit-identical points.
  return Eigen::Vector3d(x + 0.0, y + 0.0, z + 0.0).normalized();
}

Eigen::Vector2d sphere_to_octahedral(const Eigen::Vector3d& p) {
  const double l1 = std::abs(p.x()) + std::abs(p.y()) + std::abs(p.z());
  if (!(l1 > 0)) return {0, 0};
  const Eigen::Vector3d q = p / l1;
  if (q.z() >= 0) return {q.x(), q.y()};
  return {(1.0 - std::abs(q.y())) * sign_of(q.x()), (1.0 - std::abs(q.x())) * sign_of(q.y())};
}

Eigen::Vector2d texel_to_octahedral(int i, int j, int size) {
  const int m = size - 1;
  // Integer numerators: texels mirrored about the centre get exactly negated coordinates.
  return {static_cast<double>(2 * j - m) / m, static_cast<double>(2 * i - m) / m};
}

bool is_geometry_image_size(int size) {
  if (size < 3) return false;
  const int m = size - 1;
  return (m & (m - 1)) == 0;
}

Eigen::Vector2i canonical_texel(int i, int j, int size) {
  const int m = size - 1;
  for (int guard = 0; guard < 4; ++guard) {
    const int i0 = i, j0 = j;
    if (i == 0 || i == m) j = std::min(j, m - j);
    if (j == 0 || j == m) i = std::min(i, m - i);
    if (i == i0 && j == j0) break;
  }
  return {i, j};
}

// ---------------------------------------------------------------------------------------
// Sampling

Result<GeometryImage> sample_geometry_image(const TriMesh& mesh, const RowMat3d& S, int resolution,
                                            const GeometryImageOptions& options) {
  if (!is_geometry_image_size(resolution) || resolution > 16385)
    return Status(ErrorCode::InvalidArgument, "geometry image size " + std::to_string(resolution) +
                                                  " is not 2^k+1 (3, 5, 9, ..., 129, 257, ..., 16385)");
  if (mesh.F.rows() == 0 || mesh.V.rows() == 0) return Status(ErrorCode::InvalidInput, "the mesh has no faces");
  if (S.rows() != mesh.V.rows())
    return Status(ErrorCode::InvalidInput, "the sphere map has " + std::to_string(S.rows()) +
                                               " points but the mesh has " + std::to_string(mesh.V.rows()) +
                                               " vertices");
  const auto nv = static_cast<int>(mesh.V.rows());
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= nv)
    return Status(ErrorCode::InvalidInput, "a face refers to a vertex that does not exist");
  if (!S.allFinite() || !mesh.V.allFinite())
    return Status(ErrorCode::InvalidInput, "the mesh or its sphere map has a NaN/Inf coordinate");

  // Area-weighted vertex normals (unnormalized face normals summed), then normalized.
  RowMat3d vertex_normals = RowMat3d::Zero(nv, 3);
  RowMat3d face_normals(mesh.F.rows(), 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    face_normals.row(f) = n.transpose();
    for (int k = 0; k < 3; ++k) vertex_normals.row(mesh.F(f, k)) += n.transpose();
  }
  for (int v = 0; v < nv; ++v) {
    const double len = vertex_normals.row(v).norm();
    if (len > 0) vertex_normals.row(v) /= len;
  }

  const SphereLocator locator(mesh.F, S);
  const int n = resolution;
  GeometryImage image;
  image.size = n;
  const auto texels = static_cast<std::size_t>(n) * n;
  image.positions.assign(texels * 3, 0.0f);
  image.normals.assign(texels * 3, 0.0f);
  image.face_ids.assign(texels, -1);
  image.in_hole.assign(texels, 0);
  int in_holes = 0;

#pragma omp parallel for schedule(dynamic, 4) num_threads(thread_count(options.threads)) reduction(+ : in_holes)
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d uv = texel_to_octahedral(i, j, n);
      const Eigen::Vector3d p = octahedral_to_sphere(uv.x(), uv.y());
      const SphereLocation loc = locator.locate(p);
      const std::size_t t = static_cast<std::size_t>(i) * n + j;
      if (loc.face < 0) continue;  // cannot happen: the mesh has faces
      if (!loc.inside) {
        ++in_holes;
        image.in_hole[t] = 1;
      }
      Eigen::Vector3d pos = Eigen::Vector3d::Zero(), nor = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        const int v = mesh.F(loc.face, k);
        pos += loc.bary[k] * mesh.V.row(v).transpose();
        nor += loc.bary[k] * vertex_normals.row(v).transpose();
      }
      if (!(nor.norm() > 1e-300)) nor = face_normals.row(loc.face).transpose();
      if (!(nor.norm() > 1e-300)) nor = p;
      nor.normalize();
      for (int k = 0; k < 3; ++k) {
        image.positions[3 * t + k] = static_cast<float>(pos[k]);
        image.normals[3 * t + k] = static_cast<float>(nor[k]);
      }
      image.face_ids[t] = loc.face;
    }
  }
  image.texels_in_holes = in_holes;
  if (options.fit_positions) SPHEREKIT_RETURN_IF_ERROR(fit_geometry_image_positions(mesh, S, &image));
  return image;
}

// ---------------------------------------------------------------------------------------
// Remesh

std::vector<int> geometry_image_welded_ids(int n, int* count) {
  std::vector<int> id(static_cast<std::size_t>(n) * n, -1);
  int nv = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2i c = canonical_texel(i, j, n);
      const std::size_t canon = static_cast<std::size_t>(c.x()) * n + c.y();
      if (id[canon] < 0) id[canon] = nv++;
      id[static_cast<std::size_t>(i) * n + j] = id[canon];
    }
  if (count) *count = nv;
  return id;
}

RowMat3i geometry_image_grid_faces(int n) {
  const int m = n - 1, half = m / 2;
  RowMat3i F(2 * static_cast<Eigen::Index>(m) * m, 3);
  Eigen::Index f = 0;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      // Cell corners counter-clockwise in (u, v): A (i,j), B (i,j+1), C (i+1,j+1), D (i+1,j).
      const int A = i * n + j, B = i * n + j + 1, C = (i + 1) * n + j + 1, D = (i + 1) * n + j;
      if ((j >= half) == (i >= half)) {
        F.row(f++) << A, B, D;
        F.row(f++) << B, C, D;
      } else {
        F.row(f++) << A, B, C;
        F.row(f++) << A, C, D;
      }
    }
  return F;
}

TriMesh geometry_image_mesh(const GeometryImage& image) {
  TriMesh out;
  const int n = image.size;
  if (!is_geometry_image_size(n) || image.positions.size() != static_cast<std::size_t>(n) * n * 3) return out;
  int nv = 0;
  const std::vector<int> vertex_of = geometry_image_welded_ids(n, &nv);
  out.V.resize(nv, 3);
  std::vector<bool> written(static_cast<std::size_t>(nv), false);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = vertex_of[static_cast<std::size_t>(i) * n + j];
      if (written[static_cast<std::size_t>(v)]) continue;
      written[static_cast<std::size_t>(v)] = true;
      out.V.row(v) = image.position(i, j).cast<double>().transpose();
    }
  out.F = geometry_image_grid_faces(n);
  for (Eigen::Index f = 0; f < out.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) out.F(f, c) = vertex_of[static_cast<std::size_t>(out.F(f, c))];
  return out;
}

std::vector<std::uint8_t> geometry_image_hole_faces(const GeometryImage& image) {
  const int n = image.size;
  std::vector<std::uint8_t> out;
  if (!is_geometry_image_size(n) || image.in_hole.size() != static_cast<std::size_t>(n) * n) return out;
  // A face is in a hole when most of it is: two or three of its corners (a discrete "its
  // centre lies in the hole"). Faces with one hole corner reach from the surface to the rim
  // (where hole texels sit) and are the remesh's only cover of the band along the rim;
  // leaving them out too would leave that band uncovered (bunny at 257: 79.9 instead of
  // 82.7 dB, the loss all in the original-to-remesh direction).
  const RowMat3i grid = geometry_image_grid_faces(n);  // geometry_image_mesh's face order
  const auto faces = static_cast<std::size_t>(grid.rows());
  out.assign(faces, 0);
  bool any = false;
  for (std::size_t f = 0; f < faces; ++f) {
    int corners = 0;
    for (int k = 0; k < 3; ++k) corners += image.in_hole[static_cast<std::size_t>(grid(static_cast<Eigen::Index>(f), k))] != 0;
    out[f] = corners >= 2 ? 1 : 0;
    any = any || out[f];
  }
  if (!any) return out;

  // The faces left must stay a manifold: where two holes (or two arms of one) meet at a
  // vertex, their kept faces would form two fans joined only there. The hole faces around
  // such a vertex are kept until there is none (the set of kept faces only grows, so this
  // ends). Fans are counted as check_mesh counts them.
  int vertices = 0;
  const std::vector<int> id = geometry_image_welded_ids(n, &vertices);
  TriMesh kept;
  kept.V = RowMat3d::Zero(vertices, 3);  // only the vertex count matters
  for (;;) {
    kept.F.resize(static_cast<Eigen::Index>(std::count(out.begin(), out.end(), 0)), 3);
    Eigen::Index row = 0;
    for (std::size_t f = 0; f < faces; ++f) {
      if (out[f]) continue;
      for (int k = 0; k < 3; ++k) kept.F(row, k) = id[static_cast<std::size_t>(grid(static_cast<Eigen::Index>(f), k))];
      ++row;
    }
    const std::vector<int> fans = detail::fans_per_vertex(kept, detail::corner_fans(kept, detail::build_topology(kept)));
    bool pinched = false;
    for (std::size_t f = 0; f < faces; ++f)
      for (int k = 0; k < 3 && out[f]; ++k)
        if (fans[static_cast<std::size_t>(id[static_cast<std::size_t>(grid(static_cast<Eigen::Index>(f), k))])] > 1)
          out[f] = 0, pinched = true;
    if (!pinched) return out;
  }
}

TriMesh geometry_image_open_mesh(const GeometryImage& image) {
  return remove_faces(geometry_image_mesh(image), geometry_image_hole_faces(image));
}

// ---------------------------------------------------------------------------------------
// Remesh error

namespace {

// AABB tree over triangles for closest-point queries (median split on the longest axis).
class TriangleTree {
 public:
  explicit TriangleTree(const TriMesh& mesh) : mesh_(mesh) {
    const auto nf = static_cast<int>(mesh.F.rows());
    order_.resize(static_cast<std::size_t>(nf));
    centroids_.resize(static_cast<std::size_t>(nf));
    for (int f = 0; f < nf; ++f) {
      order_[static_cast<std::size_t>(f)] = f;
      centroids_[static_cast<std::size_t>(f)] =
          (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))).transpose() / 3.0;
    }
    nodes_.reserve(static_cast<std::size_t>(2 * nf / kLeafSize + 2));
    if (nf > 0) build(0, nf);
  }

  // Squared distance from p to the mesh.
  double squared_distance(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    if (nodes_.empty()) return best;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
      if (node.box.squaredExteriorDistance(p) >= best) continue;
      if (node.count > 0) {
        for (int k = node.first; k < node.first + node.count; ++k) {
          const int f = order_[static_cast<std::size_t>(k)];
          Eigen::Vector3d bary;
          const Eigen::Vector3d q = detail::closest_point_on_triangle(
              p, mesh_.V.row(mesh_.F(f, 0)).transpose(), mesh_.V.row(mesh_.F(f, 1)).transpose(),
              mesh_.V.row(mesh_.F(f, 2)).transpose(), bary);
          best = std::min(best, (q - p).squaredNorm());
        }
        continue;
      }
      const double dl = nodes_[static_cast<std::size_t>(node.left)].box.squaredExteriorDistance(p);
      const double dr = nodes_[static_cast<std::size_t>(node.right)].box.squaredExteriorDistance(p);
      // Push the farther child first so the nearer one is searched first.
      if (dl <= dr) {
        if (dr < best) stack[top++] = node.right;
        if (dl < best) stack[top++] = node.left;
      } else {
        if (dl < best) stack[top++] = node.left;
        if (dr < best) stack[top++] = node.right;
      }
    }
    return best;
  }

 private:
  static constexpr int kLeafSize = 4;
  struct Node {
    Eigen::AlignedBox3d box;
    int left = -1, right = -1, first = 0, count = 0;  // count > 0: leaf
  };

  int build(int first, int last) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    Eigen::AlignedBox3d box, cbox;
    for (int k = first; k < last; ++k) {
      const int f = order_[static_cast<std::size_t>(k)];
      for (int c = 0; c < 3; ++c) box.extend(mesh_.V.row(mesh_.F(f, c)).transpose());
      cbox.extend(centroids_[static_cast<std::size_t>(f)]);
    }
    nodes_[static_cast<std::size_t>(index)].box = box;
    if (last - first <= kLeafSize) {
      nodes_[static_cast<std::size_t>(index)].first = first;
      nodes_[static_cast<std::size_t>(index)].count = last - first;
      return index;
    }
    int axis;
    cbox.sizes().maxCoeff(&axis);
    const int mid = (first + last) / 2;
    std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + last, [&](int a, int b) {
      const double ca = centroids_[static_cast<std::size_t>(a)][axis], cb = centroids_[static_cast<std::size_t>(b)][axis];
      return ca < cb || (ca == cb && a < b);
    });
    const int left = build(first, mid);
    const int right = build(mid, last);
    nodes_[static_cast<std::size_t>(index)].left = left;
    nodes_[static_cast<std::size_t>(index)].right = right;
    return index;
  }

  const TriMesh& mesh_;
  std::vector<int> order_;
  std::vector<Eigen::Vector3d> centroids_;
  std::vector<Node> nodes_;
};

// Points uniformly distributed by area: each face gets floor(expected) samples plus one more
// with probability frac(expected); positions by the square-root barycentric rule.
std::vector<Eigen::Vector3d> sample_surface(const TriMesh& mesh, int samples, std::uint64_t seed) {
  std::vector<Eigen::Vector3d> points;
  const Eigen::Index nf = mesh.F.rows();
  std::vector<double> area(static_cast<std::size_t>(nf));
  double total = 0;
  for (Eigen::Index f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    area[static_cast<std::size_t>(f)] = 0.5 * (b - a).cross(c - a).norm();
    total += area[static_cast<std::size_t>(f)];
  }
  if (!(total > 0)) return points;
  std::mt19937_64 rng(seed);
  const auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  points.reserve(static_cast<std::size_t>(samples) + static_cast<std::size_t>(nf));
  for (Eigen::Index f = 0; f < nf; ++f) {
    const double expected = area[static_cast<std::size_t>(f)] / total * samples;
    int count = static_cast<int>(std::floor(expected));
    if (uniform() < expected - count) ++count;
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    for (int k = 0; k < count; ++k) {
      const double r1 = std::sqrt(uniform()), r2 = uniform();
      points.push_back((1 - r1) * a + r1 * (1 - r2) * b + r1 * r2 * c);
    }
  }
  return points;
}

// RMS and max of the distances of `points` to the mesh in `tree` (sum in a fixed order).
void one_sided(const std::vector<Eigen::Vector3d>& points, const TriangleTree& tree, int threads, double& rms,
               double& max_distance) {
  std::vector<double> d2(points.size());
  const auto np = static_cast<std::int64_t>(points.size());
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
  for (std::int64_t k = 0; k < np; ++k) d2[static_cast<std::size_t>(k)] = tree.squared_distance(points[static_cast<std::size_t>(k)]);
  double sum = 0, mx = 0;
  for (double x : d2) {
    sum += x;
    mx = std::max(mx, x);
  }
  rms = points.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(points.size()));
  max_distance = std::max(max_distance, std::sqrt(mx));
}

}  // namespace

RemeshError remesh_error(const TriMesh& original, const TriMesh& remesh_in, const RemeshErrorOptions& options,
                         const std::vector<std::uint8_t>& excluded_remesh_faces) {
  RemeshError e;
  TriMesh kept;
  const bool exclude = !excluded_remesh_faces.empty() &&
                       excluded_remesh_faces.size() == static_cast<std::size_t>(remesh_in.F.rows());
  if (exclude) {
    kept.V = remesh_in.V;
    kept.F.resize(remesh_in.F.rows(), 3);
    Eigen::Index k = 0;
    for (Eigen::Index f = 0; f < remesh_in.F.rows(); ++f)
      if (!excluded_remesh_faces[static_cast<std::size_t>(f)]) kept.F.row(k++) = remesh_in.F.row(f);
    kept.F.conservativeResize(k, 3);
  }
  const TriMesh& remesh = exclude ? kept : remesh_in;
  if (original.F.rows() == 0 || remesh.F.rows() == 0 || original.V.rows() == 0 || remesh.V.rows() == 0) {
    e.psnr = std::numeric_limits<double>::quiet_NaN();
    return e;
  }
  e.peak = (original.V.colwise().maxCoeff() - original.V.colwise().minCoeff()).norm();
  const int threads = thread_count(options.threads);
  const TriangleTree original_tree(original), remesh_tree(remesh);
  const auto on_original = sample_surface(original, options.samples, options.seed);
  const auto on_remesh = sample_surface(remesh, options.samples, options.seed ^ 0x9e3779b97f4a7c15ULL);
  one_sided(on_original, remesh_tree, threads, e.rms_forward, e.max_distance);
  one_sided(on_remesh, original_tree, threads, e.rms_backward, e.max_distance);
  e.rms = std::max(e.rms_forward, e.rms_backward);
  e.psnr = e.rms > 0 ? 20.0 * std::log10(e.peak / e.rms) : std::numeric_limits<double>::infinity();
  return e;
}

double remesh_psnr(const TriMesh& original, const TriMesh& remesh, const RemeshErrorOptions& options,
                   const std::vector<std::uint8_t>& excluded_remesh_faces) {
  return remesh_error(original, remesh, options, excluded_remesh_faces).psnr;
}

}  // namespace spherekit
