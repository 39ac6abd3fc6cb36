// Catmull–Clark base cages defined on the sphere domain (issue 6; Lee, Moreton & Hoppe 2000,
// "Displaced subdivision surfaces", steps 2–3, ALGORITHM.md §4.1–4.2).
//
// The cage. Its topology and its embedding in the sphere are fixed by one integer n: the cube
// with each face split into n x n quads, 6n^2 quads and 6n^2 + 2 control vertices, projected
// onto the unit sphere equi-angularly (a cube-face coordinate s in [0,1] becomes the angle
// (2s-1)·pi/4 from the face centre, which spreads the quads' areas within a factor ~1.3 instead
// of ~5 for the plain central projection). Because the cage lives on the sphere domain, not on
// any one mesh, it is the same for every mesh mapped to the sphere and, for the members of a
// consistent collection, cage vertex k sits at the same place on every member.
//
// Why the cube: of the polyhedral domains of Praun & Hoppe 2003 it is the only one whose
// subdivision is all quads (Catmull–Clark's native element: no per-corner ptex sub-faces), and
// its only extraordinary vertices are its 8 corners, of valence 3 (the mildest irregularity;
// the octahedral grid would have valence-2 vertices at its folds, where the limit surface
// degenerates). Every other vertex is regular (valence 4), so Bfr evaluates most faces as
// regular bicubic patches.
//
// Face parameterization. Quad f lies on cube face k = face_cell[f][0] in cell (a, b) =
// (face_cell[f][1], face_cell[f][2]); its corners are the lattice points (a,b), (a+1,b),
// (a+1,b+1), (a,b+1), in that order, counter-clockwise seen from outside, and the limit
// surface's (u, v) on it (OpenSubdiv's quad parameterization: u from corner 0 to 1, v from
// corner 0 to 3) is the domain point with cube-face coordinates s = (a+u)/n, t = (b+v)/n.
// So a point (f, u, v) of the limit surface corresponds to one sphere point, and through a
// sphere map to one point of the mesh: that is how the cage is fitted and displacements are
// sampled.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// The cage's topology and its embedding in the sphere domain.
struct CageDomain {
  int n = 0;                                   ///< quads per cube-face edge
  RowMat3d sphere;                             ///< #V x 3: unit domain point of each control vertex
  std::vector<std::array<int, 4>> quads;       ///< 6n^2 quads, ccw seen from outside
  std::vector<std::array<int, 3>> face_cell;   ///< per quad: cube face k (0..5), cell a, cell b
};

/// The cube cage domain with n x n quads per cube face (n >= 1). Vertex numbering is
/// deterministic and depends on n only.
[[nodiscard]] Result<CageDomain> cube_cage_domain(int n);

/// Number of distinct points of the lattice with m x m cells per cube face (6m^2 + 2).
long long cube_lattice_points(int m);
/// Id (0 .. cube_lattice_points(m) - 1) of lattice point (i, j), 0 <= i, j <= m, of cube face
/// k: points on cube edges and corners, shared by 2 or 3 faces, get one id. The vertex ids of
/// cube_cage_domain(n) are cube_lattice_id(n, ...) of the quad corners.
int cube_lattice_id(int m, int k, int i, int j);

/// The unit sphere point of cube face k at cube-face coordinates (s, t) in [0,1]^2
/// (equi-angular projection).
Eigen::Vector3d cube_domain_point(int k, double s, double t);
/// The sphere point of the limit surface's parameter (u, v) in quad f (see the file comment).
Eigen::Vector3d cage_domain_point(const CageDomain& domain, int f, double u, double v);

/// The Catmull–Clark limit surface of a cage (OpenSubdiv Bfr), as limit stencils: the limit
/// position and its derivatives at (f, u, v) are weighted sums of control points. The weights
/// depend on the topology only, so one CageLimit serves every mesh with the same n.
class CageLimit {
 public:
  /// Builds the Bfr surfaces of every quad. Errors: InvalidArgument (empty or malformed domain),
  /// Internal (OpenSubdiv refused the topology).
  [[nodiscard]] static Result<CageLimit> create(const CageDomain& domain);
  ~CageLimit();
  CageLimit(CageLimit&&) noexcept;
  CageLimit& operator=(CageLimit&&) noexcept;

