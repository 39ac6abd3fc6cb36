// End-to-end tests of `spherekit convert --lods`: the files, the report (sizes and PSNR per
// level), and a bad --lods is a usage error that writes nothing.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "gltf_test_support.h"
#include "test_paths.h"
#include "cli_shorthands.h"

namespace fs = std::filesystem;
using namespace spherekit;

namespace {

using spherekit::test::quote;

}  // namespace

TEST_CASE("spherekit convert --lods writes Draco glTF levels and reports their sizes and PSNRs", "[convert]") {
  const std::string dir = test::temp_dir("convert_cli_gltf"), cap = test::temp_dir("convert_cli_gltf_capture");
  test::write_blob_inputs(dir);
  const test::CliRun r = test::run_cli(SPHEREKIT_EXE,
                                       "convert " + quote(dir + "/blob.obj") + " " + quote(dir + "/blob.sphere.obj") +
                                           " -o " + quote(dir + "/blob.exr") + " --gi 33 --lods 3 --lod-mode uniform --report " +
                                           quote(dir + "/blob.json") + " --psnr-samples 20000",
                                       cap);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("blob_lods.glb") != std::string::npos);
  const auto report = nlohmann::json::parse(test::slurp(dir + "/blob.json"));
  const auto& levels = report.at("lods");
  REQUIRE(levels.size() == 3);
  double previous_psnr = 1e9;
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("level " << k);
    const auto& l = levels[k];
    const std::string file = dir + "/blob_lod" + std::to_string(k) + ".glb";
    CHECK(l.at("file") == file);
    CHECK(l.at("size") == (32 >> k) + 1);
    REQUIRE(fs::exists(file));
    CHECK(l.at("bytes").get<std::uintmax_t>() == fs::file_size(file));
    // The PSNR of the decoded glTF falls with the level and stays near the image's at level 0.
    const double psnr = l.at("psnr_db").get<double>();
    CHECK(psnr < previous_psnr);
    previous_psnr = psnr;
    const auto decoded = test::decode_and_check_draco(test::parse_glb(test::slurp(file)));
    REQUIRE(decoded.size() == 1);
    CHECK(decoded[0].F.rows() == l.at("F").get<Eigen::Index>());
  }
  CHECK(levels[0].at("psnr_db").get<double>() > report.at("psnr_db").get<double>() - 0.5);
  CHECK(report.at("lods_file").at("file") == dir + "/blob_lods.glb");
  CHECK(report.at("lods_file").at("bytes").get<std::uintmax_t>() == fs::file_size(dir + "/blob_lods.glb"));
  // The budget came from the measured remesh error.
  CHECK(report.at("quantization").at("reference_rms_error").get<double>() == report.at("rms").get<double>());
  CHECK(report.at("quantization").at("position_bits").get<int>() >= 14);
  const auto combined = test::parse_glb(test::slurp(dir + "/blob_lods.glb"));
  CHECK(test::decode_and_check_draco(combined).size() == 3);
}

TEST_CASE("spherekit convert: --lods that do not fit --gi are a usage error and write nothing", "[convert]") {
  const std::string dir = test::temp_dir("convert_cli_gltf_bad"), cap = test::temp_dir("convert_cli_gltf_bad_capture");
  test::write_blob_inputs(dir);
  const test::CliRun r = test::run_cli(SPHEREKIT_EXE,
                                       "convert " + quote(dir + "/blob.obj") + " " + quote(dir + "/blob.sphere.obj") +
                                           " -o " + quote(dir + "/blob.exr") + " --gi 33 --lods 6",
                                       cap);
  CHECK(r.exit_code == 2);
  CHECK(r.err.rfind("spherekit: error: ", 0) == 0);
  CHECK(r.err.find("--lods 6") != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  CHECK(files == 2);  // only the inputs
}
