// The malformed-input corpus (tests/data/bad/, table in its README.md) run through the
// `spherekit` program: every case fails with the documented exit code and exactly one stderr
// line `spherekit: error: FILE...: problem` that names the file and the problem, creates no
// output file (nor a temporary one) and leaves an existing output file untouched. The legal
// edge cases (coincident vertices, a zero-area face, a sphere map at radius 2) succeed.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "compressed_glb.h"
#include "test_meshes.h"
#include "test_paths.h"
#include "test_files.h"
#include "cli_shorthands.h"

namespace fs = std::filesystem;

namespace {

using spherekit::test::files_in;
using spherekit::test::quote;
using spherekit::test::require_failure;
using spherekit::test::write_text;

using spherekit::test::CliRun;
using spherekit::test::slurp;

CliRun run_cli(const std::string& args, const std::string& capture_dir) {
  return spherekit::test::run_cli(SPHEREKIT_EXE, args, capture_dir);
}

/// A corpus file.
std::string bad(const std::string& name) { return std::string(SPHEREKIT_SOURCE_DIR) + "/tests/data/bad/" + name; }

/// An output folder holding one existing file per output kind, each with known contents: a
/// failing command must neither replace them nor create anything beside them.
struct OutputDir {
  std::string dir;
  static constexpr const char* kSentinel = "existing output, must survive\n";
  static const std::vector<std::string>& existing() {
    static const std::vector<std::string> names = {"existing.exr", "existing.json", "existing.obj",
                                                   "existing.sphere.obj"};
    return names;
  }

  explicit OutputDir(const std::string& test_dir) : dir(test_dir + "/out") {
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const std::string& name : existing()) write_text(dir + "/" + name, kSentinel);
  }
  std::string path(const std::string& name) const { return dir + "/" + name; }

  /// Nothing created (no output, no temporary file) and nothing overwritten.
  void require_untouched() const {
    CHECK(files_in(dir) == existing());
    for (const std::string& name : existing()) {
      INFO("output file " << name);
      CHECK(slurp(path(name)) == kSentinel);
    }
  }
};

/// A mesh file every command must refuse.
struct MeshCase {
  const char* file;
  int exit_code;
  const char* problem;  // a phrase the message must contain
};

/// check, param and convert on a bad mesh file: same exit code, same one-line message, no output.
void run_mesh_file(const std::string& mesh, int exit_code, const std::string& problem, const std::string& dir) {
  const MeshCase c{mesh.c_str(), exit_code, problem.c_str()};
  INFO("case: " << mesh);
  const OutputDir out(dir);

  require_failure(run_cli("check " + quote(mesh), dir), c.exit_code, mesh, c.problem);
  require_failure(run_cli("check --json " + quote(mesh), dir), c.exit_code, mesh, c.problem);

  require_failure(run_cli("param " + quote(mesh) + " -o " + quote(out.path("new.sphere.obj")) + " --report " +
                              quote(out.path("new.json")) + " --quiet",
                          dir),
                  c.exit_code, mesh, c.problem);
  out.require_untouched();
  require_failure(run_cli("param " + quote(mesh) + " -o " + quote(out.path("existing.sphere.obj")) + " --report " +
                              quote(out.path("existing.json")) + " --quiet",
                          dir),
                  c.exit_code, mesh, c.problem);
  out.require_untouched();

  // The map is the octahedron's; every case fails on the mesh before the map matters.
  require_failure(run_cli("convert " + quote(mesh) + " " + quote(bad("octahedron.sphere.obj")) + " -o " +
                              quote(out.path("existing.exr")) + " --remesh " + quote(out.path("new.obj")) +
                              " --report " + quote(out.path("new.json")) + " --size 17 --psnr-samples 100 --quiet",
                          dir),
                  c.exit_code, mesh, c.problem);
  out.require_untouched();
}

/// run_mesh_file on a corpus file.
void run_mesh_case(const MeshCase& c, const std::string& dir) { run_mesh_file(bad(c.file), c.exit_code, c.problem, dir); }

}  // namespace

