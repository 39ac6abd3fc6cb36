// End-to-end tests of `spherekit convert`: outputs and report on success; a bad --size is a
// usage error (exit 2, one line, nothing written).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_runner.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "test_meshes.h"
#include "test_paths.h"
#include "cli_shorthands.h"

namespace fs = std::filesystem;
using namespace spherekit;

namespace {

using spherekit::test::quote;

using spherekit::test::CliRun;
using spherekit::test::slurp;
CliRun run_cli(const std::string& args, const std::string& capture_dir) {
  return spherekit::test::run_cli(SPHEREKIT_EXE, args, capture_dir);
}

// A star-shaped blob and its radial sphere map, written into `dir`.
void write_inputs(const std::string& dir) {
  const TriMesh blob = test::random_blob(3, 21);
  REQUIRE(formats::write_mesh(dir + "/blob.obj", blob).ok());
  SphereMap map;
  map.S = blob.V.rowwise().normalized();
  map.provenance.method = "radial";
  REQUIRE(formats::write_sphere_map(dir + "/blob.sphere.obj", blob, map).ok());
}

}  // namespace

TEST_CASE("spherekit convert writes the geometry image, remesh and report", "[convert]") {
  const std::string dir = test::temp_dir("convert_cli_ok"), cap = test::temp_dir("convert_cli_ok_capture");
  write_inputs(dir);
  const CliRun r = run_cli("convert " + quote(dir + "/blob.obj") + " " + quote(dir + "/blob.sphere.obj") + " -o " +
                               quote(dir + "/blob.exr") + " --size 33 --remesh " + quote(dir + "/blob.gim.obj") +
                               " --report " + quote(dir + "/blob.json") + " --psnr-samples 50000",
                           cap);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("PSNR") != std::string::npos);
  auto gi = convert::read_geometry_image_exr(dir + "/blob.exr");
  REQUIRE(gi.ok());
  CHECK(gi->image.size == 33);
  CHECK(gi->attributes.at("layout") == "octahedral");
  auto remesh = formats::read_mesh(dir + "/blob.gim.obj");
  REQUIRE(remesh.ok());
  CHECK(remesh->F.rows() == 2 * 32 * 32);
  const auto report = nlohmann::json::parse(slurp(dir + "/blob.json"));
  CHECK(report.at("size") == 33);
  CHECK(report.at("psnr_db").get<double>() > 30);
  CHECK(report.at("psnr_db").get<double>() < 100);
}

TEST_CASE("spherekit convert: a bad --size is a usage error and writes nothing", "[convert]") {
  const std::string dir = test::temp_dir("convert_cli_bad"), cap = test::temp_dir("convert_cli_bad_capture");
  write_inputs(dir);
  const CliRun r = run_cli("convert " + quote(dir + "/blob.obj") + " " + quote(dir + "/blob.sphere.obj") + " -o " +
                               quote(dir + "/out.exr") + " --size 100 --report " + quote(dir + "/r.json"),
                           cap);
  CHECK(r.exit_code == 2);
  CHECK(r.err.rfind("spherekit: error: ", 0) == 0);
  CHECK(r.err.find("100") != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir + "/out.exr"));
  CHECK_FALSE(fs::exists(dir + "/r.json"));
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  CHECK(files == 2);  // the two inputs only

  // A sphere map that does not match the mesh: exit 3, names the file.
  const TriMesh other = test::icosphere(1);
  REQUIRE(formats::write_mesh(dir + "/other.obj", other).ok());
  const CliRun r2 = run_cli("convert " + quote(dir + "/other.obj") + " " + quote(dir + "/blob.sphere.obj") + " -o " +
                                quote(dir + "/out.exr"),
                            cap);
  CHECK(r2.exit_code == 3);
  CHECK(r2.err.find("blob.sphere.obj") != std::string::npos);
  CHECK_FALSE(fs::exists(dir + "/out.exr"));
}

TEST_CASE("spherekit convert --positions: fitted texels beat sampled ones; a bad value writes nothing", "[convert]") {
  const std::string dir = test::temp_dir("convert_cli_positions"), cap = test::temp_dir("convert_cli_positions_cap");
  write_inputs(dir);
  const std::string in = quote(dir + "/blob.obj") + " " + quote(dir + "/blob.sphere.obj");
  double psnr[2] = {0, 0};
  const char* modes[2] = {"sampled", "fit"};
  for (int k = 0; k < 2; ++k) {
    const std::string out = dir + "/" + modes[k];
    const CliRun r = run_cli("convert " + in + " -o " + quote(out + ".exr") + " --size 33 --positions " + modes[k] +
                                 " --report " + quote(out + ".json") + " --psnr-samples 50000",
                             cap);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const auto report = nlohmann::json::parse(slurp(out + ".json"));
    CHECK(report.at("positions") == modes[k]);
    psnr[k] = report.at("psnr_db").get<double>();
  }
  CAPTURE(psnr[0], psnr[1]);
  CHECK(psnr[1] > psnr[0] + 3);
  // The default is the fit.
  const CliRun d = run_cli("convert " + in + " -o " + quote(dir + "/default.exr") + " --size 33 --report " +
                               quote(dir + "/default.json") + " --psnr-samples 0",
                           cap);
  REQUIRE(d.exit_code == 0);
  CHECK(nlohmann::json::parse(slurp(dir + "/default.json")).at("positions") == "fit");
  CHECK(slurp(dir + "/default.exr") == slurp(dir + "/fit.exr"));
  // A bad value: usage error, one line, nothing written.
  const CliRun bad = run_cli("convert " + in + " -o " + quote(dir + "/bad.exr") + " --positions nearest", cap);
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("--positions") != std::string::npos);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir + "/bad.exr"));
}
