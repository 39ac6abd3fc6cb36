// Levels of detail of a collection on the template member's connectivity (see template_lods.h).
#include "spherekit/convert/template_lods.h"

#include <string>

#include "spherekit/correspondence.h"
#include "spherekit/geometry_image.h"

namespace spherekit::convert {
namespace {

// A laid template face is folded where its normal makes more than about 78 degrees with the
// normal of the member's face nearest its centroid.
constexpr double kFoldCos = 0.2;

// Template faces (not closing a hole) whose laid triangle on member m is folded.
int count_folded(const FoldCutMesh& cut, const RowMatXd& P, int m, const TriMesh& mesh) {
  const ClosestPointLocator near(mesh);
  const RowMat3i& F = cut.mesh.F;
  int folded = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (cut.hole_faces[static_cast<std::size_t>(f)]) continue;
    const Eigen::Vector3d a = P.row(F(f, 0)).segment<3>(3 * m).transpose();
    const Eigen::Vector3d b = P.row(F(f, 1)).segment<3>(3 * m).transpose();
    const Eigen::Vector3d c = P.row(F(f, 2)).segment<3>(3 * m).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;  // the cut's slivers: no orientation to check
    const SurfacePoint sp = near.closest((a + b + c) / 3);
    if (sp.face < 0) continue;
    const Eigen::Vector3d p0 = mesh.V.row(mesh.F(sp.face, 0)), p1 = mesh.V.row(mesh.F(sp.face, 1)),
                          p2 = mesh.V.row(mesh.F(sp.face, 2));
    const Eigen::Vector3d s = (p1 - p0).cross(p2 - p0);
    if (!(n.dot(s) > kFoldCos * n.norm() * s.norm())) ++folded;
  }
  return folded;
}

}  // namespace

Result<TemplateLayout> lay_template(const std::vector<TemplateLodMember>& members, int template_member) {
  const auto nm = static_cast<int>(members.size());
  if (nm < 1) return Status(ErrorCode::InvalidArgument, "template levels of detail: no member");
  if (template_member < 0 || template_member >= nm)
    return Status(ErrorCode::InvalidArgument, "template levels of detail: template member out of range");
  for (int m = 0; m < nm; ++m) {
    const TemplateLodMember& t = members[static_cast<std::size_t>(m)];
    if (!t.mesh || !t.sphere_map)
      return Status(ErrorCode::InvalidArgument, "template levels of detail: member " + std::to_string(m) + " has no mesh or map");
    if (t.sphere_map->rows() != t.mesh->V.rows())
      return Status(ErrorCode::InvalidInput, "template levels of detail: member " + std::to_string(m) + "'s map has " +
                                                 std::to_string(t.sphere_map->rows()) + " points for " +
                                                 std::to_string(t.mesh->V.rows()) + " vertices");
  }
  const TemplateLodMember& tm = members[static_cast<std::size_t>(template_member)];
  TemplateLayout out;
  SPHEREKIT_ASSIGN_OR_RETURN(out.cut, cut_along_octahedral_fold(*tm.mesh, *tm.sphere_map));
  const FoldCutMesh& cut = out.cut;
  const Eigen::Index nv = cut.mesh.V.rows();
  // Member m's copy of template vertex v (and of a hole's centre): its surface point at v's
  // sphere point. A vertex the fold cut made on a template edge stays on that edge as laid
  // on the member (at the same parameter between the member's copies of its ends), so that
  // the cut changes no member's surface and its vertices collapse again at no cost in every
  // member: level 0 is the template's own triangulation on every member, but for the fold's
  // ends and crossings, which stay (and fold vertices that can only collapse along the fold).
  out.positions.resize(nv, 3 * nm);
  RowMatXd& P = out.positions;
  out.folded_faces.assign(static_cast<std::size_t>(nm), 0);
  out.outside_vertices.assign(static_cast<std::size_t>(nm), 0);
  for (Eigen::Index f = 0; f < cut.mesh.F.rows(); ++f) out.faces += !cut.hole_faces[static_cast<std::size_t>(f)];
  const Eigen::Index first_edge_point = nv - static_cast<Eigen::Index>(cut.edge_points.size());
  for (int m = 0; m < nm; ++m) {
    if (m == template_member) {
      for (Eigen::Index v = 0; v < nv; ++v) P.row(v).segment<3>(3 * m) = cut.mesh.V.row(v);
      continue;
    }
    const TriMesh& mesh = *members[static_cast<std::size_t>(m)].mesh;
    const SphereLocator locator(mesh.F, *members[static_cast<std::size_t>(m)].sphere_map);
    for (Eigen::Index v = 0; v < nv; ++v) {
      if (v >= first_edge_point) {
        const FoldCutMesh::EdgePoint& e = cut.edge_points[static_cast<std::size_t>(v - first_edge_point)];
        P.row(v).segment<3>(3 * m) =
            P.row(e.a).segment<3>(3 * m) + e.t * (P.row(e.b).segment<3>(3 * m) - P.row(e.a).segment<3>(3 * m));
        continue;
      }
      const SphereLocation loc = locator.locate(cut.S.row(v).transpose());
      if (loc.face < 0)
        return Status(ErrorCode::InvalidInput,
                      "template levels of detail: member " + std::to_string(m) + "'s sphere map has no usable face");
      out.outside_vertices[static_cast<std::size_t>(m)] += !loc.inside;
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int c = 0; c < 3; ++c) x += loc.bary[c] * mesh.V.row(mesh.F(loc.face, c)).transpose();
      P.row(v).segment<3>(3 * m) = x.transpose();
    }
    out.folded_faces[static_cast<std::size_t>(m)] = count_folded(cut, P, m, mesh);
  }
  return out;
}

Result<std::vector<std::vector<GltfMesh>>> template_lod_meshes(const TemplateLayout& layout,
                                                              const OriginalLodOptions& options,
                                                              const ProgressFn& progress) {
  return fold_cut_lod_meshes(layout.cut, layout.positions, options, progress);
}

}  // namespace spherekit::convert
