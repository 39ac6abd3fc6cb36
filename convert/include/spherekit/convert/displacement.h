// Displacement maps over a Catmull–Clark cage (Lee, Moreton & Hoppe 2000 step 3; the Ptex-style
// per-face layout OpenSubdiv users apply, ALGORITHM.md §4.2), and the displaced surface they
// reconstruct.
//
// Samples. Each cage quad f carries a T x T grid of samples at (u, v) = (c/(T-1), r/(T-1)),
// c, r = 0..T-1: the tile includes its border, so a sample on a cage edge is stored in both
// quads (with values that agree up to rounding: the limit surface and its normal are continuous
// and both quads see the same mesh point), and a viewer can filter inside a tile without
// looking at neighbours.
//
// Scalar displacement (the default, one float per sample): the signed distance d along the
// limit normal n from the limit point P to the mesh, P + d n on the surface. The ray is found
// by a fixed-point iteration started at the mesh point the sphere map pairs with the sample
// (x <- closest point of the mesh to P + ((x - P)·n) n), which converges to where the normal
// line crosses the surface near that point; the iterate with the smallest residual (distance
// of P + d n to the mesh) is kept, so the result is never worse than the plain projection
// (x0 - P)·n.
// Vector displacement (three floats per sample): the object-space vector from P to the mesh
// point the sphere map pairs with the sample, so P + D reproduces that point exactly.
//
// Reconstruction. The displaced surface is evaluated at every sample and meshed as one welded
// triangle mesh on the cube lattice with n(T-1) cells per cube-face edge (vertex ids
// cube_lattice_id), two triangles per lattice cell.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spherekit/convert/subd_cage.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

enum class DisplacementKind { Scalar, Vector };

struct DisplacementOptions {
  int tile = 17;                 ///< samples per tile edge T (>= 2)
  DisplacementKind kind = DisplacementKind::Scalar;
  int max_iterations = 8;        ///< scalar: fixed-point iterations per sample
  int threads = 0;               ///< effort: 0 = all cores; the result does not depend on it
};

/// Per-quad sample tiles. Value of channel ch of sample (r, c) of quad f:
/// values[((f * tile + r) * tile + c) * channels + ch].
struct DisplacementMap {
  int cage_n = 0;                 ///< the cage's n (cube_cage_domain)
  int faces = 0;                  ///< 6 n^2
  int tile = 0;                   ///< T
  DisplacementKind kind = DisplacementKind::Scalar;
  std::vector<float> values;
  std::vector<std::uint8_t> in_hole;  ///< per sample: its sphere point is in a hole of the mesh
  int samples_in_holes = 0;
  double max_abs = 0;             ///< largest |displacement| (vector: length)
  double mean_ray_residual = 0;   ///< scalar: mean distance of P + d n to the mesh

  int channels() const { return kind == DisplacementKind::Scalar ? 1 : 3; }
};

/// Samples the displacement of `mesh` (sphere map S) over the fitted cage.
/// Errors: InvalidArgument (options), InvalidInput (sizes differ), Cancelled.
[[nodiscard]] Result<DisplacementMap> sample_displacement(const TriMesh& mesh, const RowMat3d& S, const SubdCage& cage,
                                                          const CageLimit& limit, const DisplacementOptions& options = {},
                                                          const ProgressFn& progress = {});

/// The welded triangle mesh of the displaced limit surface (or of the bare limit surface when
/// `map` is null, with `tile` samples per quad edge). `hole_faces`, if given, receives per
/// triangle 1 when one of its samples is in a hole (those span a hole of the source mesh and
/// are left out of PSNRs, as for geometry images).
TriMesh displaced_surface_mesh(const SubdCage& cage, const CageLimit& limit, const DisplacementMap* map, int tile,
                               std::vector<std::uint8_t>* hole_faces = nullptr, int threads = 0);

/// Floats a user stores for this representation: the control points plus the samples.
long long stored_floats(const SubdCage& cage, const DisplacementMap& map);

}  // namespace spherekit::convert
