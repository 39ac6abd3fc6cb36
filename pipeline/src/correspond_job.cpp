// correspond_members() (correspond.h).
#include <filesystem>
#include <unordered_map>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/formats/text_formats.h"
#include "spherekit/pipeline/correspond.h"
#include "spherekit/pipeline/mesh_input.h"
#include "spherekit/pipeline/paths.h"

#include "spherekit/format_text.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline {
namespace {

using formats::Collection;
using formats::kCollectionManifest;

struct Mapped {
  LoadedMesh mesh;
  SphereMap map;
};

Result<Mapped> load_mapped_member(const Collection& c, const std::string& path) {
  const int i = formats::find_member(c, path);
  if (i < 0)
    return Status(ErrorCode::InvalidInput, path + ": not a member of the collection " + c.dir +
                                               " (add it with 'spherekit add')");
  SPHEREKIT_ASSIGN_OR_RETURN(LoadedMesh m, load_mesh(path));
  const formats::CollectionMember& e = c.manifest.members[static_cast<size_t>(i)];
  // The mesh must be the one that was mapped: say so when its vertex count shows it is not
  // (the map reader below could only report that two counts differ).
  if (e.vertices && *e.vertices != static_cast<long long>(m.mesh.V.rows()))
    return Status(ErrorCode::InvalidInput,
                  format_text("%s: has %lld vertices, but member '%s' of %s was mapped with %lld (not the mesh of "
                            "the collection?)",
                            path.c_str(), static_cast<long long>(m.mesh.V.rows()), e.name.c_str(),
                            (fs::path(c.dir) / kCollectionManifest).string().c_str(), *e.vertices));
  const std::string map_path = (fs::path(c.dir) / e.map).string();
  std::error_code ec;
  if (!fs::is_regular_file(map_path, ec))
    return Status(ErrorCode::IoError, map_path + ": missing (the map of member '" + e.name +
                                          "' in " + (fs::path(c.dir) / kCollectionManifest).string() + ")");
  auto map = formats::read_sphere_map(map_path, m.mesh);
  if (!map.ok()) return map.status();
  Mapped out;
  out.mesh = std::move(m);
  out.map = std::move(map).value();
  return out;
}

}  // namespace

Json to_json(const CorrespondenceError& e) {
  return Json{{"pairs", e.pairs},          {"mean", e.mean},
              {"median", e.median},        {"p90", e.p90},
              {"max", e.max},              {"under_0.025", e.under_0025},
              {"under_0.05", e.under_005}, {"under_0.1", e.under_01}};
}

Result<CorrespondResult> correspond_members(const CorrespondJob& a) {
  CorrespondResult out;
  if (a.points.empty() && a.corr.empty() && a.gt.empty())
    return Status(ErrorCode::InvalidArgument, "nothing to do: give --points, --corr or --gt");
  if (Status s = require_output_folders({a.output}); !s.ok()) return s;
  auto col = formats::read_collection(a.collection);
  if (!col.ok()) return col.status();
  auto A = load_mapped_member(col.value(), a.a);
  if (!A.ok()) return A.status();
  auto B = load_mapped_member(col.value(), a.b);
  if (!B.ok()) return B.status();
  const TriMesh& ma = A->mesh.mesh;
  const TriMesh& mb = B->mesh.mesh;

  if (!a.points.empty()) {
    auto pts = formats::read_points(a.points);
    if (!pts.ok()) return pts.status();
    const ClosestPointLocator closest(ma);
    std::vector<SurfacePoint> on_a;
    for (const auto& p : pts.value()) on_a.push_back(closest.closest(p));
    auto moved = transfer_points(ma, A->map.S, on_a, mb, B->map.S);
    if (!moved.ok()) return moved.status();
    for (const TransferredPoint& t : moved.value()) {
      const Eigen::Vector3d x = surface_position(mb, t.point);
      out.points_text += format_text("%.9g %.9g %.9g\n", x.x(), x.y(), x.z());
      out.points_in_holes += t.in_hole;
    }
    if (!a.output.empty()) SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(a.output, out.points_text));
  }

  if (!a.corr.empty() || !a.gt.empty()) {
    const bool corr = !a.corr.empty();
    const auto& files = corr ? a.corr : a.gt;
    auto la = formats::read_vertex_indices(files[0]);
    if (!la.ok()) return la.status();
    auto lb = formats::read_vertex_indices(files[1]);
    if (!lb.ok()) return lb.status();
    std::vector<std::pair<int, int>> pairs;
    if (corr) {
      if (la->size() != lb->size())
        return Status(ErrorCode::InvalidInput, files[0] + " and " + files[1] + " differ in length");
      for (size_t i = 0; i < la->size(); ++i) pairs.push_back({(*la)[i], (*lb)[i]});
    } else {
      // Template ids: vertex i of A pairs with the first vertex of B with the same id.
      std::unordered_map<int, int> first;
      for (size_t j = 0; j < lb->size(); ++j) first.emplace((*lb)[j], static_cast<int>(j));
      for (size_t i = 0; i < la->size(); ++i)
        if (auto it = first.find((*la)[i]); (*la)[i] >= 0 && it != first.end()) pairs.push_back({static_cast<int>(i), it->second});
    }
    for (const auto& [x, y] : pairs)
      if (x < 0 || x >= ma.V.rows() || y < 0 || y >= mb.V.rows())
        return Status(ErrorCode::InvalidInput, format_text("%s: vertex pair (%d, %d) out of range", files[0].c_str(), x, y));
    if (a.samples > 0 && static_cast<int>(pairs.size()) > a.samples) {
      // Evenly spaced subset: deterministic.
      std::vector<std::pair<int, int>> sub;
      for (int i = 0; i < a.samples; ++i) sub.push_back(pairs[static_cast<size_t>(i) * pairs.size() / a.samples]);
      pairs.swap(sub);
    }
    std::vector<SurfacePoint> on_a;
    std::vector<int> truth;
    for (const auto& [x, y] : pairs) {
      on_a.push_back(vertex_surface_point(ma, x));
      truth.push_back(y);
    }
    auto moved = transfer_points(ma, A->map.S, on_a, mb, B->map.S);
    if (!moved.ok()) return moved.status();
    std::vector<SurfacePoint> predicted;
    for (const auto& t : moved.value()) predicted.push_back(t.point);
    auto err = correspondence_error(mb, predicted, truth);
    if (!err.ok()) return err.status();
    out.error = err.value();
  }
  return out;
}

}  // namespace spherekit::pipeline