TEST_CASE("bad input: the reference files of the corpus are valid", "[cli]") {
  // Most cases are one defect away from these: they must pass, so each case fails for its
  // own defect.
  const std::string dir = spherekit::test::temp_dir("bad_input_reference");
  for (const char* file : {"octahedron.obj", "octahedron.off", "octahedron_binary.ply", "octahedron.stl",
                           "octahedron.gltf", "octahedron.glb"}) {
    INFO("file: " << file);
    const CliRun r = run_cli("check " + quote(bad(file)), dir);
    CHECK(r.exit_code == 0);
    CHECK(r.out.find("vertices: 0 unreferenced") != std::string::npos);
    CHECK(r.out.find("6 vertices, 8 faces") != std::string::npos);
  }
  const CliRun lm =
      run_cli("check " + quote(bad("octahedron.obj")) + " --landmarks " + quote(bad("octahedron.lm.txt")), dir);
  CHECK(lm.exit_code == 0);
  CHECK(lm.out.find("landmarks: 3 in") != std::string::npos);
  const CliRun ev = run_cli("eval " + quote(bad("octahedron.obj")) + " " + quote(bad("octahedron.sphere.obj")) +
                                " --targets " + quote(bad("octahedron.targets.txt")) + " --json",
                            dir);
  CHECK(ev.exit_code == 0);
  CHECK(ev.out.find("\"flipped_exact\":0") != std::string::npos);
  CHECK(ev.out.find("\"feature_err_deg\":0.0") != std::string::npos);
}

TEST_CASE("bad input: malformed mesh files", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_readers");
  static const MeshCase kCases[] = {
      // OBJ
      {"empty.obj", 3, "file is empty"},
      {"obj_truncated.obj", 3, ":5: vertex has fewer than 3 coordinates"},
      {"obj_index_out_of_range.obj", 3, ":14: face index 99 out of range (6 vertices)"},
      {"obj_negative_index_out_of_range.obj", 3, ":14: face index -9 out of range"},
      {"obj_zero_index.obj", 3, ":7: face index 0 out of range"},
      {"obj_nan_coordinate.obj", 3, "vertex 2 has a non-finite coordinate"},
      {"obj_inf_coordinate.obj", 3, "vertex 4 has a non-finite coordinate"},
      {"obj_overflow_coordinate.obj", 3, "vertex 0 has a non-finite coordinate"},
      {"obj_huge_coordinates.obj", 3, "coordinates reach 1e+300, beyond the supported"},
      {"obj_bad_number.obj", 3, ":2: bad number 'x'"},
      {"obj_binary_garbage.obj", 3, "not a text file (NUL byte"},
      {"no_faces.obj", 3, "no faces"},
      {"unsupported_extension.xyz", 3, "unsupported mesh format '.xyz'"},
      // PLY
      {"empty.ply", 3, "file is empty"},
      {"ply_ascii_truncated.ply", 3, "ascii PLY ends after 5 of 8 faces"},
      {"ply_ascii_vertex_count_too_high.ply", 3, ":17: vertex 6 does not end its line"},
      {"ply_ascii_vertex_count_too_low.ply", 3, ":15: face 0 does not end its line"},
      {"ply_ascii_face_count_too_low.ply", 3, "data after the last element (wrong counts in header?)"},
      {"ply_negative_index.ply", 3, "face 7 index -1 out of range (6 vertices)"},
      {"ply_inf_coordinate.ply", 3, "vertex 1 has a non-finite coordinate"},
      {"ply_no_end_header.ply", 3, ":10: PLY header has no end_header"},
      {"ply_missing_z.ply", 3, "vertex element has no 'z' property"},
      {"ply_binary_le_truncated.ply", 3, "binary PLY ends after 7 of 8 faces"},
      {"ply_binary_be_truncated.ply", 3, "binary PLY ends after 4 of 6 vertices"},
      {"ply_binary_huge_count.ply", 3, "of 4000000000 vertices"},
      {"ply_binary_face_count_too_high.ply", 3, "binary PLY ends after 8 of 9 faces"},
      {"ply_binary_nan.ply", 3, "vertex 3 has a non-finite coordinate"},
      {"ply_binary_bad_list_length.ply", 3, "binary PLY ends after 7 of 8 faces"},
      // OFF
      {"off_vertex_count_too_high.off", 3, "OFF ends after 7 of 8 faces (truncated, or wrong counts"},
      {"off_face_count_too_low.off", 3, ":16: data after the last face (wrong counts in header?)"},
      {"off_truncated.off", 3, ":16: face lists 3 corners but has only 2 indices"},
      {"off_index_out_of_range.off", 3, "face index 6 out of range (6 vertices)"},
      {"off_negative_index.off", 3, "face index -3 out of range"},
      {"off_overflow_coordinate.off", 3, "vertex 5 has a non-finite coordinate"},
      {"off_negative_count.off", 3, ":2: bad counts line"},
      // STL
      {"stl_ascii_truncated.stl", 3, "ascii STL ends inside facet 1"},
      {"stl_ascii_nan.stl", 3, "non-finite coordinate"},
      {"stl_binary_truncated.stl", 3, "binary STL ends after 5 of 8 triangles"},
      {"stl_binary_nan.stl", 3, "non-finite coordinate"},
      {"stl_binary_no_triangles.stl", 3, "no faces"},
      // glTF / GLB. A missing buffer file is an I/O error (4), like any file that cannot be opened.
      {"gltf_missing_buffer_file.gltf", 4, "buffer 0: uri 'gltf_missing_buffer.bin': cannot open (No such file"},
      {"gltf_missing_buffer_entry.gltf", 3, "refers to missing buffer 1"},
      {"gltf_buffer_device.gltf", 3, "buffer 0: uri '/dev/zero' is not a regular file"},
      // Fuzzing finding (fuzz_gltf): the uri went into the message unquoted, newline and all.
      {"gltf_buffer_uri_newline.gltf", 4, "buffer 0: uri 'missing?buffer.bin': cannot open"},
      {"gltf_buffer_too_short.gltf", 3, "buffer 0 has 120 bytes, byteLength says 4096"},
      {"gltf_index_out_of_range.gltf", 3, "index 6 out of range (6 vertices)"},
      {"gltf_invalid_json.gltf", 3, "invalid JSON"},
      {"glb_truncated.glb", 3, "GLB is truncated"},
      {"glb_bad_magic.glb", 3, "not a GLB file (bad magic)"},
  };
  for (const MeshCase& c : kCases) run_mesh_case(c, dir);
}

