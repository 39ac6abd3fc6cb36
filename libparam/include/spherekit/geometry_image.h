// Octahedral geometry images of a sphere map (Praun & Hoppe 2003, §1.5 of ALGORITHM.md):
// the octahedral map of the unit sphere, a spatial locator over a sphere map, resampling a
// mesh into an N x N image (N = 2^k+1), the remesh an image defines, and the remesh PSNR
// (the single definition used by `convert`, the tests and the samples).
//
// Texel convention. Texel (i, j) = (row, column) of an N x N image samples the domain point
//   u = -1 + 2j/(N-1),  v = -1 + 2i/(N-1)          (u grows with the column, v with the row)
// and the sphere point octahedral_to_sphere(u, v). With rows drawn upwards (row 0 at the
// bottom) the square looks like this; "+x+y+z" names the octant that lands in each triangle:
//
//   row N-1    (-z)--------------(+y)--------------(-z)     v = +1
//               | -x+y-z       /  |  \       +x+y-z |
//               |           /     |     \           |
//               |        /  -x+y+z|+x+y+z  \        |
//   row (N-1)/2 (-x)-------------(+z)-------------(+x)     v =  0
//               |        \  -x-y+z|+x-y+z  /        |
//               |           \     |     /           |
//               | -x-y-z       \  |  /       +x-y-z |
//   row 0      (-z)--------------(-y)--------------(-z)     v = -1
//             col 0          col (N-1)/2        col N-1
//             u = -1            u = 0            u = +1
//
// The inner diamond |u|+|v| <= 1 is the upper hemisphere (z >= 0, (u,v) = (x,y) after the
// central projection onto |x|+|y|+|z| = 1); the lower hemisphere is folded out into the four
// corner triangles. The 6 octahedron vertices are texels: +z = centre, +-x = middle of the
// right/left column, +-y = middle of the top/bottom row, and all four corners are the -z pole.
// Every side of the square is folded at its midpoint, so border texels come in equal pairs:
//   (0, s) == (0, N-1-s),  (N-1, s) == (N-1, N-1-s),  (s, 0) == (N-1-s, 0),  (s, N-1) == (N-1-s, N-1).
// Texels of one pair hold bit-identical values (the domain coordinates are computed so that
// their sphere points are bit-identical).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit {

// ---------------------------------------------------------------------------------------
// The octahedral map

/// Domain point (u, v) in [-1,1]^2 -> unit vector (inverse octahedral map, then normalize).
Eigen::Vector3d octahedral_to_sphere(double u, double v);
/// Unit (or any non-zero) vector -> (u, v) in [-1,1]^2. Points on a fold map to one of
/// their (equal) domain images.
Eigen::Vector2d sphere_to_octahedral(const Eigen::Vector3d& p);
/// Domain point of texel (row i, column j) of an N x N image; folded border pairs give
/// exactly negated coordinates so that their sphere points are bit-identical.
Eigen::Vector2d texel_to_octahedral(int i, int j, int size);
/// True for sizes 2^k+1 with k >= 1 (3, 5, 9, ..., 257, ...).
bool is_geometry_image_size(int size);
/// Texel that stands for (i, j) after welding the folded borders: the first of its fold pair
/// (smaller column on the top/bottom rows, smaller row on the left/right columns); the four
/// corners all map to (0, 0). Interior texels map to themselves.
Eigen::Vector2i canonical_texel(int i, int j, int size);

// ---------------------------------------------------------------------------------------
// Locating sphere points in a sphere map

/// A sphere point located in a sphere map.
struct SphereLocation {
  int face = -1;               ///< face index, -1 only when the map has no usable face
  Eigen::Vector3d bary{0, 0, 0};  ///< barycentrics (>= 0, sum 1) of the point in that face
  bool inside = false;         ///< false: the point is in no face (a hole); `face` is the
                               ///< nearest face and `bary` the nearest point on it
};

