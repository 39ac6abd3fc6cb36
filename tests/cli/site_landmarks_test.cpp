// Issue 25, the page half: checking and fixing landmarks on the results page in a real browser.
// Two sample meshes without their feature files go through `spherekit run`, which proposes
// landmarks into OUT/landmarks/ and shows them on its page. tests/cli/site_landmarks_check.mjs
// (headless Debian Chromium through playwright-core; the page served on 127.0.0.1 and opened
// from disk) places a landmark by clicking a vertex, turns the view by dragging, moves one,
// renames one (and is refused a name the format cannot hold), downloads the member's .lm.txt
// and then every member's, and shows the other member; this test then reads the download back with `spherekit check --landmarks` against
// the input mesh and compares it with the edits. Skips with a message without node, npm or
// Chromium.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "browser_setup.h"
#include "cli_runner.h"
#include "cli_shorthands.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;
using Json = nlohmann::json;

namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// The longest edge at vertex v: how far a click on the surface may be from the vertex it picks.
double longest_edge_at(const TriMesh& m, int v) {
  double longest = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (m.F(f, c) == v)
        for (int d = 1; d < 3; ++d) longest = std::max(longest, (m.V.row(v) - m.V.row(m.F(f, (c + d) % 3))).norm());
  return longest;
}

Json as_json(const std::vector<Landmark>& l) {
  Json j = Json::array();
  for (const Landmark& x : l) j.push_back({{"name", x.name}, {"vertex", x.vertex}});
  return j;
}

}  // namespace

