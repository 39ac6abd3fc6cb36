// The results page of `spherekit run` (written by spherekit::pipeline, site_page.h) and the
// page in a real browser. The browser test makes real inputs with the program (Draco LOD
// glTF files from `convert --lods`, a morph glTF and a plot from `morph` and `pca` over a
// consistent collection), installs the viewer with scripts/setup_viewer.sh --browser, and runs
// tests/cli/site_browser_check.mjs: headless Debian Chromium (playwright-core), the page served
// on 127.0.0.1 and opened from disk. It skips with a message when node, npm or Chromium is
// unavailable.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "browser_setup.h"
#include "cli_runner.h"
#include "spherekit/formats/atomic_file.h"
#include "test_paths.h"
#include "cli_shorthands.h"

namespace fs = std::filesystem;
using namespace spherekit;
using Json = nlohmann::ordered_json;

namespace {

using spherekit::test::quote;
bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// What the main job must have written (README): per mesh its map, geometry image (PSNR,
// previews, LODs); the consistent collection and its correspondence against the samples'
// ground truth; the converted assets (every member with the same layout) and the
// applications' folders.
void check_main_job_outputs(const std::string& out) {
  const Json report = Json::parse(test::slurp(out + "/report.json"));
  REQUIRE(report["meshes"].size() >= 2);
  for (const Json& m : report["meshes"]) {
    INFO(m.dump());
    CHECK(m["status"] == "ok");
    CHECK(m["eval"]["flipped"] == 0);
    CHECK(m["eval"]["flipped_exact"] == 0);
    CHECK(fs::exists(m["sphere_map"].get<std::string>()));
    const Json& gim = m["geometry_image"];
    CHECK(gim["size"] == 129);
    const std::string gim_file = gim["file"].get<std::string>();
    CHECK(fs::path(gim_file).filename().string() == m["name"].get<std::string>() + ".gim129.exr");
    CHECK(fs::equivalent(fs::path(gim_file).parent_path(), fs::path(out)));
    CHECK(fs::exists(gim_file));
    REQUIRE(gim["psnr_db"].is_number());
    CHECK(gim["psnr_db"].get<double>() > 30);
    REQUIRE(gim["previews"].size() == 2);
    for (const Json& p : gim["previews"]) CHECK(fs::file_size(p.get<std::string>()) > 100);
    REQUIRE(gim["lods"].size() == 3);
    for (const Json& p : gim["lods"]) CHECK(fs::exists(p.get<std::string>()));
  }
  CHECK(fs::is_directory(out + "/input"));
  CHECK(fs::exists(out + "/collection/collection.json"));
  REQUIRE(report.contains("collection"));
  const Json& col = report["collection"];
  INFO(col.dump());
  CHECK(col["pairs"] == report["meshes"].size() * (report["meshes"].size() - 1));
  CHECK(col["mean_error"].get<double>() < 0.05);
  CHECK(col["under_0.1"].get<double>() > 0.9);
  CHECK(report["summary"]["collection"] == true);
  // Assets: every member converted, all with one layout (same vertex count in every LOD0).
  REQUIRE(report.contains("assets"));
  const Json& assets = report["assets"];
  REQUIRE(assets["members"].size() == report["meshes"].size());
  for (const Json& m : assets["members"]) {
    INFO(m.dump());
    for (const char* f : {"_normals.png", "_positions.png", "_cage.obj", "_disp.exr", "_lod0.glb", "_lod2.glb"})
      CHECK(fs::exists(out + "/assets/" + m["name"].get<std::string>() + f));
    CHECK(m["cage"]["psnr_db"].get<double>() > m["cage"]["psnr_db_limit"].get<double>());
  }
  CHECK(fs::exists(out + "/assets/collection_morph.glb"));
  // Applications: the colour round trip comes back close; morph and PCA folders complete.
  CHECK(report["transfer"]["round_trip_mean_color_error"].get<double>() < 0.05);
  CHECK(fs::exists(out + "/apps/morph/morph.glb"));
  CHECK(fs::exists(out + "/apps/pca/pca.glb"));
  CHECK(fs::exists(out + "/apps/pca/pca_errors.png"));
  const Json& errors = report["pca"]["errors"];
  REQUIRE(errors.size() >= 2);
  // With all components every member is reconstructed to float precision.
  CHECK(errors.back()["max_rms"].get<double>() < 1e-4);
}

}  // namespace

