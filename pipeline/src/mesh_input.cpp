// Mesh input with its check and verdict (mesh_input.h).
#include "spherekit/pipeline/mesh_input.h"

#include <cstddef>
#include <vector>

#include "spherekit/file_status.h"
#include "stopwatch.h"

namespace spherekit::pipeline {

Result<LoadedMesh> load_mesh(const std::string& path) {
  LoadedMesh out;
  out.path = path;
  Stopwatch read_time;
  auto mesh = formats::read_mesh(path, formats::ReadOptions{}, &out.info);
  if (!mesh.ok()) return with_file(mesh.status(), path);
  out.mesh = std::move(mesh).value();
  out.read_seconds = read_time.seconds();
  Stopwatch check_time;
  out.check = check_mesh(out.mesh);
  out.check_seconds = check_time.seconds();
  return out;
}

Result<LoadedMesh> load_mesh_checked(const std::string& path, bool allow_boundary, bool repair) {
  auto loaded = load_mesh(path);
  if (!loaded.ok()) return loaded.status();
  LoadedMesh& m = loaded.value();
  if (repair && m.check.nonmanifold_vertices > 0) {
    Stopwatch t;
    m.split_vertices = repair_pinched_vertices(m.mesh);
    m.check = check_mesh(m.mesh);
    m.check_seconds += t.seconds();
  }
  Status verdict = param_verdict(m, allow_boundary);
  if (!verdict.ok()) return verdict;
  return loaded;
}

MeshRepair repair_mesh(LoadedMesh& m) {
  Stopwatch t;
  MeshRepair r;
  std::vector<int> old_to_new;
  r.removed_unreferenced_vertices = remove_unreferenced_vertices(m.mesh, &old_to_new);
  for (std::size_t v = 0; v < old_to_new.size(); ++v)
    r.renumbered = r.renumbered || (old_to_new[v] >= 0 && old_to_new[v] != static_cast<int>(v));
  r.split_vertices = repair_pinched_vertices(m.mesh);
  m.split_vertices += r.split_vertices;
  m.check = check_mesh(m.mesh);
  m.check_seconds += t.seconds();
  return r;
}

Status param_verdict(const LoadedMesh& m, bool allow_boundary) {
  return with_file(require_param_accepts(m.mesh, m.check, allow_boundary), m.path);
}

}  // namespace spherekit::pipeline
