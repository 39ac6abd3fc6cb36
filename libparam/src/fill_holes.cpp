// Closing boundary loops with one centre vertex and a triangle fan per hole, the
// `Filtermesh -fillholes` step of the authors' pipeline (REFERENCE.md 2.7): hole faces are
// tagged (here: appended after the original faces) so later stages can down-weight them.
//
// The centre is the length-weighted centroid of the loop polyline, not the plain vertex
// average, so an unevenly sampled loop does not pull the centre toward its dense side.
// For a loop that is not star-shaped from that centre (e.g. a C-shaped slit) the fan
// overlaps itself in 3D. That is accepted on purpose: the fan only has to make the mesh a
// closed genus-0 surface; parameterization works on connectivity and edge lengths, and
// hole faces carry almost no weight there.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "detail/check_topology.h"
#include "spherekit/check_mesh.h"
#include "spherekit/fill_holes.h"

namespace spherekit {
namespace {

Status refuse(const std::string& why) { return Status(ErrorCode::InvalidInput, "cannot fill holes: " + why); }

// The checks fill_holes needs: loops must be well defined (manifold, consistently oriented
// edges) and the centroid finite.
Status check_fillable(const MeshCheck& c) {
  auto s = [](int x) { return std::to_string(x); };
  if (c.invalid_indices > 0)
    return refuse("face " + s(c.first_invalid_face) + " has vertex index " + s(c.first_invalid_index) +
                  " outside [0, " + s(c.vertices) + ")");
  if (c.nonmanifold_edges > 0 && c.nonmanifold_edge_ids.size() >= 2)
    return refuse("edge (" + s(c.nonmanifold_edge_ids[0]) + "," + s(c.nonmanifold_edge_ids[1]) + ") is shared by " +
                  s(c.nonmanifold_edge_face_counts[0]) + " faces, so the boundary is not a set of simple loops");
  if (c.orientation_conflicts > 0)
    return refuse("faces are inconsistently oriented (edge (" + s(c.first_conflict_from) + "," +
                  s(c.first_conflict_to) + ") is used twice in the same direction), so hole fans cannot be oriented");
  if (c.nonfinite_vertices > 0) return refuse("vertex " + s(c.first_nonfinite_vertex) + " has a NaN/Inf coordinate");
  return Status::ok_status();
}

Eigen::RowVector3d loop_centre(const RowMat3d& V, const std::vector<int>& loop) {
  // Computed on the loop scaled by a power of two that brings its largest coordinate near 1:
  // |b - a|^2 and l * (a + b) overflow for coordinates beyond ~1e154 (and underflow for tiny
  // ones), and scaling by 2^k is exact, so at ordinary scales the bits are those of the
  // unscaled formula.
  double largest = 0;
  for (int v : loop) largest = std::max(largest, V.row(v).cwiseAbs().maxCoeff());
  int exponent = 0;
  (void)std::frexp(largest, &exponent);
  // Coordinates into [-2, 2]; the clamp keeps both factors finite (2^1024 is not).
  exponent = std::clamp(exponent - 1, -1000, 1000);
  const double to_unit = std::ldexp(1.0, -exponent), back = std::ldexp(1.0, exponent);
  Eigen::RowVector3d weighted = Eigen::RowVector3d::Zero(), plain = Eigen::RowVector3d::Zero();
  double length = 0;
  for (size_t i = 0; i < loop.size(); ++i) {
    const Eigen::RowVector3d a = V.row(loop[i]) * to_unit, b = V.row(loop[(i + 1) % loop.size()]) * to_unit;
    const double l = (b - a).norm();
    weighted += 0.5 * l * (a + b);
    length += l;
    plain += a;
  }
  // All loop vertices at one point (zero length): fall back to the plain average.
  const Eigen::RowVector3d centre = length > 0 ? Eigen::RowVector3d(weighted / length)
                                               : Eigen::RowVector3d(plain / double(loop.size()));
  return centre * back;
}

}  // namespace

Result<FilledMesh> fill_holes(const TriMesh& mesh) {
  FilledMesh out;
  out.original_vertices = static_cast<int>(mesh.V.rows());
  out.original_faces = static_cast<int>(mesh.F.rows());
  const MeshCheck check = check_mesh(mesh);
  SPHEREKIT_RETURN_IF_ERROR(check_fillable(check));
  if (check.boundary_edges == 0) {
    out.mesh = mesh;
    return out;
  }

  const detail::MeshTopology topo = detail::build_topology(mesh);
  bool ok = false;
  const auto he_loops = detail::trace_boundary_loops(mesh, topo, &ok);
  if (!ok) return refuse("the boundary edges do not form closed loops");

  // A vertex visited twice by the loops is a pinched boundary vertex: filling both sides
  // would leave it non-manifold. Splitting it first (repair_pinched_vertices) fixes that.
  std::vector<char> on_loop(static_cast<size_t>(out.original_vertices), 0);
  for (const auto& hl : he_loops) {
    std::vector<int> loop;
    loop.reserve(hl.size());
    for (int h : hl) {
      const int v = detail::he_from(mesh, h);
      if (on_loop[v])
        return refuse("vertex " + std::to_string(v) +
                      " is on the boundary twice (boundary loops touch there); run `spherekit check --repair`");
      on_loop[v] = 1;
      loop.push_back(v);
    }
    out.loops.push_back(std::move(loop));
  }

  int fan_faces = 0;
  for (const auto& loop : out.loops) fan_faces += static_cast<int>(loop.size());
  out.holes = static_cast<int>(out.loops.size());
  out.mesh.V.resize(out.original_vertices + out.holes, 3);
  out.mesh.V.topRows(out.original_vertices) = mesh.V;
  out.mesh.F.resize(out.original_faces + fan_faces, 3);
  out.mesh.F.topRows(out.original_faces) = mesh.F;
  int f = out.original_faces;
  for (int i = 0; i < out.holes; ++i) {
    const auto& loop = out.loops[i];
    const int centre = out.original_vertices + i;
    out.mesh.V.row(centre) = loop_centre(mesh.V, loop);
    // loop[k] -> loop[k+1] is a half-edge of an original face, so the fan face must use
    // that edge the other way round to be oriented consistently with it.
    for (size_t k = 0; k < loop.size(); ++k) out.mesh.F.row(f++) << loop[(k + 1) % loop.size()], loop[k], centre;
  }
  return out;
}

}  // namespace spherekit