TEST_CASE("run without meshes: the main job on the built-in samples, its outputs, and its page in headless Chromium",
          "[cli][browser]") {
  // (The sanitizer build skips this case by name: "without meshes".)
  // The viewer and the browser tools first, so that the page gets its 3-D views (idempotent,
  // no network once installed).
  const test::BrowserSetup browser = test::setup_browser_viewer();
  const std::string& viewer = browser.viewer;

  // The README's main job: the samples mapped, mapped consistently, converted, and
  // transfer, morph and pca run on them; report.json and index.html.
  const std::string out = test::temp_dir("cli_run_samples") + "/spherekit-out", cap = test::temp_dir("cli_run_capture");
  const test::CliRun r = test::run_cli(SPHEREKIT_EXE, "run -q -o " + quote(out), cap);
  INFO("spherekit run stderr:\n" << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("PSNR129") != std::string::npos);
  check_main_job_outputs(out);
  const Json run_report = Json::parse(test::slurp(out + "/report.json"));
  const std::size_t members = run_report["meshes"].size();
  const std::string page = test::slurp(out + "/index.html");
  CHECK(contains(page, "SphereKit results"));

  if (!browser.ready) {
    // Without the viewer the page says why, and so does the run.
    CHECK(contains(r.err, "warning"));
    SPHEREKIT_SKIP("the browser part: it needs node, npm and Chromium; scripts/setup_viewer.sh --browser said: "
                   << browser.error);
  }
  CHECK(r.err.find("warning") == std::string::npos);  // no viewer missing, no file skipped
  // The landmark editor (issue 25; driven in site_landmarks_test.cpp) is on the page, with the
  // samples' own landmark files; the checks below see its script run without errors.
  CHECK(contains(page, "id=\"landmark-canvas\""));
  CHECK(contains(test::slurp(out + "/site/data.js"), "\"source\":\"given: " + out + "/input/sample_a.lm.txt\""));

  const std::string shots = test::temp_dir("site_browser_shots");
  const int rc = test::run_shell("node " + quote(std::string(SPHEREKIT_SOURCE_DIR) + "/tests/cli/site_browser_check.mjs") + " " +
                                     quote(viewer) + " " + quote(out) + " " + quote(shots),
                                 shots + "/stdout.json", shots + "/stderr.txt");
  INFO("node stderr: " << test::slurp(shots + "/stderr.txt"));
  INFO("report: " << test::slurp(shots + "/stdout.json"));
  REQUIRE(rc == 0);
  const auto report = nlohmann::json::parse(test::slurp(shots + "/stdout.json"));
  REQUIRE(report.at("modes").size() == 2);
  for (const auto& m : report["modes"]) {
    INFO("mode " << m.at("mode") << ": " << m.dump(1));
    CHECK_FALSE(m.contains("error"));
    CHECK(m.at("console_errors").empty());
    CHECK(m.at("page_errors").empty());
    CHECK(m.at("failed_requests").empty());
    CHECK(m.at("viewer_errors").empty());
    // Per model two previews, plus the plots (normal map, PCA error, compression).
    CHECK(m.at("images").get<std::size_t>() >= 2 * members + 2);
    CHECK(m.at("broken_images").empty());
    CHECK(m.at("tables") == 5);  // maps, correspondence, assets, transfer, PCA
    REQUIRE(m.at("models").size() == members);
    for (const auto& model : m["models"]) {
      REQUIRE(model.at("lods").size() == 3);
      double previous = 1e18;
      for (const auto& lod : model["lods"]) {
        // The model fills a good part of the canvas at every level, each coarser than the last.
        CHECK(lod.at("coverage").get<double>() > 0.1);
        CHECK(lod.at("triangles").get<double>() < previous);
        previous = lod["triangles"].get<double>();
      }
    }
    // "auto": the finest level when framed, a coarser one once zoomed out.
    CHECK(m.at("auto_lod").at("before") == 0);
    CHECK(m.at("auto_lod").at("after_zoom_out").get<int>() > 0);
    // The shared texture on every member and on all of them side by side: the grid changes a
    // good part of each model's pixels against the grey render; each model on its sphere
    // covers the canvas too and differs from the model.
    REQUIRE(m.at("textures").size() == members + (members > 1 ? 1 : 0));
    for (const auto& t : m["textures"]) {
      INFO("texture on model " << t.at("model"));
      CHECK(t.at("coverage_plain").get<double>() > 0.02);
      CHECK(t.at("changed_fraction").get<double>() > 0.3 * t.at("coverage_plain").get<double>());
      CHECK(t.at("coverage_sphere").get<double>() > 0.02);
      CHECK(t.at("sphere_changed_fraction").get<double>() > 0.01);
    }
    REQUIRE(m.at("morphs").size() == 3);  // members as targets, the morph, the PCA
    for (const auto& morph : m["morphs"]) {
      CHECK(morph.at("targets").get<int>() >= 1);
      CHECK(morph.at("coverage_start").get<double>() > 0.1);
      CHECK(morph.at("coverage_end").get<double>() > 0.1);
      // The two ends of the slider are different shapes.
      CHECK(morph.at("changed_fraction").get<double>() > 0.005);
    }
  }
}
