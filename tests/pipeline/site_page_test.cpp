// The results page writer of spherekit::pipeline (spherekit/pipeline/site_page.h): the files
// it writes with and without the installed viewer, its tolerance of a sparse or wrong
// description, and the embedded viewer.js being the source tree's file. The page in a real
// browser is tests/cli/site_browser_test.cpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "spherekit/pipeline/site_page.h"
#include "spherekit/formats/atomic_file.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;
using pipeline::Json;

namespace {

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

}  // namespace

TEST_CASE("results page without the viewer: images and tables, and a note why there is no 3-D view", "[pipeline]") {
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
  REQUIRE(pipeline::write_site_page(out, site, &warnings).ok());

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

TEST_CASE("results page with the viewer: scripts, glTF files as base64 scripts, stale scripts removed", "[pipeline]") {
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
  REQUIRE(pipeline::write_site_page(out, site, &warnings).ok());
  REQUIRE(warnings.size() == 1);
  CHECK(contains(warnings[0], "assets/gone.glb"));

  CHECK(test::slurp(out + "/site/lib/three-viewer.js") == "var THREE = {};\n");
  CHECK(test::slurp(out + "/site/lib/draco_decoder.js") == "function DracoDecoderModule() {}\n");
  CHECK(test::slurp(out + "/site/lib/NOTICE.txt") == "notices\n");
  CHECK(test::slurp(out + "/site/viewer.js") == test::slurp(SPHEREKIT_SOURCE_DIR "/pipeline/site/viewer.js"));
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

TEST_CASE("results page: a description that is not an object is an invalid argument, an empty one a bare page", "[pipeline]") {
  const std::string out = test::temp_dir("site_page_bad");
  const Status s = pipeline::write_site_page(out, Json::array({1, 2}));
  CHECK(s.code() == ErrorCode::InvalidArgument);
  CHECK_FALSE(fs::exists(out + "/index.html"));
  REQUIRE(pipeline::write_site_page(out, Json::object({{"viewer_dir", out + "/none"}, {"models", "not a list"}})).ok());
  CHECK(contains(test::slurp(out + "/index.html"), "<h1>SphereKit results</h1>"));
}

TEST_CASE("results page: the landmark editor's meshes as scripts in the input's vertex numbering, its landmarks, "
          "unreadable files", "[pipeline]") {
  const std::string out = test::temp_dir("site_page_landmarks"), viewer = test::temp_dir("site_page_landmarks_lib");
  const std::string in = test::temp_dir("site_page_landmarks_in");
  put(viewer + "/dist/three-viewer.js", "var THREE = {};\n");
  put(viewer + "/dist/draco_decoder.js", "function DracoDecoderModule() {}\n");
  // A tetrahedron far from the origin (the page gets positions minus the box centre), with
  // its faces in an order the file gives and no reader should change.
  put(in + "/tet.obj", "v 1000 0 0\nv 1001 0 0\nv 1000 1 0\nv 1000 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  put(in + "/tet.lm.txt", "# two\ntip 3\nbase 0\n");
  put(in + "/bad.lm.txt", "tip 7\n");
  put(out + "/site/mesh/777_old.js", "stale");
  const Json site = {{"viewer_dir", viewer},
                     {"landmarks",
                      {{"members",
                        {{{"name", "tet"}, {"mesh", in + "/tet.obj"}, {"features", in + "/tet.lm.txt"}, {"source", "given"},
                          {"confidence", {{"tip", 0.25}, {"base", "not a number"}}}, {"note", "left/right undecided"}},
                         {{"name", "none yet"}, {"mesh", in + "/tet.obj"}},
                         {{"name", "bad file"}, {"mesh", in + "/tet.obj"}, {"features", in + "/bad.lm.txt"}},
                         {{"name", "gone"}, {"mesh", in + "/gone.obj"}}}}}}};
  std::vector<std::string> warnings;
  REQUIRE(pipeline::write_site_page(out, site, &warnings).ok());
  REQUIRE(warnings.size() == 1);  // the mesh that cannot be read
  CHECK(contains(warnings[0], in + "/gone.obj"));
  CHECK_FALSE(fs::exists(out + "/site/mesh/777_old.js"));
  CHECK(test::slurp(out + "/site/landmarks.js") == test::slurp(SPHEREKIT_SOURCE_DIR "/pipeline/site/landmarks.js"));

  const std::string data_js = test::slurp(out + "/site/data.js");
  const std::string prefix = "window.SPHEREKIT_SITE = ";
  REQUIRE(data_js.rfind(prefix, 0) == 0);
  const auto data = nlohmann::json::parse(data_js.substr(prefix.size(), data_js.rfind(';') - prefix.size()));
  const auto& members = data.at("landmarks");
  REQUIRE(members.size() == 3);
  CHECK(members[0]["name"] == "tet");
  CHECK(members[0]["file"] == "tet.lm.txt");
  CHECK(members[0]["source"] == "given");
  CHECK(members[0]["vertices"] == 4);
  CHECK(members[0]["triangles"] == 4);
  CHECK(members[0]["landmarks"] == nlohmann::json::parse(R"([{"name":"tip","vertex":3},{"name":"base","vertex":0}])"));
  CHECK_FALSE(members[0].contains("error"));
  CHECK(members[0]["confidence"] == nlohmann::json::parse(R"({"tip":0.25})"));
  CHECK(members[0]["note"] == "left/right undecided");
  CHECK_FALSE(members[1].contains("confidence"));
  CHECK_FALSE(members[1].contains("note"));
  CHECK(members[1]["landmarks"].empty());
  CHECK_FALSE(members[1].contains("error"));
  CHECK(members[2]["landmarks"].empty());
  CHECK(contains(members[2].at("error").get<std::string>(), in + "/bad.lm.txt"));

  // The script's bytes: #V, #F, positions minus the offset (float32), the faces as in the file.
  const auto& script_entry = members[0].at("mesh");
  const std::string script = test::slurp(out + "/" + script_entry.at("script").get<std::string>());
  const std::string call = "spherekitMesh(\"" + script_entry.at("path").get<std::string>() + "\",\"";
  REQUIRE(script.rfind(call, 0) == 0);
  const std::string bytes = base64_decode(script.substr(call.size(), script.rfind('"') - call.size()));
  REQUIRE(bytes.size() == 8 + 12 * 4 + 12 * 4);
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 3; k >= 0; --k) v = v << 8 | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  auto f32 = [&](std::size_t at) {
    const std::uint32_t v = u32(at);
    float f;
    std::memcpy(&f, &v, sizeof f);
    return static_cast<double>(f);
  };
  CHECK(u32(0) == 4);
  CHECK(u32(4) == 4);
  const double file_v[4][3] = {{1000, 0, 0}, {1001, 0, 0}, {1000, 1, 0}, {1000, 0, 1}};
  const auto& offset = members[0].at("offset");
  CHECK(offset[0].get<double>() == 1000.5);
  for (int v = 0; v < 4; ++v)
    for (int c = 0; c < 3; ++c) CHECK(f32(8 + 12 * v + 4 * c) + offset[c].get<double>() == file_v[v][c]);
  const std::uint32_t file_f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (int f = 0; f < 4; ++f)
    for (int c = 0; c < 3; ++c) CHECK(u32(8 + 48 + 12 * f + 4 * c) == file_f[f][c]);

  const std::string page = test::slurp(out + "/index.html");
  CHECK(contains(page, "<option value=\"1\">none yet</option>"));
  CHECK(contains(page, "<script src=\"site/landmarks.js\"></script>"));
  CHECK(page.find("site/viewer.js") < page.find("site/landmarks.js"));

  // Without the viewer: no editor, and the note says why there is no 3-D view.
  const std::string bare = test::temp_dir("site_page_landmarks_bare");
  Json no_viewer = site;
  no_viewer["viewer_dir"] = bare + "/none";
  REQUIRE(pipeline::write_site_page(bare, no_viewer).ok());
  CHECK(contains(test::slurp(bare + "/index.html"), "id=\"no-viewer\""));
  CHECK_FALSE(contains(test::slurp(bare + "/index.html"), "landmark-canvas"));
  CHECK_FALSE(fs::exists(bare + "/site/mesh"));
}