TEST_CASE("bad input: meshes param does not accept", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_topology");
  static const MeshCase kCases[] = {
      {"duplicate_vertex_unreferenced.obj", 3, "vertex 6 is used by no face"},
      {"degenerate_face.obj", 3, "face 0 repeats a vertex"},
      {"duplicate_faces.obj", 3, "face 8 has the same vertices as face 0"},
      {"nonmanifold_edge.obj", 3, "edge (0,2) is shared by 3 faces"},
      {"pinched_vertex.obj", 3, "vertex 0 is non-manifold"},
      {"two_components.obj", 3, "2 connected components"},
      {"genus1_torus.obj", 3, "genus 1"},
      {"genus2.obj", 3, "genus 2"},
      {"inconsistent_orientation.obj", 3, "inconsistently oriented"},
  };
  for (const MeshCase& c : kCases) run_mesh_case(c, dir);

  // --repair writes the split mesh whatever the verdict (documented), but never for a file
  // that cannot be read.
  const OutputDir out(dir);
  require_failure(run_cli("check " + quote(bad("ply_binary_le_truncated.ply")) + " --repair -o " +
                              quote(out.path("existing.obj")),
                          dir),
                  3, "ply_binary_le_truncated.ply", "binary PLY ends after");
  out.require_untouched();
  const CliRun repaired = run_cli("check --json " + quote(bad("pinched_vertex.obj")) + " --repair -o " +
                                      quote(out.path("repaired.obj")),
                                  dir);
  CHECK(repaired.exit_code == 3);  // split into its two tetrahedra: two components
  CHECK(repaired.out.find("\"split_vertices\": 1") != std::string::npos);
  CHECK(fs::exists(out.path("repaired.obj")));
}

