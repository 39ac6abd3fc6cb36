// The results page (tools/spherekit/site_page.h, linked into this test): the files it writes
// with and without the installed viewer, its tolerance of a sparse or wrong description, and
// the page in a real browser. The browser test makes real inputs with the program (Draco LOD
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

#include "cli_runner.h"
#include "site_page.h"
#include "site_viewer_js.h"
#include "spherekit/formats/atomic_file.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;
using cli::Json;

namespace {

std::string quote(const std::string& s) { return test::shell_quote(s); }

void put(const std::string& path, const std::string& bytes) {
  fs::create_directories(fs::path(path).parent_path());
  REQUIRE(formats::write_file_atomic(path, bytes).ok());
}

std::string be32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

// A w x h RGB PNG (a colour ramp), zlib with stored blocks: enough for <img> and for the page
// writer's size probe, without an encoder library in the test.
std::string small_png(int w, int h) {
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw += '\0';
    for (int x = 0; x < w; ++x) raw += {static_cast<char>(x * 255 / w), static_cast<char>(y * 255 / h), '\x60'};
  }
  std::string z = "\x78\x01";
  for (std::size_t at = 0; at < raw.size(); at += 65535) {
    const std::size_t n = std::min<std::size_t>(65535, raw.size() - at);
    z += static_cast<char>(at + n == raw.size() ? 1 : 0);
    z += {static_cast<char>(n & 255), static_cast<char>(n >> 8), static_cast<char>(~n & 255), static_cast<char>((~n >> 8) & 255)};
    z += raw.substr(at, n);
  }
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  z += be32(b << 16 | a);
  auto chunk = [](const std::string& type, const std::string& data) {
    std::uint32_t crc = 0xffffffffu;
    for (unsigned char c : type + data) {
      crc ^= c;
      for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
    }
    return be32(static_cast<std::uint32_t>(data.size())) + type + data + be32(~crc);
  };
  const std::string ihdr = be32(w) + be32(h) + std::string("\x08\x02\x00\x00\x00", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", z) + chunk("IEND", "");
}

std::string base64_decode(const std::string& s) {
  std::string out;
  unsigned v = 0;
  int bits = 0;
  for (char c : s) {
    int d = c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52
          : c == '+' ? 62 : c == '/' ? 63 : -1;
    if (d < 0) continue;
    v = v << 6 | static_cast<unsigned>(d);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((v >> bits) & 255);
    }
  }
  return out;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// Files left by unfinished atomic writes (".NAME.tmp.PID.N").
int temp_files(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (contains(e.path().filename().string(), ".tmp.")) ++n;
  return n;
}

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

TEST_CASE("results page without the viewer: images and tables, and a note why there is no 3-D view", "[cli]") {
  const std::string out = test::temp_dir("site_page_no_viewer"), nowhere = test::temp_dir("site_page_no_viewer_lib");
  put(out + "/assets/a_gim.png", small_png(65, 65));
  put(out + "/apps/plot.png", small_png(400, 300));
  put(out + "/assets/a_lod0.glb", "glTF not really");
  const Json site = {
      {"title", "Results <1>"},
      {"models", {{{"name", "a"},
                   {"lods", {"assets/a_lod0.glb"}},
                   {"images", {{{"label", "geometry image"}, {"png", "assets/a_gim.png"}},
                               {{"label", "gone"}, {"png", "assets/missing.png"}},
                               {{"label", "outside"}, {"png", "../elsewhere.png"}}}}}}},
      {"morph", {{"glb", "apps/morph.glb"}}},
      {"plots", {{{"label", "PCA error"}, {"png", "apps/plot.png"}}}},
      {"tables", {{{"label", "maps & stretch"},
                   {"columns", {"mesh", "efficiency", "flips", "ok"}},
                   {"rows", {{"a<b>", 0.718123456, 0, true}, {"c", 1e-9, 12, nullptr}}}}}},
      {"viewer_dir", nowhere}};
  std::vector<std::string> warnings;
  REQUIRE(cli::write_site_page(out, site, &warnings).ok());

  const std::string page = test::slurp(out + "/index.html");
  CHECK(contains(page, "<title>Results &lt;1&gt;</title>"));
  CHECK(contains(page, "id=\"no-viewer\""));
  CHECK(contains(page, nowhere));
  // The geometry image enlarged with sharp texels, the plot at its size.
  CHECK(contains(page, "<img src=\"assets/a_gim.png\" alt=\"geometry image\" width=\"260\" height=\"260\" class=\"pixels\">"));
  CHECK(contains(page, "<img src=\"apps/plot.png\" alt=\"PCA error\" width=\"400\" height=\"300\">"));
  CHECK_FALSE(contains(page, "missing.png"));
  CHECK_FALSE(contains(page, "elsewhere.png"));
  CHECK(contains(page, "<h3>maps &amp; stretch</h3>"));
  CHECK(contains(page, "<td>a&lt;b&gt;</td><td class=\"num\">0.718123</td><td class=\"num\">0</td><td>yes</td>"));
  CHECK(contains(page, "<td class=\"num\">1e-09</td><td class=\"num\">12</td><td></td>"));
  CHECK_FALSE(contains(page, "<script"));
  CHECK_FALSE(fs::exists(out + "/site"));
  CHECK(temp_files(out) == 0);

  auto warned = [&](const std::string& part) {
    for (const auto& w : warnings)
      if (contains(w, part)) return true;
    return false;
  };
  CHECK(warned("no 3-D view"));
  CHECK(warned("assets/missing.png: no such file"));
  CHECK(warned("../elsewhere.png: not a path inside"));
  CHECK(warned("apps/morph.glb: no such file"));
}

TEST_CASE("results page with the viewer: scripts, glTF files as base64 scripts, stale scripts removed", "[cli]") {
  const std::string out = test::temp_dir("site_page_viewer"), viewer = test::temp_dir("site_page_viewer_lib");
  // Stand-ins for what scripts/setup_viewer.sh builds (the browser test uses the real ones).
  put(viewer + "/dist/three-viewer.js", "var THREE = {};\n");
  put(viewer + "/dist/draco_decoder.js", "function DracoDecoderModule() {}\n");
  put(viewer + "/dist/NOTICE.txt", "notices\n");
  put(viewer + "/dist/STAMP", "three 0.0.0, esbuild 0.0.0, bundle v1\n");
  std::string glb0, glb1, morph;
  for (int i = 0; i < 1000; ++i) glb0 += static_cast<char>(i * 7 % 256);
  glb1 = glb0.substr(0, 301);  // lengths 1000 and 301 cover both base64 padding cases
  morph = glb0.substr(0, 2);
  put(out + "/assets/a b_lod0.glb", glb0);
  put(out + "/assets/a b_lod1.glb", glb1);
  put(out + "/apps/morph.glb", morph);
  put(out + "/site/glb/999_old.js", "stale");
  const Json site = {{"models", {{{"name", "a b"}, {"lods", {"assets/a b_lod0.glb", "assets/a b_lod1.glb", "assets/gone.glb"}}},
                                 {{"name", "empty"}, {"lods", Json::array()}}}},
                     {"morph", Json::array({{{"glb", "apps/morph.glb"}, {"label", "PCA"}, {"mode", "weights"}}})},
                     {"viewer_dir", viewer}};
  std::vector<std::string> warnings;
  REQUIRE(cli::write_site_page(out, site, &warnings).ok());
  REQUIRE(warnings.size() == 1);
  CHECK(contains(warnings[0], "assets/gone.glb"));

  CHECK(test::slurp(out + "/site/lib/three-viewer.js") == "var THREE = {};\n");
  CHECK(test::slurp(out + "/site/lib/draco_decoder.js") == "function DracoDecoderModule() {}\n");
  CHECK(test::slurp(out + "/site/lib/NOTICE.txt") == "notices\n");
  CHECK(test::slurp(out + "/site/viewer.js") == cli::kSiteViewerJs);
  CHECK_FALSE(fs::exists(out + "/site/glb/999_old.js"));

  const std::string data_js = test::slurp(out + "/site/data.js");
  const std::string prefix = "window.SPHEREKIT_SITE = ";
  REQUIRE(data_js.rfind(prefix, 0) == 0);
  const auto data = nlohmann::json::parse(data_js.substr(prefix.size(), data_js.rfind(';') - prefix.size()));
  REQUIRE(data.at("models").size() == 1);  // "empty" has no level to show
  CHECK(data["models"][0]["name"] == "a b");
  const auto& lods = data["models"][0]["lods"];
  REQUIRE(lods.size() == 2);
  const std::string expected[] = {glb0, glb1};
  for (int k = 0; k < 2; ++k) {
    INFO("level " << k);
    CHECK(lods[k]["bytes"] == expected[k].size());
    const std::string script = test::slurp(out + "/" + lods[k]["script"].get<std::string>());
    const std::string call = "spherekitGlb(\"" + lods[k]["path"].get<std::string>() + "\",\"";
    REQUIRE(script.rfind(call, 0) == 0);
    CHECK(base64_decode(script.substr(call.size(), script.rfind('"') - call.size())) == expected[k]);
  }
  REQUIRE(data.at("morphs").size() == 1);
  CHECK(data["morphs"][0]["mode"] == "weights");
  CHECK(data["morphs"][0]["label"] == "PCA");

  const std::string page = test::slurp(out + "/index.html");
  CHECK(contains(page, "<title>SphereKit results</title>"));
  CHECK(contains(page, "<option value=\"0\">a b</option>"));
  CHECK(contains(page, "id=\"morph-canvas-0\""));
  CHECK(contains(page, "three 0.0.0"));
  // Classic scripts only, in dependency order (file:// pages may not load modules).
  const auto three = page.find("<script src=\"site/lib/three-viewer.js\">"), draco = page.find("site/lib/draco_decoder.js"),
             data_tag = page.find("site/data.js"), app = page.find("site/viewer.js");
  REQUIRE(three != std::string::npos);
  CHECK((three < draco && draco < data_tag && data_tag < app && app != std::string::npos));
  CHECK_FALSE(contains(page, "type=\"module\""));
  CHECK(temp_files(out) == 0);
}

TEST_CASE("results page: a description that is not an object is an invalid argument, an empty one a bare page", "[cli]") {
  const std::string out = test::temp_dir("site_page_bad");
  const Status s = cli::write_site_page(out, Json::array({1, 2}));
  CHECK(s.code() == ErrorCode::InvalidArgument);
  CHECK_FALSE(fs::exists(out + "/index.html"));
  REQUIRE(cli::write_site_page(out, Json::object({{"viewer_dir", out + "/none"}, {"models", "not a list"}})).ok());
  CHECK(contains(test::slurp(out + "/index.html"), "<h1>SphereKit results</h1>"));
}

TEST_CASE("run without meshes: the main job on the built-in samples, its outputs, and its page in headless Chromium",
          "[cli][browser]") {
  // (The sanitizer build skips this case by name: "without meshes".)
  // The viewer and the browser tools first, so that the page gets its 3-D views (idempotent,
  // no network once installed).
  std::string viewer;
  if (const char* env = std::getenv("SPHEREKIT_VIEWER_DIR"); env && *env)
    viewer = env;
  else if (const char* home = std::getenv("HOME"); home && *home)
    viewer = std::string(home) + "/.cache/spherekit/viewer";
  else
    viewer = std::string(SPHEREKIT_BINARY_DIR) + "/viewer";
  const std::string logs = test::temp_dir("site_browser_setup");
  const int setup = test::run_shell("bash " + quote(std::string(SPHEREKIT_SOURCE_DIR) + "/scripts/setup_viewer.sh") + " " +
                                        quote(viewer) + " --browser",
                                    logs + "/out.txt", logs + "/err.txt");
  ::setenv("SPHEREKIT_VIEWER_DIR", viewer.c_str(), 1);

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

  if (setup != 0) {
    // Without the viewer the page says why, and so does the run.
    CHECK(contains(r.err, "warning"));
    WARN("SKIPPED the browser part: it needs node, npm and Chromium; scripts/setup_viewer.sh --browser said: "
         << test::slurp(logs + "/err.txt"));
    return;
  }
  CHECK(r.err.find("warning") == std::string::npos);  // no viewer missing, no file skipped

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