  struct Stencil {
    std::vector<int> indices;     ///< control points involved
    std::vector<double> w, wu, wv;  ///< weights of the position, d/du, d/dv
  };
  /// Limit stencil at (u, v) in [0,1]^2 of quad f. Thread-safe (const).
  void stencil(int f, double u, double v, Stencil& out) const;
  /// Limit position and unit normal (du x dv, outward for a ccw cage) at (f, u, v) for the
  /// control points `points` (#V x 3). Thread-safe.
  void evaluate(const RowMat3d& points, int f, double u, double v, Eigen::Vector3d& position,
                Eigen::Vector3d& normal) const;
  int faces() const;

 private:
  CageLimit();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct CageFitOptions {
  int samples_per_edge = 8;   ///< the fit samples k x k points per quad (cell centres)
  double smoothness = 1e-3;   ///< weight of the umbrella-Laplacian term relative to one quad's samples
  double hole_weight = 0.05;  ///< weight of samples whose sphere point falls in a hole of the mesh
  int project_iterations = 2; ///< re-fits with each sample's target moved to the mesh point
                              ///< closest to its current limit point (see fit_subd_cage)
  int threads = 0;            ///< effort: 0 = all cores; the result does not depend on it
};

/// A fitted cage: control points whose limit surface approximates the mesh.
struct SubdCage {
  CageDomain domain;
  RowMat3d points;        ///< #V x 3 control points
  int fit_samples = 0;    ///< samples in the least-squares system
  double fit_rms = 0;     ///< RMS distance of the limit surface to the samples (unweighted)
};

/// Fits the control points of cube_cage_domain(n) by linear least squares so that the limit
/// surface at each sample's (f, u, v) matches the mesh point at the same sphere point (located
/// in the sphere map S, #V x 3, gnomonic barycentrics), plus a small umbrella-Laplacian term
/// that keeps the system definite where samples are scarce (holes). The sphere map fixes where
/// on the limit surface each mesh point goes, which the cubic patches can follow only
/// approximately (most visibly around the valence-3 corners, where the patches' own
/// parameterization differs from the equi-angular one), and that tangential mismatch would
/// cost normal accuracy. So the fit is then repeated project_iterations times with each
/// sample's target replaced by the mesh point closest to its current limit point (as DSS fits
/// by projection), kept only where that point's face faces the same way as the limit normal
/// (so a thin part cannot pull the surface onto its other side). The system matrix does not
/// change, so each repeat costs one back-substitution. Deterministic.
/// Errors: InvalidArgument (n < 1, options), InvalidInput (S and V differ in size, empty mesh),
/// SolverFailed (the normal equations are singular), Cancelled (progress returned false).
[[nodiscard]] Result<SubdCage> fit_subd_cage(const TriMesh& mesh, const RowMat3d& S, const CageLimit& limit,
                                             const CageDomain& domain, const CageFitOptions& options = {},
                                             const ProgressFn& progress = {});

struct CageUvAtlas;

/// Writes the cage as an OBJ (v lines, then quad f lines, 1-based), atomically. With `uv`, also
/// four `vt` lines per quad, in quad order (the UVs of its corners 0..3, cage_uv_atlas.h), and
/// `f v/vt ...` faces: every quad its own chart, so a tool that subdivides the cage with
/// linear face-varying interpolation (Blender: UV Smooth "None"; OpenSubdiv
/// FVAR_LINEAR_ALL) maps the limit-surface parameter (u, v) bilinearly onto the quad's tile.
[[nodiscard]] Status write_cage_obj(const std::string& path, const SubdCage& cage, const std::string& comment = {},
                                    const CageUvAtlas* uv = nullptr);

}  // namespace spherekit::convert