TEST_CASE("bad input: legal edge cases succeed", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_legal");
  const OutputDir out(dir);
  // Coincident positions are geometry, not topology; a zero-area face is valid topology.
  for (const char* file : {"duplicate_vertices_coincident.obj", "zero_area_face.obj"}) {
    INFO("case: " << file);
    const CliRun c = run_cli("check --json " + quote(bad(file)), dir);
    CHECK(c.exit_code == 0);
    CHECK(c.out.find("\"genus0_ok\": true") != std::string::npos);
    const std::string sphere = out.path(fs::path(file).stem().string() + ".sphere.obj");
    const CliRun p = run_cli("param " + quote(bad(file)) + " -o " + quote(sphere) + " --quiet", dir);
    INFO("stderr: " << p.err);
    CHECK(p.exit_code == 0);
    CHECK(fs::exists(sphere));
    const CliRun e = run_cli("eval --json " + quote(bad(file)) + " " + quote(sphere), dir);
    CHECK(e.exit_code == 0);
    CHECK(e.out.find("\"flipped_exact\":0") != std::string::npos);
  }
  CHECK(run_cli("check --json " + quote(bad("zero_area_face.obj")), dir).out.find("\"zero_area_faces\": 1") !=
        std::string::npos);
  // Sphere-map points at radius 2 are normalised on reading (read_sphere_map's contract).
  const CliRun r = run_cli("convert " + quote(bad("octahedron.obj")) + " " +
                               quote(bad("sphere_map_radius2.sphere.obj")) + " -o " + quote(out.path("radius2.exr")) +
                               " --size 17 --psnr-samples 100 --quiet",
                           dir);
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 0);
  CHECK(fs::exists(out.path("radius2.exr")));

  // Fuzzing finding (fuzz_sphere_points, same normalisation in read_sphere_map): points at
  // radius 1e303 or 1e-320 normalise exactly for convert; eval, which must see the radius as
  // written, refuses them instead of reporting NaN measures as a result.
  for (const char* file : {"sphere_map_huge.sphere.obj", "sphere_map_subnormal.sphere.obj"}) {
    INFO("case: " << file);
    const std::string exr = out.path(fs::path(file).stem().stem().string() + ".exr");
    const CliRun c = run_cli("convert " + quote(bad("octahedron.obj")) + " " + quote(bad(file)) + " -o " + quote(exr) +
                                 " --size 17 --psnr-samples 100 --quiet",
                             dir);
    INFO("stderr: " << c.err);
    CHECK(c.exit_code == 0);
    CHECK(fs::exists(exr));
    require_failure(run_cli("eval --json " + quote(bad("octahedron.obj")) + " " + quote(bad(file)), dir), 3, file,
                    "from the origin, outside the 1e-50..1e+50 eval can measure");
  }
}

