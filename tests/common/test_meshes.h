// Procedural meshes for tests: exact, small, generated here (no data files needed).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

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
/// A six-armed star: an icosphere pushed out to radius 5 along the +-x, +-y, +-z axes (arms
/// where the largest coordinate of the unit direction exceeds 0.8), a limb shape whose arms
/// the stretch optimum squeezes on the sphere.
TriMesh six_armed_star(int level);

/// A mesh with polygon faces, as a DCC tool exports it.
struct PolygonMesh {
  RowMat3d V;
  std::vector<std::vector<int>> faces;  ///< 0-based corners, counter-clockwise seen from outside
};
/// A closed genus-0 "star prism" mixing every face kind: a non-convex 12-corner star base
/// (an n-gon a fan would fold), 11 twisted (non-planar) side quads, one side pentagon, a cap of
/// 11 triangles (a fan around an apex) and one cap quad. 26 vertices; 11 triangles, 12 quads,
/// 2 n-gons (25 faces, 48 triangles after triangulation).
PolygonMesh star_prism_polygons();
/// The file text of `mesh` as "obj", "off" or "ply" (ascii).
std::string polygon_mesh_text(const PolygonMesh& mesh, const std::string& format);

}  // namespace spherekit::test
