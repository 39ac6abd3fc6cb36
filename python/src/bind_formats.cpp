// spherekit::formats in Python: mesh, sphere-map, landmark and sphere-point files. Writers are
// the library's (atomic, the command line's bytes); errors name the file.
#include "py_common.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/sphere_map.h"

namespace spherekit::py {

void bind_formats(pyb::module_& m) {
  m.def(
      "read_mesh",
      [](const std::string& path) {
        Mesh mesh;
        auto r = [&] {
          pyb::gil_scoped_release release;
          return formats::read_mesh(path);
        }();
        mesh.mesh = unwrap(std::move(r));
        mesh.source = path;
        return mesh;
      },
      pyb::arg("path"), "Reads OBJ, PLY, OFF, STL or glTF/GLB (as every subcommand does). Raises ParseError, IoError, ...");
  m.def(
      "write_mesh",
      [](const std::string& path, const Mesh& mesh, bool binary, int precision) {
        formats::WriteOptions o;
        o.binary = binary;
        o.precision = precision;
        check(formats::write_mesh(path, mesh.mesh, o));
      },
      pyb::arg("path"), pyb::arg("mesh"), pyb::kw_only(), pyb::arg("binary") = true, pyb::arg("precision") = 17,
      "Writes OBJ or PLY (by extension) atomically.");
  m.def(
      "read_sphere_map", [](const std::string& path, const Mesh& mesh) { return unwrap(formats::read_sphere_map(path, mesh.mesh)); },
      pyb::arg("path"), pyb::arg("mesh"), "Reads a *.sphere.obj written for `mesh` (same vertices and faces).");
  m.def(
      "write_sphere_map",
      [](const std::string& path, const Mesh& mesh, pyb::object map) {
        // A result (param, param_constrained, consistent().maps[i]) or a SphereMap.
        if (pyb::hasattr(map, "map") && !pyb::isinstance<SphereMap>(map)) map = map.attr("map");
        check(formats::write_sphere_map(path, mesh.mesh, map.cast<const SphereMap&>()));
      },
      pyb::arg("path"), pyb::arg("mesh"), pyb::arg("map"),
      "Writes a sphere map (the bytes `spherekit param` writes), atomically. `map`: a SphereMap or a result.");
  m.def(
      "read_landmarks",
      [](const std::string& path, int num_vertices) {
        std::vector<std::pair<std::string, int>> out;
        for (const Landmark& l : unwrap(formats::read_landmarks(path, num_vertices), path)) out.emplace_back(l.name, l.vertex);
        return out;
      },
      pyb::arg("path"), pyb::arg("num_vertices") = -1, "Reads a *.lm.txt file: [(name, vertex), ...] in file order.");
  m.def(
      "write_landmarks",
      [](const std::string& path, const std::vector<std::pair<std::string, int>>& landmarks) {
        std::vector<Landmark> l;
        for (const auto& [name, vertex] : landmarks) l.push_back({name, vertex});
        check(formats::write_landmarks(path, l));
      },
      pyb::arg("path"), pyb::arg("landmarks"));
  m.def(
      "read_sphere_points",
      [](const std::string& path, bool require_unit) {
        const std::vector<SpherePoint> pts = unwrap(formats::read_sphere_points(path, require_unit), path);
        std::vector<std::string> names;
        RowMat3d p(static_cast<Eigen::Index>(pts.size()), 3);
        for (std::size_t i = 0; i < pts.size(); ++i) {
          names.push_back(pts[i].name);
          p.row(static_cast<Eigen::Index>(i)) = pts[i].p.transpose();
        }
        return pyb::make_tuple(names, p);
      },
      pyb::arg("path"), pyb::arg("require_unit") = false,
      "Reads `name x y z` lines (e.g. a collection's features.txt): (names, k x 3 array).");
  m.def(
      "write_sphere_points",
      [](const std::string& path, const std::vector<std::string>& names, const pyb::array& points) {
        const RowMat3d p = to_rowmat3d(points, "points");
        if (static_cast<Eigen::Index>(names.size()) != p.rows())
          throw_status(Status(ErrorCode::InvalidArgument, "names and points differ in length"));
        std::vector<SpherePoint> pts;
        for (std::size_t i = 0; i < names.size(); ++i) pts.push_back({names[i], p.row(static_cast<Eigen::Index>(i)).transpose()});
        check(formats::write_sphere_points(path, pts));
      },
      pyb::arg("path"), pyb::arg("names"), pyb::arg("points"));
}

}  // namespace spherekit::py