TEST_CASE("bad input: landmark files", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_landmarks");
  struct Case {
    const char* file;
    int exit_code;
    const char* problem;
  };
  static const Case kCases[] = {
      {"landmarks_missing_vertex.lm.txt", 3, ":3: vertex index 99 out of range (6 vertices)"},
      {"landmarks_duplicate_name.lm.txt", 3, ":3: duplicate landmark name 'nose' (first on line 1)"},
      {"landmarks_duplicate_vertex.lm.txt", 3, ":2: landmark 'chin' uses vertex 4, already used by 'nose'"},
      {"landmarks_negative_index.lm.txt", 3, ":2: negative vertex index -1"},
      {"landmarks_bad_line.lm.txt", 3, ":2: expected 'name vertex_index', got 3 fields"},
      {"landmarks_missing_file.lm.txt", 4, "cannot open"},
  };
  for (const Case& c : kCases) {
    INFO("case: " << c.file);
    const std::string lm = bad(c.file);
    require_failure(run_cli("check " + quote(bad("octahedron.obj")) + " --landmarks " + quote(lm), dir), c.exit_code,
                    lm, c.problem);
    const CliRun j = run_cli("check --json " + quote(bad("octahedron.obj")) + " --landmarks " + quote(lm), dir);
    require_failure(j, c.exit_code, lm, c.problem);
    CHECK(j.out.find("\"landmarks\"") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(bad("landmarks_missing_file.lm.txt")));
}

TEST_CASE("bad input: eval targets (sphere points)", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_targets");
  struct Case {
    const char* file;
    const char* problem;
  };
  static const Case kCases[] = {
      {"targets_not_unit.txt", ":3: target 'tail' has length 2, not 1"},
      {"targets_missing_vertex.txt", ":2: vertex index 6 out of range (6 vertices)"},
      {"targets_nan.txt", ":2: target 'tail' is not finite"},
      {"targets_duplicate_name.txt", ":2: duplicate target name 'nose'"},
      {"targets_bad_line.txt", ":2: expected 'name vertex_index x y z', got 4 fields"},
      // Fuzzing finding (fuzz_sphere_points): |p|^2 overflowed, the point became (0, 0, 0).
      {"targets_huge.txt", ":3: target 'tail' has length 1e+303, not 1"},
  };
  for (const Case& c : kCases) {
    INFO("case: " << c.file);
    const std::string t = bad(c.file);
    require_failure(run_cli("eval " + quote(bad("octahedron.obj")) + " " + quote(bad("octahedron.sphere.obj")) +
                                " --targets " + quote(t) + " --json",
                            dir),
                    3, t, c.problem);
  }
}

TEST_CASE("bad input: sphere maps", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_sphere_maps");
  const OutputDir out(dir);
  const std::string mesh = bad("octahedron.obj");
  struct Case {
    const char* file;
    const char* problem;   // convert's message
    bool eval_fails;       // eval measures any map that has the mesh's vertex count
    const char* eval_problem;
  };
  static const Case kCases[] = {
      {"sphere_map_wrong_count.sphere.obj", "has 5 vertices, mesh has 6", true, "sphere map has 5 vertices"},
      {"sphere_map_nan.sphere.obj", "vertex 2 has a non-finite coordinate", true, "vertex 2 has a non-finite"},
      {"sphere_map_zero_point.sphere.obj", "point 3 is zero (not on the sphere)", true, "vertex 3 is zero"},
      {"sphere_map_flipped.sphere.obj", "(8 of 8 faces flipped or degenerate on the sphere); nothing written", false,
       ""},
      {"sphere_map_future_version.sphere.obj", ":1: sphere map format v99 is newer", false, ""},
      {"sphere_map_other_faces.sphere.obj", "face 2 differs from the mesh's (a map of another mesh)", false, ""},
  };
  for (const Case& c : kCases) {
    INFO("case: " << c.file);
    const std::string sphere = bad(c.file);
    require_failure(run_cli("convert " + quote(mesh) + " " + quote(sphere) + " -o " + quote(out.path("existing.exr")) +
                                " --remesh " + quote(out.path("new.obj")) + " --report " + quote(out.path("new.json")) +
                                " --size 17 --psnr-samples 100 --quiet",
                            dir),
                    3, sphere, c.problem);
    out.require_untouched();
    const CliRun e = run_cli("eval --json " + quote(mesh) + " " + quote(sphere), dir);
    if (c.eval_fails) {
      require_failure(e, 3, sphere, c.eval_problem);
    } else {
      CHECK(e.exit_code == 0);  // a folded map is measured, not refused: eval reports the flips
    }
  }
  // The folded map's flips are what eval reports.
  CHECK(run_cli("eval --json " + quote(mesh) + " " + quote(bad("sphere_map_flipped.sphere.obj")), dir)
            .out.find("\"flipped_exact\":8") != std::string::npos);
}

TEST_CASE("bad input: output paths and commands without mesh input", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_outputs");
  const OutputDir out(dir);
  const std::string mesh = bad("octahedron.obj"), sphere = bad("octahedron.sphere.obj");
  const std::string missing = dir + "/no_such_folder";

  // param into a folder that does not exist: an I/O error, nothing written anywhere.
  require_failure(run_cli("param " + quote(mesh) + " -o " + quote(missing + "/x.sphere.obj") + " --quiet", dir), 4,
                  "x.sphere.obj", "folder '");
  CHECK_FALSE(fs::exists(missing));

  // convert checks every output folder before writing: a bad --report path must not leave
  // the image behind.
  require_failure(run_cli("convert " + quote(mesh) + " " + quote(sphere) + " -o " + quote(out.path("new.exr")) +
                              " --report " + quote(missing + "/r.json") + " --size 17 --psnr-samples 100 --quiet",
                          dir),
                  4, "r.json", "does not exist");
  out.require_untouched();
  require_failure(run_cli("convert " + quote(mesh) + " " + quote(sphere) + " -o " + quote(out.path("new.exr")) +
                              " --remesh " + quote(missing + "/m.obj") + " --size 17 --psnr-samples 100 --quiet",
                          dir),
                  4, "m.obj", "does not exist");
  out.require_untouched();

  // samples into a path that is a file.
  require_failure(run_cli("samples -o " + quote(out.path("existing.obj")) + " --members 1 --vertices 100", dir), 4,
                  "existing.obj", "cannot create folder");
  out.require_untouched();

  // run reports a bad mesh, writes no map for it and exits 3.
  const std::string run_out = dir + "/run";
  const CliRun r = run_cli("run " + quote(bad("empty.obj")) + " -o " + quote(run_out), dir);
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("empty.obj: file is empty") != std::string::npos);
  CHECK_FALSE(fs::exists(run_out + "/empty.sphere.obj"));
  CHECK(slurp(run_out + "/report.json").find("file is empty") != std::string::npos);
}

