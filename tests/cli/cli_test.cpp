// End-to-end tests of the `spherekit` program: exit codes, one-line error messages that
// name the file, no output (and no temporary file) left behind on failure, and valid
// outputs on success. Inputs are generated here into per-test temporary folders.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "spherekit/sphere_param.h"
#include "spherekit/version.h"
#include "test_meshes.h"
#include "test_paths.h"
#include "test_files.h"
#include "cli_shorthands.h"

namespace fs = std::filesystem;
using nlohmann::json;
using spherekit::TriMesh;

namespace {

using spherekit::test::files_in;
using spherekit::test::quote;
using spherekit::test::write_text;

using spherekit::test::CliRun;
using spherekit::test::slurp;
// Runs `spherekit ARGS` with stdout/stderr captured into files of `capture_dir` (never the
// folder whose contents a test inspects).
CliRun run_cli(const std::string& args, const std::string& capture_dir) {
  return spherekit::test::run_cli(SPHEREKIT_EXE, args, capture_dir);
}

std::string obj_text(const TriMesh& m) {
  std::string s;
  char buf[128];
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", m.V(i, 0), m.V(i, 1), m.V(i, 2));
    s += buf;
  }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    std::snprintf(buf, sizeof buf, "f %d %d %d\n", m.F(f, 0) + 1, m.F(f, 1) + 1, m.F(f, 2) + 1);
    s += buf;
  }
  return s;
}

std::string write_obj(const std::string& dir, const std::string& name, const TriMesh& m) {
  const std::string path = dir + "/" + name;
  write_text(path, obj_text(m));
  return path;
}

// Binary little-endian PLY (float x y z, uchar/int lists) with the given vertex count in
// the header, which lets a test lie about it.
std::string binary_ply(const TriMesh& m, long header_vertices) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(header_vertices) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(m.F.rows()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&](const void* p, size_t n) { s.append(static_cast<const char*>(p), n); };
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    for (int k = 0; k < 3; ++k) {
      const float x = static_cast<float>(m.V(i, k));
      put(&x, 4);
    }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const unsigned char n = 3;
    put(&n, 1);
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = m.F(f, k);
      put(&v, 4);
    }
  }
  return s;
}

int count_lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// The contract for every failure: exactly one line on stderr, `spherekit: error: ...`,
// naming the offending file.
void require_one_line_error(const CliRun& r, const std::string& file) {
  INFO("stderr: " << r.err);
  CHECK(count_lines(r.err) == 1);
  CHECK(r.err.rfind("spherekit: error: ", 0) == 0);
  CHECK(r.err.find(fs::path(file).filename().string()) != std::string::npos);
}

// Vertex positions of an OBJ, parsed here (independently of formats/).
std::vector<Eigen::Vector3d> obj_vertices(const std::string& path) {
  std::vector<Eigen::Vector3d> V;
  std::istringstream in(slurp(path));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) != 0) continue;
    std::istringstream f(line.substr(2));
    Eigen::Vector3d p;
    f >> p.x() >> p.y() >> p.z();
    V.push_back(p);
  }
  return V;
}

json parse_json(const std::string& text) {
  json j = json::parse(text, nullptr, false);
  INFO("text: " << text);
  REQUIRE_FALSE(j.is_discarded());
  return j;
}

}  // namespace

TEST_CASE("help and version flags exit 0", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_help");
  CliRun help = run_cli("--help", dir);
  CHECK(help.exit_code == 0);
  for (const char* cmd : {"check", "param", "eval", "samples", "bench", "run"}) {
    CHECK(help.out.find(cmd) != std::string::npos);
    CliRun sub = run_cli(std::string(cmd) + " --help", dir);
    INFO(cmd);
    CHECK(sub.exit_code == 0);
    CHECK(sub.out.find("Examples:") != std::string::npos);
  }
  CliRun version = run_cli("--version", dir);
  CHECK(version.exit_code == 0);
  CHECK(version.out.find(spherekit::kVersion) != std::string::npos);
}

TEST_CASE("usage errors exit 2 with one line", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_usage");
  const std::string mesh = write_obj(dir, "blob.obj", spherekit::test::random_blob(1, 3));
  for (const std::string& args : {std::string(""), std::string("frobnicate"), "check --no-such-flag " + mesh,
                                 "param " + mesh + " -o " + dir + "/x.obj --effort 9", "param " + mesh,
                                 "check " + mesh + " --repair"}) {
    INFO("args: " << args);
    CliRun r = run_cli(args, dir);
    CHECK(r.exit_code == 2);
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.rfind("spherekit: error: ", 0) == 0);
  }
  CHECK_FALSE(fs::exists(dir + "/x.obj"));
}

