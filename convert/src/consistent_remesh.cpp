// Consistent remeshes of collection members through their geometry images (see the header).
#include "spherekit/convert/consistent_remesh.h"

#include <string>

namespace spherekit::convert {

Result<ConsistentRemesh> consistent_remesh(const TriMesh& mesh, const RowMat3d& S, int size,
                                           const GeometryImageOptions& options) {
  ConsistentRemesh out;
  SPHEREKIT_ASSIGN_OR_RETURN(out.image, sample_geometry_image(mesh, S, size, options));
  out.mesh = geometry_image_mesh(out.image);
  if (out.image.texels_in_holes > 0) out.hole_faces = geometry_image_hole_faces(out.image);
  return out;
}

Result<std::vector<ConsistentRemesh>> consistent_remeshes(const std::vector<TriMesh>& meshes,
                                                          const std::vector<RowMat3d>& maps, int size,
                                                          const GeometryImageOptions& options,
                                                          const ProgressFn& progress) {
  if (meshes.size() != maps.size())
    return Status(ErrorCode::InvalidArgument, std::to_string(meshes.size()) + " meshes but " +
                                                  std::to_string(maps.size()) + " sphere maps");
  std::vector<ConsistentRemesh> out;
  out.reserve(meshes.size());
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    if (!report_progress(progress, "remesh", static_cast<int>(k), static_cast<double>(k) / static_cast<double>(meshes.size())))
      return Status(ErrorCode::Cancelled, "cancelled");
    auto r = consistent_remesh(meshes[k], maps[k], size, options);
    if (!r.ok()) return r.status().with_context("member " + std::to_string(k));
    out.push_back(std::move(r).value());
  }
  if (!report_progress(progress, "remesh", static_cast<int>(meshes.size()), 1.0))
    return Status(ErrorCode::Cancelled, "cancelled");
  return out;
}

}  // namespace spherekit::convert