TEST_CASE("bad input: large generated files fail fast", "[cli]") {
  // Too big to commit: a 300k-vertex OBJ whose very last face has an index out of range, and
  // the same data as binary PLY whose header claims one vertex more than it holds.
  const std::string dir = spherekit::test::temp_dir("bad_input_large");
  const OutputDir out(dir);
  const int n = 300000;
  std::string obj;
  obj.reserve(static_cast<std::size_t>(n) * 40);
  char line[96];
  for (int i = 0; i < n; ++i) {
    std::snprintf(line, sizeof line, "v %d %d %d\n", i % 97, (i / 97) % 89, i / (97 * 89));
    obj += line;
  }
  for (int i = 0; i + 2 < n; i += 3) {
    std::snprintf(line, sizeof line, "f %d %d %d\n", i + 1, i + 2, i + 3);
    obj += line;
  }
  obj += "f 1 2 " + std::to_string(n + 1) + "\n";
  const std::string big_obj = dir + "/large_index_out_of_range.obj";
  write_text(big_obj, obj);
  const std::string problem =
      "face index " + std::to_string(n + 1) + " out of range (" + std::to_string(n) + " vertices)";
  require_failure(run_cli("check " + quote(big_obj), dir), 3, big_obj, problem);
  require_failure(
      run_cli("param " + quote(big_obj) + " -o " + quote(out.path("existing.sphere.obj")) + " --quiet", dir), 3,
      big_obj, problem);
  out.require_untouched();

  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(n + 1) +
                    "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (int i = 0; i < n; ++i) {
    const float xyz[3] = {static_cast<float>(i), 0.f, 1.f};
    ply.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  }
  const std::string big_ply = dir + "/large_vertex_count_too_high.ply";
  write_text(big_ply, ply);
  require_failure(run_cli("check " + quote(big_ply), dir), 3, big_ply,
                  "binary PLY ends after " + std::to_string(n) + " of " + std::to_string(n + 1) + " vertices");
}

TEST_CASE("bad input: corrupt compressed glTF", "[cli]") {
  // Generated here from good files: a Draco .glb as `convert --lods` writes it, and a meshopt
  // .glb as gltfpack writes it (compressed_glb.h). Both good ones are read.
  const std::string dir = spherekit::test::temp_dir("bad_input_compressed_gltf");
  const std::string oct = dir + "/oct.exr";
  const CliRun made = run_cli("convert " + quote(bad("octahedron.obj")) + " " + quote(bad("octahedron.sphere.obj")) +
                                  " -o " + quote(oct) + " --size 17 --lods 1 --psnr-samples 100 --quiet",
                              dir);
  INFO("stderr: " << made.err);
  REQUIRE(made.exit_code == 0);
  const std::string draco_glb = dir + "/oct_lod0.glb";
  REQUIRE(fs::exists(draco_glb));
  const std::string meshopt_glb = dir + "/blob_meshopt.glb";
  write_text(meshopt_glb, spherekit::test::meshopt_glb(spherekit::test::random_blob(2, 5),
                                                       spherekit::test::MeshoptGlb::QuantizedTriangles));
  for (const std::string& good : {draco_glb, meshopt_glb}) {
    const CliRun c = run_cli("check " + quote(good), dir);
    INFO("stderr: " << c.err);
    CHECK(c.exit_code == 0);
  }

  const spherekit::test::GlbParts draco = spherekit::test::glb_parts(slurp(draco_glb));
  const spherekit::test::GlbParts meshopt = spherekit::test::glb_parts(slurp(meshopt_glb));
  const nlohmann::json& prim = draco.json["meshes"][0]["primitives"][0];
  const int view = prim["extensions"]["KHR_draco_mesh_compression"]["bufferView"].get<int>();
  const std::string ext = "EXT_meshopt_compression";
  struct Case {
    std::string file;
    const spherekit::test::GlbParts* from;
    std::function<void(spherekit::test::GlbParts&)> spoil;
    std::string problem;
  };
  const std::vector<Case> cases = {
      {"draco_truncated.glb", &draco,
       [&](spherekit::test::GlbParts& g) {
         auto& bv = g.json["bufferViews"][view];
         bv["byteLength"] = bv["byteLength"].get<std::size_t>() / 2;
       },
       "KHR_draco_mesh_compression (bufferView " + std::to_string(view) + "): Draco data is corrupt or truncated"},
      {"draco_wrong_count.glb", &draco,
       [&](spherekit::test::GlbParts& g) {
         const int acc = prim["attributes"]["POSITION"].get<int>();
         g.json["accessors"][acc]["count"] = g.json["accessors"][acc]["count"].get<int>() + 1;
       },
       "POSITION accessor count"},
      {"meshopt_bad_header.glb", &meshopt,
       [&](spherekit::test::GlbParts& g) {
         g.bin[g.json["bufferViews"][0]["extensions"][ext]["byteOffset"].get<std::size_t>()] = 0x13;
       },
       "bufferView 0 EXT_meshopt_compression: meshopt data is corrupt"},
      {"meshopt_wrong_count.glb", &meshopt,
       [&](spherekit::test::GlbParts& g) { g.json["bufferViews"][0]["extensions"][ext]["count"] = 4000000000ull; }, 
       "cannot come from"},
  };
  for (const Case& c : cases) {
    spherekit::test::GlbParts g = *c.from;
    c.spoil(g);
    const std::string path = dir + "/" + c.file;
    write_text(path, spherekit::test::glb_bytes(g));
    run_mesh_file(path, 3, c.problem, dir);
  }
}

