// Procedural meshes for tests: exact, small, generated here (no data files needed).
#pragma once

#include <cstdint>

#include "spherekit/mesh.h"

namespace spherekit::test {

/// Regular tetrahedron inscribed in the unit sphere, outward (ccw) faces.
TriMesh tetrahedron();
/// Regular octahedron (+-x, +-y, +-z), outward faces.
TriMesh octahedron();
/// Icosahedron subdivided `level` times, vertices on the unit sphere (level 0: 12 V, 20 F).
TriMesh icosphere(int level);
/// Torus (genus 1) with n x m quads split into triangles.
TriMesh torus(int n = 12, int m = 8);
/// Two disjoint tetrahedra.
TriMesh two_tetrahedra();
/// Two tetrahedra sharing one vertex (a pinched, non-manifold vertex, genus 0 after repair).
TriMesh pinched_tetrahedra();
/// Icosphere(level) with `holes` disjoint patches of faces removed (one boundary loop each, <= 3).
TriMesh sphere_with_holes(int level, int holes);
/// A random genus-0 surface: an icosphere whose radius varies smoothly (bumps, elongation),
/// deterministic in `seed`; star-shaped so always embedded.
TriMesh random_blob(int level, std::uint64_t seed);
/// A long thin shape (capsule stretched `aspect` times along x): hard for stretch.
TriMesh elongated(int level, double aspect);

}  // namespace spherekit::test