/// Spatial index over the faces of a sphere map (faces F over unit vectors S): which face
/// contains a direction, with barycentrics by gnomonic (central) projection onto the face's
/// chord plane, which is exact for the great-circle edges of the spherical triangle (so two
/// faces sharing an edge agree on it).
///
/// Index: a G x G uniform grid over the octahedral domain (G even, about sqrt(#F)); every
/// face is listed in the cells whose spherical bounding cap meets its own bounding cap, found
/// by a flood fill that follows the folded borders (faces crossing the octahedral seams need
/// no special case). A query visits one cell. Points on edges and vertices (barycentric
/// tolerance 1e-9) go to the candidate with the largest smallest barycentric. Points in no
/// face (holes of the mesh, which sphere maps leave uncovered) get the nearest face found in
/// the surrounding cells (nearest in chord distance) with the barycentrics of the nearest
/// point on it. Faces whose sphere triangle is inverted or degenerate are never "inside".
class SphereLocator {
 public:
  /// `S` #V by 3 unit vectors, `F` faces (ccw seen from outside). Empty F: every query
  /// returns face -1.
  SphereLocator(const RowMat3i& F, const RowMat3d& S);
  ~SphereLocator();
  SphereLocator(SphereLocator&&) noexcept;
  SphereLocator& operator=(SphereLocator&&) noexcept;

  /// Locates a unit direction. Thread-safe (const).
  SphereLocation locate(const Eigen::Vector3d& direction) const;
  /// Grid size G of the index (for tests and statistics).
  int grid_size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Gnomonic barycentrics of direction `p` in the spherical triangle (a, b, c): the
/// barycentrics of the point where the ray t*p (t > 0) meets the plane through a, b, c.
/// Returns false (and leaves `bary` untouched) if the ray misses the plane (p on the far
/// side or the triangle degenerate).
bool gnomonic_barycentrics(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                           const Eigen::Vector3d& p, Eigen::Vector3d& bary);

// ---------------------------------------------------------------------------------------
// Geometry images

struct GeometryImageOptions {
  int threads = 0;  ///< effort: worker threads for sampling (0: all cores); output is identical
  /// false: every texel holds the surface point it samples. true: the positions are then
  /// fitted by least squares (fit_geometry_image_positions), which lowers the remesh error;
  /// normals, face ids and hole flags stay the sampled ones.
  bool fit_positions = false;
};

/// An octahedral geometry image: N x N texels, row-major (texel (i, j) at index i*N + j).
struct GeometryImage {
  int size = 0;                 ///< N = 2^k+1
  std::vector<float> positions;  ///< N*N*3: surface point of each texel
  std::vector<float> normals;    ///< N*N*3: unit normal (area-weighted vertex normals interpolated)
  std::vector<std::int32_t> face_ids;  ///< N*N: face of the source mesh each texel fell in
  std::vector<std::uint8_t> in_hole;   ///< N*N: 1 if the texel's sphere point lies in no face
                                       ///< (a hole of the mesh; the nearest face's value is used)
  int texels_in_holes = 0;      ///< number of texels with in_hole == 1

