// spherekit::convert in Python: geometry-image EXR files, Draco glTF levels of detail and
// Catmull-Clark cages (the pieces `spherekit convert` writes).
#include "py_common.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/subd_cage.h"
#include "spherekit/geometry_image.h"

namespace spherekit::py {

void bind_convert(pyb::module_& m) {
  m.def(
      "write_geometry_image_exr",
      [](const std::string& path, const GeometryImage& image, const std::string& source_mesh, const std::string& sphere_map) {
        const Status s = [&] {
          pyb::gil_scoped_release release;
          return convert::write_geometry_image_exr(path, image, {source_mesh, sphere_map});
        }();
        check(s);
      },
      pyb::arg("path"), pyb::arg("image"), pyb::kw_only(), pyb::arg("source_mesh") = "", pyb::arg("sphere_map") = "",
      "Writes a geometry image as float EXR (as `spherekit convert`), atomically.");
  m.def(
      "read_geometry_image_exr",
      [](const std::string& path) {
        convert::GeometryImageFile f = unwrap(convert::read_geometry_image_exr(path));
        return pyb::make_tuple(std::move(f.image), f.attributes);
      },
      pyb::arg("path"), "Reads an EXR written by write_geometry_image_exr: (image, header attributes).");
  m.def(
      "write_gltf_lods",
      [](const std::string& prefix, const Mesh& mesh, const pyb::array& S, const GeometryImage& image, int levels,
         const std::string& name, std::optional<pyb::function> progress) {
        const RowMat3d s = to_rowmat3d(S, "S");
        GeometryImageOptions gio;
        gio.fit_positions = true;
        convert::GltfLodOptions o;
        o.levels = levels;
        o.name = name;
        o.provenance = {mesh.source, ""};
        o.drop_hole_faces = true;  // a single mesh's levels show its holes, as convert --lods
        const auto level_images = unwrap(convert::lod_geometry_images(mesh.mesh, s, image, levels, gio), mesh.source);
        const convert::GltfLods lods = run_stage(std::move(progress), mesh.source, [&](const ProgressFn& fn) {
          return convert::build_gltf_lods(level_images, o, fn);
        });
        const convert::GltfLodPaths paths = unwrap(convert::write_gltf_lods(prefix, lods));
        return pyb::make_tuple(paths.levels, paths.combined);
      },
      pyb::arg("prefix"), pyb::arg("mesh"), pyb::arg("S"), pyb::arg("image"), pyb::kw_only(), pyb::arg("levels") = 3,
      pyb::arg("name") = "mesh", pyb::arg("progress") = pyb::none(),
      "Draco glTF levels of detail of a geometry image (as `convert --lods`): PREFIX_lod0.glb ... and\n"
      "PREFIX_lods.glb (MSFT_lod); each level fitted at its own size. Returns (level paths, combined path).");
  m.def(
      "write_cage",
      [](const std::string& path, const Mesh& mesh, const pyb::array& S, int n, std::optional<pyb::function> progress) {
        const RowMat3d s = to_rowmat3d(S, "S");
        const convert::CageDomain domain = unwrap(convert::cube_cage_domain(n));
        const convert::CageLimit limit = unwrap(convert::CageLimit::create(domain));
        convert::SubdCage cage = run_stage(std::move(progress), mesh.source, [&](const ProgressFn& fn) {
          return convert::fit_subd_cage(mesh.mesh, s, limit, domain, {}, fn);
        });
        check(convert::write_cage_obj(path, cage, mesh.source.empty() ? std::string() : "fitted to " + mesh.source));
        return pyb::make_tuple(cage.points, cage.fit_rms);
      },
      pyb::arg("path"), pyb::arg("mesh"), pyb::arg("S"), pyb::kw_only(), pyb::arg("n") = 8, pyb::arg("progress") = pyb::none(),
      "Fits a Catmull-Clark cage (cube with n x n quads per face, OpenSubdiv limit surface; as `convert --cage n`)\n"
      "and writes it as OBJ quads. Returns (control points, fit RMS).");
}

}  // namespace spherekit::py