TEST_CASE("check reports a good mesh as genus 0", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_check_good");
  const TriMesh blob = spherekit::test::random_blob(2, 7);
  const std::string mesh = write_obj(dir, "blob.obj", blob);

  CliRun r = run_cli("check --json " + quote(mesh), dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  json j = parse_json(r.out);
  REQUIRE(j.is_array());
  REQUIRE(j.size() == 1);
  CHECK(j[0]["file"] == mesh);
  CHECK(j[0]["V"] == blob.V.rows());
  CHECK(j[0]["F"] == blob.F.rows());
  CHECK(j[0]["genus"] == 0);
  CHECK(j[0]["euler"] == 2);
  CHECK(j[0]["components"] == 1);
  CHECK(j[0]["boundary_loops"] == 0);
  CHECK(j[0]["genus0_ok"] == true);
  for (const char* key : {"edges", "unreferenced_vertices", "degenerate_faces", "duplicate_faces", "zero_area_faces",
                          "boundary_edges", "nonmanifold_edges", "orientation_conflicts", "nonmanifold_vertices",
                          "orientable", "bbox_diag"})
    CHECK(j[0].contains(key));

  CliRun human = run_cli("check " + quote(mesh), dir);
  CHECK(human.exit_code == 0);
  CHECK(human.out.find("ok: genus-0 (0 holes)") != std::string::npos);
}

TEST_CASE("check accepts holes and refuses genus 1 with exit 3", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_check_topology");
  const std::string holes = write_obj(dir, "holes.obj", spherekit::test::sphere_with_holes(2, 3));
  const std::string torus = write_obj(dir, "torus.obj", spherekit::test::torus());

  CliRun ok = run_cli("check " + quote(holes), dir);
  CHECK(ok.exit_code == 0);
  CHECK(ok.out.find("ok: genus-0 (3 holes)") != std::string::npos);

  CliRun bad = run_cli("check --json " + quote(torus), dir);
  CHECK(bad.exit_code == 3);
  require_one_line_error(bad, torus);
  json j = parse_json(bad.out);
  CHECK(j[0]["genus"] == 1);
  CHECK(j[0]["genus0_ok"] == false);

  // Several files: the worst verdict wins, every file still reported.
  CliRun both = run_cli("check --json " + quote(holes) + " " + quote(torus), dir);
  CHECK(both.exit_code == 3);
  CHECK(parse_json(both.out).size() == 2);
}

TEST_CASE("check --repair splits a pinched vertex", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_repair");
  const std::string pinched = write_obj(dir, "pinched.obj", spherekit::test::pinched_tetrahedra());
  const std::string fixed = dir + "/fixed.obj";

  CliRun before = run_cli("check --json " + quote(pinched), dir);
  CHECK(before.exit_code == 3);
  CHECK(parse_json(before.out)[0]["nonmanifold_vertices"] == 1);

  CliRun r = run_cli("check --json " + quote(pinched) + " --repair -o " + quote(fixed), dir);
  REQUIRE(fs::exists(fixed));
  json j = parse_json(r.out);
  CHECK(j[0]["repair"]["split_vertices"].get<int>() >= 1);
  CHECK(j[0]["nonmanifold_vertices"] == 0);

  CliRun after = run_cli("check --json " + quote(fixed), dir);
  CHECK(parse_json(after.out)[0]["nonmanifold_vertices"] == 0);
}

TEST_CASE("malformed inputs fail with one line, no output, no temp files", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_malformed");
  const std::string out_dir = dir + "/out";
  fs::create_directories(out_dir);
  const TriMesh blob = spherekit::test::random_blob(1, 5);

  const std::string good_ply = binary_ply(blob, blob.V.rows());
  struct Bad {
    std::string name, content;
    int exit_code;
  };
  std::vector<Bad> cases = {
      {"empty.obj", "", 3},
      {"truncated.ply", good_ply.substr(0, good_ply.size() - 7 * 13 - 5), 3},
      {"index_out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 99\n", 3},
      {"nan_coordinate.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", 3},
      // (A mix of triangles and quads is accepted since issue 24: inputs_cli_test.cpp.)
      // The header claims one vertex more than the file holds: the faces are read one
      // vertex record late and the data ends early.
      {"wrong_counts.ply", binary_ply(blob, blob.V.rows() + 1), 3},
      {"torus.obj", obj_text(spherekit::test::torus()), 3},
      {"two_components.obj", obj_text(spherekit::test::two_tetrahedra()), 3},
  };
  for (const Bad& c : cases) {
    const std::string input = dir + "/" + c.name;
    write_text(input, c.content);
    const std::string output = out_dir + "/" + fs::path(c.name).stem().string() + ".sphere.obj";
    const std::string report = out_dir + "/" + fs::path(c.name).stem().string() + ".json";
    INFO("input: " << c.name);

    CliRun p = run_cli("param " + quote(input) + " -o " + quote(output) + " --report " + quote(report), dir);
    CHECK(p.exit_code == c.exit_code);
    require_one_line_error(p, input);
    CHECK(files_in(out_dir).empty());

    if (c.name != "torus.obj" && c.name != "two_components.obj") {
      CliRun k = run_cli("check " + quote(input), dir);
      CHECK(k.exit_code == c.exit_code);
      require_one_line_error(k, input);
    }
  }

  const std::string missing = dir + "/does_not_exist.obj";
  CliRun m = run_cli("param " + quote(missing) + " -o " + quote(out_dir + "/m.obj"), dir);
  CHECK(m.exit_code == 4);
  require_one_line_error(m, missing);
  CHECK(files_in(out_dir).empty());
}

TEST_CASE("param --report - writes the report to standard output, no file named -", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_report_stdout");
  const std::string out_dir = dir + "/out";
  fs::create_directories(out_dir);
  const std::string mesh = write_obj(dir, "blob.obj", spherekit::test::random_blob(2, 5));
  CliRun p = run_cli("param " + quote(mesh) + " -o " + quote(out_dir + "/blob.sphere.obj") +
                         " --report - --effort 0 --quiet", out_dir);
  INFO("stderr: " << p.err);
  REQUIRE(p.exit_code == 0);
  CHECK_FALSE(fs::exists(fs::current_path() / "-"));  // the command runs in the test's directory
  // The report is the last JSON object on stdout (the summary comes before it).
  const size_t start = p.out.find("{\n");
  REQUIRE(start != std::string::npos);
  json r = json::parse(p.out.substr(start), nullptr, false);
  REQUIRE_FALSE(r.is_discarded());
  CHECK(r["flipped_faces"] == 0);
}

TEST_CASE("param writes a bijective unit sphere map and eval agrees", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_param");
  const std::string out_dir = dir + "/out";
  fs::create_directories(out_dir);
  const TriMesh blob = spherekit::test::random_blob(2, 11);
  const std::string mesh = write_obj(dir, "blob.obj", blob);
  const std::string sphere = out_dir + "/blob.sphere.obj";
  const std::string report = out_dir + "/blob.json";

  CliRun p = run_cli("param " + quote(mesh) + " -o " + quote(sphere) + " --report " + quote(report) + " --effort 1", dir);
  INFO("stderr: " << p.err);
  REQUIRE(p.exit_code == 0);
  CHECK(files_in(out_dir) == std::vector<std::string>{"blob.json", "blob.sphere.obj"});
  CHECK(p.out.find("efficiency") != std::string::npos);

  const auto S = obj_vertices(sphere);
  REQUIRE(S.size() == static_cast<size_t>(blob.V.rows()));
  double worst = 0;
  for (const auto& s : S) worst = std::max(worst, std::abs(s.norm() - 1.0));
  CHECK(worst < 1e-12);

  json r = parse_json(slurp(report));
  CHECK(r["flipped_faces"] == 0);
  CHECK(r["V"] == blob.V.rows());
  CHECK(r["F"] == blob.F.rows());
  CHECK(r["efficiency"].get<double>() > 0.1);
  CHECK(r["efficiency"].get<double>() <= 1.0);
  for (const char* key : {"input", "holes_filled", "l2_stretch", "linf_stretch", "winding", "base_vertices",
                          "optimization_passes", "times", "cpu_seconds", "peak_rss_mb", "options", "version"})
    CHECK(r.contains(key));
  CHECK(r["options"]["effort"] == 1);

  CliRun e = run_cli("eval --json " + quote(mesh) + " " + quote(sphere), dir);
  REQUIRE(e.exit_code == 0);
  json m = parse_json(e.out);
  CHECK(m["vertices"] == blob.V.rows());
  CHECK(m["faces"] == blob.F.rows());
  CHECK(m["flipped"] == 0);
  CHECK(m["flipped_exact"] == 0);
  CHECK(m["degenerate_exact"] == 0);
  CHECK(m["closed"] == true);
  CHECK(m["winding"].get<double>() == Approx(1.0).margin(1e-9));
  CHECK(m["fold_excess"].get<double>() == Approx(0.0).margin(1e-9));
  CHECK(m["efficiency"].get<double>() == Approx(r["efficiency"].get<double>()).margin(1e-6));
  CHECK_FALSE(m.contains("feature_err_deg"));

  // --targets: vertex 0 must land where the map put it; vertex 1 on the opposite point.
  const std::string targets = dir + "/targets.txt";
  write_text(targets, "# name vertex x y z\nhere 0 " + std::to_string(S[0].x()) + " " + std::to_string(S[0].y()) +
                          " " + std::to_string(S[0].z()) + "\n");
  CliRun t = run_cli("eval --json " + quote(mesh) + " " + quote(sphere) + " --targets " + quote(targets), dir);
  REQUIRE(t.exit_code == 0);
  CHECK(parse_json(t.out)["feature_err_deg"].get<double>() < 1e-3);

  const std::string bad_targets = dir + "/bad_targets.txt";
  write_text(bad_targets, "nose 100000 0 0 1\n");
  CliRun bt = run_cli("eval " + quote(mesh) + " " + quote(sphere) + " --targets " + quote(bad_targets), dir);
  CHECK(bt.exit_code == 3);
  require_one_line_error(bt, bad_targets);

  CliRun human = run_cli("eval " + quote(mesh) + " " + quote(sphere), dir);
  CHECK(human.exit_code == 0);
  CHECK(human.out.find("efficiency") != std::string::npos);

  // A sphere map of another mesh (different vertex count) is refused, naming the sphere file.
  const std::string other = write_obj(dir, "other.obj", spherekit::test::icosphere(1));
  CliRun mismatch = run_cli("eval " + quote(other) + " " + quote(sphere), dir);
  CHECK(mismatch.exit_code == 3);
  require_one_line_error(mismatch, sphere);
}

TEST_CASE("param: a constrained map takes the collection stages' anti-cruft and hole shape weights unless the flags are given, and ranks its network on both embeddings unless --no-arc-ranking (--as-unconstrained off unless given)",
          "[cli]") {
  // The unconstrained map's default weight is lower (sphere_param.h); a constrained map is the
  // map `consistent` or `add` would make, so `param --features` keeps theirs.
  const std::string dir = spherekit::test::temp_dir("cli_param_regularizer");
  const TriMesh blob = spherekit::test::random_blob(2, 11);
  const std::string mesh = write_obj(dir, "blob.obj", blob);
  // Four features: the vertices farthest out towards a regular tetrahedron's corners.
  const double k = 1.0 / std::sqrt(3.0);
  const Eigen::Vector3d corners[4] = {{k, k, k}, {k, -k, -k}, {-k, k, -k}, {-k, -k, k}};
  std::string features, targets;
  for (int c = 0; c < 4; ++c) {
    Eigen::Index best = 0;
    double best_dot = -2;
    for (Eigen::Index v = 0; v < blob.V.rows(); ++v) {
      const double d = blob.V.row(v).normalized().dot(corners[c].transpose());
      if (d > best_dot) best_dot = d, best = v;
    }
    features += "f" + std::to_string(c) + " " + std::to_string(best) + "\n";
    char line[160];
    std::snprintf(line, sizeof line, "f%d %.17g %.17g %.17g\n", c, corners[c].x(), corners[c].y(), corners[c].z());
    targets += line;
  }
  write_text(dir + "/blob.lm.txt", features);
  write_text(dir + "/blob.targets.txt", targets);
  auto option = [&](const std::string& extra, const char* key) {
    const std::string report = dir + "/r.json";
    CliRun p = run_cli("param " + quote(mesh) + " -o " + quote(dir + "/blob.sphere.obj") + " --report " + quote(report) +
                           " --effort 0 --quiet" + extra, dir);
    INFO("stderr: " << p.err);
    REQUIRE(p.exit_code == 0);
    return parse_json(slurp(report))["options"][key];
  };
  auto weight = [&](const std::string& extra) { return option(extra, "regularizer_weight").get<double>(); };
  auto hole_shape = [&](const std::string& extra) { return option(extra, "hole_shape_weight").get<double>(); };
  const std::string constrained = " --features " + quote(dir + "/blob.lm.txt") + " --targets " + quote(dir + "/blob.targets.txt");
  CHECK(weight("") == spherekit::SphereParamOptions{}.regularizer_weight);
  CHECK(weight(constrained) == spherekit::kCollectionRegularizerWeight);
  CHECK(weight(constrained + " --regularizer-weight 2e-5") == 2e-5);
  CHECK(weight(" --regularizer-weight 3e-4") == 3e-4);
  // The hole faces' shape weight the same way, and the coarse-layout precision.
  CHECK(hole_shape("") == spherekit::SphereParamOptions{}.hole_shape_weight);
  CHECK(hole_shape(constrained) == spherekit::kCollectionHoleShapeWeight);
  CHECK(hole_shape(constrained + " --hole-shape-weight 0.1") == 0.1);
  CHECK(option("", "precise_layout").get<bool>());
  CHECK_FALSE(option(constrained, "precise_layout").get<bool>());
  // The simplification in blocks likewise, and its flag.
  CHECK(option("", "block_vertices").get<int>() == spherekit::SphereParamOptions{}.block_vertices);
  CHECK(option(" --block-vertices 0", "block_vertices").get<int>() == 0);
  CHECK(option(constrained, "block_vertices").get<int>() == 0);
  // The path network's ranking (path_network.cpp, rank_cost): on unless switched off.
  CHECK(option(constrained, "arc_ranking").get<bool>());
  CHECK_FALSE(option(constrained + " --no-arc-ranking", "arc_ranking").get<bool>());
  // The unconstrained stage's simplification and energy: off unless asked for.
  CHECK_FALSE(option(constrained, "as_unconstrained").get<bool>());
  CHECK(option(constrained + " --as-unconstrained", "as_unconstrained").get<bool>());
}

TEST_CASE("param checks every output folder before writing anything", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_param_folders");
  const std::string out_dir = dir + "/out";
  fs::create_directories(out_dir);
  const std::string mesh = write_obj(dir, "blob.obj", spherekit::test::random_blob(1, 3));
  CliRun p = run_cli("param " + quote(mesh) + " -o " + quote(out_dir + "/blob.sphere.obj") + " --report " +
                         quote(dir + "/missing/r.json"),
                     dir);
  CHECK(p.exit_code == 4);
  CHECK(p.err.find("missing") != std::string::npos);
  CHECK(std::count(p.err.begin(), p.err.end(), '\n') == 1);
  CHECK(files_in(out_dir).empty());
}

TEST_CASE("param refuses a sphere-map name it cannot write before reading the mesh", "[cli]") {
  // The name is checked first: a mesh that does not exist is not even opened, so a user with a
  // large mesh learns of a wrong -o name at once, not after the whole map was computed.
  const std::string dir = spherekit::test::temp_dir("cli_param_output_name");
  const std::string out_dir = dir + "/out";
  fs::create_directories(out_dir);
  CliRun p = run_cli("param " + quote(dir + "/absent.obj") + " -o " + quote(out_dir + "/absent.sph") + " --report " +
                         quote(out_dir + "/r.json"),
                     dir);
  CHECK(p.exit_code != 0);
  CHECK(p.err.find("absent.sph: sphere maps are written as .obj files") != std::string::npos);
  CHECK(std::count(p.err.begin(), p.err.end(), '\n') == 1);
  CHECK(files_in(out_dir).empty());
}

TEST_CASE("param on a mesh with holes maps the original vertices only; convert leaves the holes open", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_param_holes");
  const TriMesh holes = spherekit::test::sphere_with_holes(2, 2);
  const std::string mesh = write_obj(dir, "holes.obj", holes);
  const std::string sphere = dir + "/holes.sphere.obj";
  const std::string report = dir + "/holes.json";

  CliRun p = run_cli("param " + quote(mesh) + " -o " + quote(sphere) + " --report " + quote(report) + " --quiet", dir);
  INFO("stderr: " << p.err);
  REQUIRE(p.exit_code == 0);
  CHECK(p.out.empty());  // --quiet
  CHECK(p.err.empty());
  CHECK(obj_vertices(sphere).size() == static_cast<size_t>(holes.V.rows()));
  CHECK(parse_json(slurp(report))["holes_filled"] == 2);

  CliRun e = run_cli("eval --json " + quote(mesh) + " " + quote(sphere), dir);
  REQUIRE(e.exit_code == 0);
  json m = parse_json(e.out);
  CHECK(m["closed"] == false);
  CHECK(m["flipped"] == 0);
  CHECK(m["flipped_exact"] == 0);
  CHECK_FALSE(m.contains("winding"));

  // The remesh of one mesh keeps its holes open and is a genus-0 manifold with both rims.
  const std::string remesh = dir + "/holes.gim.obj";
  CliRun c = run_cli("convert " + quote(mesh) + " " + quote(sphere) + " -o " + quote(dir + "/holes.exr") +
                         " --size 33 --psnr-samples 0 --quiet --remesh " + quote(remesh),
                     dir);
  INFO("convert stderr: " << c.err);
  REQUIRE(c.exit_code == 0);
  CliRun k = run_cli("check --json " + quote(remesh), dir);
  INFO("check: " << k.out);
  REQUIRE(k.exit_code == 0);
  json r = parse_json(k.out).at(0);
  CHECK(r["genus0_ok"] == true);
  CHECK(r["boundary_loops"] == 2);
  CHECK(r["unreferenced_vertices"] == 0);
}

TEST_CASE("samples writes meshes and landmarks that check accepts", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_samples");
  const std::string out = dir + "/samples";
  CliRun r = run_cli("samples -o " + quote(out) + " --members 2 --vertices 800", dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  std::vector<std::string> objs;
  for (const std::string& f : files_in(out))
    if (fs::path(f).extension() == ".obj") objs.push_back(out + "/" + f);
  REQUIRE(objs.size() == 2);
  for (const std::string& obj : objs) {
    const std::string stem = fs::path(obj).stem().string();
    CHECK(fs::exists(out + "/" + stem + ".lm.txt"));
    CliRun c = run_cli("check " + quote(obj), dir);
    CHECK(c.exit_code == 0);
  }
  // -q: the same files, nothing printed.
  const std::string quiet_out = dir + "/quiet";
  CliRun q = run_cli("samples -q -o " + quote(quiet_out) + " --members 2 --target-vertices 800", dir);
  REQUIRE(q.exit_code == 0);
  CHECK(q.out.empty());
  CHECK(q.err.empty());
  for (const std::string& f : files_in(out)) CHECK(slurp(out + "/" + f) == slurp(quiet_out + "/" + f));
}

TEST_CASE("run maps given meshes and reports failures but keeps going", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_run");
  const std::string good = write_obj(dir, "blob.obj", spherekit::test::random_blob(2, 4));
  const std::string bad = write_obj(dir, "torus.obj", spherekit::test::torus());
  const std::string out = dir + "/out";

  CliRun r = run_cli("run " + quote(good) + " " + quote(bad) + " -o " + quote(out) + " --effort 0", dir);
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 3);
  CHECK(r.out.find(fs::absolute(out).lexically_normal().string()) != std::string::npos);
  CHECK(fs::exists(out + "/blob.sphere.obj"));
  CHECK_FALSE(fs::exists(out + "/torus.sphere.obj"));
  json report = parse_json(slurp(out + "/report.json"));
  REQUIRE(report["meshes"].size() == 2);
  CHECK(report["meshes"][0]["status"] == "ok");
  CHECK(report["meshes"][0]["eval"]["flipped"] == 0);
  CHECK(report["meshes"][0]["eval"]["winding"].get<double>() == Approx(1.0).margin(1e-9));
  CHECK(report["meshes"][1]["status"] == "failed");
  CHECK(report["meshes"][1]["check"]["genus"] == 1);
  CHECK(report["summary"]["failed"] == 1);
}

// The main job on the built-in samples (run without meshes) is tested with its results page
// in site_page_test.cpp.

// A child's peak memory is its own: after bench has read and measured a large mesh itself,
// the next mesh's peak is what param measures running alone, not the bench's (a spawned
// child's ru_maxrss includes the address space it was spawned from).
TEST_CASE("bench: a mesh's peak memory does not include what the bench held before", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_bench_peak");
  const std::string big = write_obj(dir, "big.obj", spherekit::test::icosphere(6));
  const std::string small = write_obj(dir, "small.obj", spherekit::test::random_blob(2, 5));
  const std::string out = dir + "/bench.json", alone = dir + "/alone.json";
  CliRun r = run_cli("bench " + quote(big) + " " + quote(small) + " --effort 0 --threads 1 -o " + quote(out), dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  REQUIRE(run_cli("param " + quote(small) + " -o " + quote(dir + "/small.sphere.obj") +
                      " --effort 0 --threads 1 --quiet --report " + quote(alone),
                  dir)
              .exit_code == 0);
  const json rows = parse_json(slurp(out))["rows"];
  REQUIRE(rows.size() == 2);
  const double big_peak = rows[0]["peak_mb"].get<double>(), small_peak = rows[1]["peak_mb"].get<double>();
  const double alone_peak = parse_json(slurp(alone))["peak_rss_mb"].get<double>();
  CAPTURE(big_peak, small_peak, alone_peak);
  CHECK(small_peak > 0);
  CHECK(small_peak < alone_peak + 2);
  CHECK(big_peak > small_peak + 5);
  // -q: no progress, table or summary; the JSON still written.
  const std::string quiet_json = dir + "/quiet.json";
  CliRun q = run_cli("bench -q " + quote(small) + " --effort 0 --threads 1 -o " + quote(quiet_json), dir);
  REQUIRE(q.exit_code == 0);
  CHECK(q.out.empty());
  CHECK(q.err.empty());
  CHECK(r.out.find("total CPU") != std::string::npos);
  CHECK(parse_json(slurp(quiet_json))["rows"].size() == 1);
}

// bench --reference-dir runs the reference's pipeline script after ours on each mesh and
// compares with what it measured in the same run. The stand-in "reference" here is a script
// that runs this same spherekit (deterministic), so both rows must agree exactly; the real
// kit (shared/anchors/mpl) is exercised by hand, its build takes minutes.
TEST_CASE("bench compares with a reference measured in the same run", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_bench_reference");
  const std::string mesh = write_obj(dir, "blob.obj", spherekit::test::random_blob(2, 5));
  const std::string kit = dir + "/mpl";
  fs::create_directories(kit + "/bin/unix");
  write_text(kit + "/bin/unix/SphereParam", "#!/bin/sh\nexit 1\n");
  const std::string script = dir + "/fake_sphereparam.sh";
  write_text(script, "#!/bin/bash\n[[ -n $MPL_ROOT && -n $OMP_NUM_THREADS ]] || exit 9\nexec " +
                         quote(SPHEREKIT_EXE) + " param \"$1\" -o \"$2\" --quiet\n");
  // bench of the blob against the stand-in reference `ref_script`, JSON to `json_out`.
  auto bench_against = [&](const std::string& ref_script, const std::string& json_out) {
    return run_cli("bench " + quote(mesh) + " --reference-dir " + quote(kit) + " --reference-script " +
                       quote(ref_script) + " --threads 1 -o " + quote(json_out),
                   dir);
  };
  const std::string out = dir + "/bench.json";
  CliRun r = bench_against(script, out);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("measured in this run") != std::string::npos);
  json j = parse_json(slurp(out));
  REQUIRE(j["rows"].size() == 1);
  const json& row = j["rows"][0];
  REQUIRE(row.contains("reference"));
  CHECK(row["reference"]["efficiency"].get<double>() == Approx(row["efficiency"].get<double>()).epsilon(1e-9));
  CHECK(row["reference"]["cpu_seconds"].get<double>() > 0);
  CHECK(j["totals"]["cpu_ratio"].get<double>() > 0);
  // Linf stretch of both maps, measured by the same evaluator: a normalised max singular
  // value is >= 1 (the chord-area-weighted mean of the area ratios is 1), the ratio is
  // ours / reference, and the identical stand-in gives the same Linf, so the 1.5x rule passes.
  REQUIRE(row.contains("linf"));
  REQUIRE(row["reference"].contains("linf"));
  const double linf = row["linf"].get<double>(), ref_linf = row["reference"]["linf"].get<double>();
  CHECK(linf >= 1.0);
  CHECK(ref_linf == Approx(linf).epsilon(1e-9));
  CHECK(row["linf_ratio"].get<double>() == Approx(linf / ref_linf).epsilon(1e-12));
  CHECK(j["totals"]["linf_compared"] == 1);
  CHECK(j["totals"]["worst_linf_ratio"].get<double>() == Approx(row["linf_ratio"].get<double>()).epsilon(1e-12));
  CHECK(j["totals"]["linf_ratio_limit"].get<double>() == 1.5);
  CHECK(j["totals"]["linf_rule_pass"] == true);
  CHECK(j["totals"]["linf_over_limit"].empty());
  CHECK(r.out.find("Linf rule (ours <= 1.5x the reference's): pass, 0 of 1 meshes above") != std::string::npos);
  CHECK(r.out.find("Linf ratio") != std::string::npos);
  // The reference's map is checked for flips by the same exact predicate as ours.
  CHECK(row["reference"]["flipped_faces"] == 0);
  CHECK(j["totals"]["reference_flipped_faces"] == 0);
  CHECK(j["totals"]["reference_failed"].empty());
  CHECK(r.out.find("reference: 0 flipped faces in its maps; failed on 0 meshes") != std::string::npos);

  // A reference run that fails (SphereParam exits with an error on large generated shapes):
  // our row is still measured and the bench succeeds; the row says how the reference's run
  // ended, the totals name the mesh, and no reference figure enters the ratios.
  const std::string failing = dir + "/failing_sphereparam.sh";
  write_text(failing, "#!/bin/bash\nsleep 0.2\nexit 3\n");
  const std::string out_failed = dir + "/bench_failed.json";
  CliRun rf = bench_against(failing, out_failed);
  INFO("stderr: " << rf.err);
  REQUIRE(rf.exit_code == 0);
  const json jf = parse_json(slurp(out_failed));
  const json& frow = jf["rows"][0];
  CHECK(frow["status"] == "ok");
  CHECK(frow["efficiency"].get<double>() == Approx(row["efficiency"].get<double>()).epsilon(1e-12));
  REQUIRE(frow.contains("reference"));
  CHECK(frow["reference"]["status"] == "failed");
  CHECK(frow["reference"]["exit_code"] == 3);
  CHECK(frow["reference"]["wall_seconds"].get<double>() >= 0.2);
  CHECK_FALSE(frow["reference"].contains("efficiency"));
  CHECK_FALSE(frow.contains("cpu_ratio"));
  CHECK_FALSE(frow.contains("linf_ratio"));
  CHECK(jf["totals"]["reference_failed"] == json::array({"blob.obj"}));
  CHECK_FALSE(jf["totals"].contains("cpu_ratio"));
  CHECK(rf.out.find("failed on 1 meshes (blob.obj)") != std::string::npos);
  CHECK(rf.err.find("the reference failed on") != std::string::npos);

  // Without a reference measured here (the blob has no recorded figures either) our Linf is
  // still there, the reference side is left out, and our figure is the one param itself
  // reports for its map (bench reads the written file back: 17 digits, same definition).
  const std::string out_alone = dir + "/bench_alone.json", param_report = dir + "/param.json";
  CliRun alone = run_cli("bench " + quote(mesh) + " --threads 1 -o " + quote(out_alone), dir);
  INFO("stderr: " << alone.err);
  REQUIRE(alone.exit_code == 0);
  REQUIRE(run_cli("param " + quote(mesh) + " -o " + quote(dir + "/blob.sphere.obj") + " --threads 1 --quiet --report " +
                      quote(param_report),
                  dir)
              .exit_code == 0);
  const json alone_row = parse_json(slurp(out_alone))["rows"][0];
  REQUIRE(alone_row.contains("linf"));
  CHECK(alone_row["linf"].get<double>() == Approx(parse_json(slurp(param_report))["linf_stretch"].get<double>()).epsilon(1e-6));
  CHECK(alone_row["linf"].get<double>() == Approx(linf).epsilon(1e-9));
  CHECK_FALSE(alone_row.contains("linf_ratio"));
  CHECK_FALSE(parse_json(slurp(out_alone))["totals"].contains("worst_linf_ratio"));
  CHECK(alone.out.find("Linf rule") == std::string::npos);

  // A folder without the reference's programs: one-line error naming it, no output.
  const std::string out2 = dir + "/bench2.json";
  CliRun bad = run_cli("bench " + quote(mesh) + " --reference-dir " + quote(dir + "/nowhere") + " -o " + quote(out2), dir);
  CHECK(bad.exit_code != 0);
  CHECK(bad.err.find("nowhere") != std::string::npos);
  CHECK_FALSE(fs::exists(out2));
}

// bench runs each mesh in a child of its own executable. When the file it was started from is
// replaced while it runs (a rebuild or an upgrade during a long bench), the children still
// start: here the stand-in reference deletes the copy of spherekit the bench runs from after
// the first mesh, and the second mesh is measured all the same (before, spawning the deleted
// file's name failed: "cannot start child process").
TEST_CASE("bench measures every mesh after its executable file was removed", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_bench_removed_exe");
  const std::string a = write_obj(dir, "a.obj", spherekit::test::random_blob(2, 5));
  const std::string b = write_obj(dir, "b.obj", spherekit::test::random_blob(2, 6));
  const std::string copy = dir + "/spherekit_copy";
  fs::copy_file(SPHEREKIT_EXE, copy, fs::copy_options::overwrite_existing);
  fs::permissions(copy, fs::perms::owner_all);
  const std::string kit = dir + "/mpl";
  fs::create_directories(kit + "/bin/unix");
  write_text(kit + "/bin/unix/SphereParam", "#!/bin/sh\nexit 1\n");
  const std::string script = dir + "/removing_sphereparam.sh";
  write_text(script, "#!/bin/bash\nrm -f " + quote(copy) + "\nexec " + quote(SPHEREKIT_EXE) +
                         " param \"$1\" -o \"$2\" --quiet\n");
  const std::string out = dir + "/bench.json";
  CliRun r = spherekit::test::run_cli(copy, "bench " + quote(a) + " " + quote(b) + " --reference-dir " + quote(kit) +
                                                " --reference-script " + quote(script) + " --threads 1 -o " + quote(out),
                                      dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_FALSE(fs::exists(copy));
  const json j = parse_json(slurp(out));
  REQUIRE(j["rows"].size() == 2);
  for (const json& row : j["rows"]) {
    CHECK(row["status"] == "ok");
    CHECK(row["flipped_faces"] == 0);
    CHECK(row["reference"]["efficiency"].get<double>() == Approx(row["efficiency"].get<double>()).epsilon(1e-9));
  }
}