  Eigen::Vector3f position(int i, int j) const {
    const float* p = &positions[3 * (static_cast<std::size_t>(i) * size + j)];
    return {p[0], p[1], p[2]};
  }
  Eigen::Vector3f normal(int i, int j) const {
    const float* p = &normals[3 * (static_cast<std::size_t>(i) * size + j)];
    return {p[0], p[1], p[2]};
  }
};

/// Resamples `mesh` through its sphere map `S` (#V by 3 unit vectors, same vertex order):
/// texel (i, j) -> sphere point -> face containing it (SphereLocator) -> positions and
/// normals interpolated with the gnomonic barycentrics. Texels falling into holes take the
/// nearest face's value (see SphereLocator). `resolution` must be 2^k+1 (k >= 1).
/// Errors: InvalidArgument (resolution), InvalidInput (S and V differ in size, empty mesh,
/// face index out of range).
[[nodiscard]] Result<GeometryImage> sample_geometry_image(const TriMesh& mesh, const RowMat3d& S, int resolution,
                                                          const GeometryImageOptions& options = {});

/// Replaces the sampled positions of `image` (from sample_geometry_image of the same mesh and
/// map) by the least-squares fit of the surface: the texel values whose remesh
/// (geometry_image_mesh) is closest to the mesh in the L2 sense over the surface, with a small
/// pull towards the sampled values so that texels no surface sample reaches keep theirs.
/// Surface samples are a lattice on every face (about 16 per grid triangle), carried into the
/// octahedral domain through the map exactly as the sampler carries texels to the surface.
/// Folded border pairs stay identical (they are one unknown). Deterministic.
/// Errors: InvalidArgument (image not sampled), InvalidInput (map size), SolverFailed.
[[nodiscard]] Status fit_geometry_image_positions(const TriMesh& mesh, const RowMat3d& S, GeometryImage* image);

/// Welded numbering of an n x n octahedral image's texels: the folded border identifies
/// texels (canonical_texel), and each class gets one id, numbered in order of first
/// appearance in row-major order. Returns the id of every texel (i * n + j); *count gets the
/// number of ids. The vertex order of geometry_image_mesh.
std::vector<int> geometry_image_welded_ids(int n, int* count);

/// The triangles of an n x n octahedral grid on texel indices (i * n + j), two per cell,
/// counter-clockwise in (u, v), split along the diamond edges of the octahedron (the
/// anti-diagonal in quadrants u * v > 0, the main diagonal elsewhere). The face order of
/// geometry_image_mesh.
RowMat3i geometry_image_grid_faces(int n);

/// The remesh an image defines: one vertex per texel with the folded border duplicates
/// welded (canonical_texel; (N-2)^2 + 2N - 1 vertices, vertex index = order of first
/// appearance in row-major texel order), two triangles per cell, each cell split along the
/// diagonal parallel to its quadrant's diamond edge (so the octahedron's edges are mesh
/// edges), ccw as seen from outside when the sphere map preserves orientation. The result is
/// a closed genus-0 manifold with 2(N-1)^2 faces. An empty/invalid image gives an empty mesh.
TriMesh geometry_image_mesh(const GeometryImage& image);

/// Per face of geometry_image_mesh(image) (same order): 1 if at least two of its three texels
/// are in a hole. Such faces span (part of) a hole of the source mesh: hole texels sit at the
/// nearest point of the nearest face, on the hole's rim, so these faces keep the remesh closed
/// but are not resampled surface. Faces with a single hole texel are kept: they reach from
/// the surface to the rim and cover the band along it. So are the hole faces around a vertex
/// where the kept faces would otherwise meet in two fans, so that the faces left form a
/// manifold (geometry_image_open_mesh). Empty if image.in_hole is.
std::vector<std::uint8_t> geometry_image_hole_faces(const GeometryImage& image);

/// The remesh of a mesh with holes with its holes open: geometry_image_mesh(image) without the
/// faces geometry_image_hole_faces flags and without the vertices no remaining face uses; the
/// rest keep their order. Equals geometry_image_mesh(image) for an image without hole texels.
TriMesh geometry_image_open_mesh(const GeometryImage& image);

// ---------------------------------------------------------------------------------------
// Remesh error (PSNR) — the one definition used everywhere in SphereKit

struct RemeshErrorOptions {
  int samples = 400000;     ///< points sampled on each mesh (uniform by area), per direction
  std::uint64_t seed = 1;   ///< sampling is deterministic in the seed
  int threads = 0;          ///< 0: all cores; the result does not depend on it
};

struct RemeshError {
  double peak = 0;          ///< bounding-box diagonal of the original
  double rms_forward = 0;   ///< RMS distance of points of the original to the remesh
  double rms_backward = 0;  ///< RMS distance of points of the remesh to the original
  double rms = 0;           ///< symmetric RMS distance d = max(rms_forward, rms_backward)
  double max_distance = 0;  ///< largest sampled distance, either direction (Hausdorff estimate)
  double psnr = 0;          ///< 20 log10(peak / rms) in dB; +infinity when rms == 0
};

/// Remesh error by dense sampling (Metro-style, both directions): points are sampled
/// uniformly by area on each mesh (count per face proportional to its area) and their
/// distance to the other mesh is exact point-to-triangle distance, found with an AABB tree.
/// PSNR = 20 log10(bounding-box diagonal of `original` / d), d = the larger of the two
/// one-sided RMS distances. Empty meshes give psnr = NaN.
///
/// `excluded_remesh_faces` (empty, or one flag per remesh face): faces flagged 1 are left out
/// of the remesh's surface on both sides of the measure. Pass geometry_image_hole_faces() for a
/// source mesh with holes, so that the faces spanning the holes (which have no counterpart in
/// the original) do not dominate the error; callers should report that they did so.
RemeshError remesh_error(const TriMesh& original, const TriMesh& remesh, const RemeshErrorOptions& options = {},
                         const std::vector<std::uint8_t>& excluded_remesh_faces = {});
/// remesh_error(...).psnr.
double remesh_psnr(const TriMesh& original, const TriMesh& remesh, const RemeshErrorOptions& options = {},
                   const std::vector<std::uint8_t>& excluded_remesh_faces = {});

}  // namespace spherekit