TEST_CASE("bad input: unreferenced vertices are refused with a hint and dropped by check --repair", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_unreferenced");
  const std::string mesh = bad("duplicate_vertex_unreferenced.obj");
  require_failure(run_cli("check " + quote(mesh), dir), 3, mesh, "--repair -o OUT");
  const OutputDir out(dir);
  const CliRun r = run_cli("check --json " + quote(mesh) + " --repair -o " + quote(out.path("fixed.obj")), dir);
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 0);  // the repaired mesh is accepted
  CHECK(r.out.find("\"removed_unreferenced_vertices\": 1") != std::string::npos);
  CHECK(r.out.find("\"unreferenced_vertices\": 0") != std::string::npos);
  // The unused vertex is the last one: no other vertex changes its number.
  CHECK(r.out.find("\"renumbered\": false") != std::string::npos);
  const CliRun text = run_cli("check " + quote(mesh) + " --repair -o " + quote(out.path("fixed2.obj")), dir);
  CHECK(text.out.find("removed 1 unreferenced vertex") != std::string::npos);
  CHECK(text.out.find("need remapping") == std::string::npos);
  // An unused vertex first: every other vertex moves down by one, which the repair says.
  const std::string first = dir + "/unused_first.obj";
  write_text(first, "v 7 7 7\nv 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
                    "f 2 4 6\nf 4 3 6\nf 3 5 6\nf 5 2 6\nf 4 2 7\nf 3 4 7\nf 5 3 7\nf 2 5 7\n");
  require_failure(run_cli("check " + quote(first), dir), 3, first, "vertex 0 is used by no face");
  const CliRun moved = run_cli("check " + quote(first) + " --repair -o " + quote(out.path("fixed3.obj")), dir);
  CHECK(moved.exit_code == 0);
  CHECK(moved.out.find("landmark files of the input need remapping") != std::string::npos);
  CHECK(slurp(out.path("fixed3.obj")).find("v 7 7 7") == std::string::npos);
  const CliRun again = run_cli("check " + quote(out.path("fixed.obj")), dir);
  CHECK(again.exit_code == 0);
  CHECK(again.out.find("7 vertices") == std::string::npos);
  CHECK(again.out.find("6 vertices") != std::string::npos);
  const std::string sphere = out.path("fixed.sphere.obj");
  const CliRun p = run_cli("param " + quote(out.path("fixed.obj")) + " -o " + quote(sphere) + " --quiet", dir);
  INFO("stderr: " << p.err);
  CHECK(p.exit_code == 0);
  const CliRun e = run_cli("eval --json " + quote(out.path("fixed.obj")) + " " + quote(sphere), dir);
  CHECK(e.out.find("\"flipped_exact\":0") != std::string::npos);
}