TEST_CASE("landmark editor on the results page: place, move, rename and download in headless Chromium, "
          "read back by check --landmarks",
          "[cli][browser]") {
  const test::BrowserSetup browser = test::setup_browser_viewer();

  // Two sample meshes without their landmark files: `run` proposes landmarks (OUT/landmarks/).
  const std::string work = test::temp_dir("site_landmarks"), in = work + "/in", out = work + "/out";
  const test::CliRun samples = test::sk("samples -o " + test::q(work + "/samples"), work);
  REQUIRE(samples.exit_code == 0);
  fs::create_directories(in);
  for (const char* name : {"sample_a", "sample_c"})
    fs::copy_file(work + "/samples/" + name + ".obj", in + "/" + name + ".obj");
  const std::string mesh_a = in + "/sample_a.obj";
  const test::CliRun r = test::sk("run -q -o " + test::q(out) + " " + test::q(mesh_a) + " " + test::q(in + "/sample_c.obj"), work);
  INFO("spherekit run stderr:\n" << r.err);
  REQUIRE(r.exit_code == 0);
  const std::string proposed = out + "/landmarks/sample_a.lm.txt";
  REQUIRE(fs::exists(proposed));

  if (!browser.ready)
    SPHEREKIT_SKIP("the landmark editor's browser test: it needs node, npm and Chromium; scripts/setup_viewer.sh --browser said: "
                   << browser.error);
  const std::string page = test::slurp(out + "/index.html");
  CHECK(contains(page, "id=\"landmark-canvas\""));
  CHECK(contains(page, "<script src=\"site/landmarks.js\"></script>"));

  auto mesh = formats::read_mesh(mesh_a);
  REQUIRE(mesh.ok());
  const TriMesh& a = mesh.value();
  auto given = formats::read_landmarks(proposed, static_cast<int>(a.V.rows()));
  REQUIRE(given.ok());
  REQUIRE(given->size() >= 3);  // the check renames the second and tries the third

  const std::string shots = work + "/browser";
  fs::create_directories(shots);
  const int rc = test::run_shell("node " + test::q(std::string(SPHEREKIT_SOURCE_DIR) + "/tests/cli/site_landmarks_check.mjs") +
                                     " " + test::q(browser.viewer) + " " + test::q(out) + " " + test::q(shots),
                                 shots + "/stdout.json", shots + "/stderr.txt");
  INFO("node stderr: " << test::slurp(shots + "/stderr.txt"));
  INFO("report: " << test::slurp(shots + "/stdout.json"));
  REQUIRE(rc == 0);
  const Json report = Json::parse(test::slurp(shots + "/stdout.json"));
  REQUIRE(report.at("modes").size() == 2);
  for (const Json& m : report["modes"]) {
    INFO("mode " << m.at("mode"));
    REQUIRE_FALSE(m.contains("error"));
    CHECK(m.at("console_errors").empty());
    CHECK(m.at("page_errors").empty());
    CHECK(m.at("failed_requests").empty());
    CHECK(m.at("viewer_errors").empty());
    // The member as read from its input file, with the proposed landmarks labelled.
    CHECK(m.at("member") == "sample_a");
    CHECK(m.at("vertices") == a.V.rows());
    CHECK(m.at("initial") == as_json(*given));
    CHECK(m.at("labels") == given->size());
    // Each proposed landmark with the proposal's confidence; the moved one loses it (its point
    // is the user's now), the placed one has none.
    CHECK(m.at("confidences") == given->size());
    CHECK(m.at("confidences_final") == given->size() - 1);

    // Placed at the clicked vertex, which is where the ray met the input mesh: the page's
    // vertex numbers are the input's.
    const Json& placed = m.at("placed");
    const int v1 = placed.at("target").get<int>();
    CHECK(placed.at("vertex") == v1);
    CHECK(placed.at("labels") == given->size() + 1);
    const Eigen::RowVector3d hit(placed["point"][0].get<double>(), placed["point"][1].get<double>(),
                                 placed["point"][2].get<double>());
    const double edge = longest_edge_at(a, v1);
    REQUIRE(edge > 0);
    CHECK((hit - a.V.row(v1)).norm() < 0.1 * edge);
    // A drag turns the view and places nothing.
    CHECK(m.at("drag").at("picks_after") == m["drag"].at("picks_before"));
    CHECK(m["drag"].at("landmarks_after") == m["drag"].at("landmarks_before"));
    CHECK(m["drag"].at("camera_moved").get<double>() > 0);
    // Moved to the second clicked vertex, renamed in place, and a bad name refused.
    const Json& moved = m.at("moved");
    CHECK(moved.at("name") == (*given)[0].name);
    CHECK(moved.at("from") == (*given)[0].vertex);
    CHECK(moved.at("to") == moved.at("target"));
    CHECK(moved.at("to") != moved.at("from"));
    CHECK(m.at("renamed").at("to") == "renamed_on_page");
    CHECK(m["renamed"].at("vertex") == (*given)[1].vertex);
    CHECK(m.at("refused_rename").at("name_after") == (*given)[2].name);
    CHECK(contains(m["refused_rename"].at("status_class").get<std::string>(), "error"));

    // The download, read back by the program against the input mesh.
    const Json& download = m.at("download");
    CHECK(download.at("suggested") == "sample_a.lm.txt");
    CHECK(download.at("failure").is_null());
    const std::string file = download.at("path").get<std::string>();
    REQUIRE(fs::exists(file));
    const test::CliRun checked = test::sk("check " + test::q(mesh_a) + " --landmarks " + test::q(file), work);
    INFO("check: " << checked.out << checked.err);
    CHECK(checked.exit_code == 0);
    CHECK(contains(checked.out, "landmarks: " + std::to_string(given->size() + 1) + " in " + file + ", all valid"));
    auto back = formats::read_landmarks(file, static_cast<int>(a.V.rows()));
    REQUIRE(back.ok());
    CHECK(as_json(*back) == m.at("final"));
    std::vector<Landmark> expected = *given;
    expected[0].vertex = moved.at("target").get<int>();
    expected[1].name = "renamed_on_page";
    expected.push_back({placed.at("name").get<std::string>(), v1});
    CHECK(as_json(*back) == as_json(expected));

    // "download all": every member's file, each accepted against its own input mesh; the
    // edited member's the same as its single download.
    const Json& all = m.at("download_all");
    CHECK(all.at("members") == 2);
    REQUIRE(all.at("files") == Json::array({"sample_a.lm.txt", "sample_c.lm.txt"}));
    const std::string dir = all.at("dir").get<std::string>();
    CHECK(test::slurp(dir + "/sample_a.lm.txt") == test::slurp(file));
    const test::CliRun checked_c =
        test::sk("check " + test::q(in + "/sample_c.obj") + " --landmarks " + test::q(dir + "/sample_c.lm.txt"), work);
    CHECK(checked_c.exit_code == 0);
    auto proposed_c = formats::read_landmarks(out + "/landmarks/sample_c.lm.txt");
    auto all_c = formats::read_landmarks(dir + "/sample_c.lm.txt");
    REQUIRE(proposed_c.ok());
    REQUIRE(all_c.ok());
    CHECK(as_json(*all_c) == as_json(*proposed_c));  // not edited
    // The other member shown as its own mesh with its own landmarks.
    const Json& second = m.at("second");
    CHECK(second.at("member") == "sample_c");
    auto mesh_c = formats::read_mesh(in + "/sample_c.obj");
    REQUIRE(mesh_c.ok());
    CHECK(second.at("vertices") == mesh_c->V.rows());
    CHECK(second.at("landmarks") == as_json(*proposed_c));
    CHECK(second.at("labels") == proposed_c->size());
  }
}
