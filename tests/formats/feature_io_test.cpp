// Landmark and sphere-point files: round trips, comments, every rejected line, real sidecars.
#include "spherekit/formats/feature_io.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "spherekit/formats/mesh_io.h"
#include "test_paths.h"

namespace {

namespace fs = std::filesystem;
using namespace spherekit;
using namespace spherekit::formats;

std::string write_feature_file(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::error_code ec;
  fs::remove(path, ec);  // replace, not truncate (see mesh_io_test.cpp)
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

/// Expects an error with `code` whose single-line message starts with "path:line:" and
/// contains `word`.
template <class T>
void check_error(const Result<T>& r, ErrorCode code, const std::string& path, int line, const std::string& word) {
  INFO("message: " << r.status().message());
  REQUIRE_FALSE(r.ok());
  CHECK(r.status().code() == code);
  CHECK(r.status().message().rfind(path + ":" + std::to_string(line) + ": ", 0) == 0);
  CHECK(r.status().message().find(word) != std::string::npos);
  CHECK(r.status().message().find('\n') == std::string::npos);
}

}  // namespace

TEST_CASE("landmarks: round trip, comments and blank lines", "[formats]") {
  const std::string dir = test::temp_dir("formats_landmarks");
  const std::vector<Landmark> marks = {{"nose", 12}, {"left_ear", 0}, {"tail-tip.2", 99}};
  const std::string path = dir + "/m.lm.txt";
  REQUIRE(write_landmarks(path, marks).ok());
  Result<std::vector<Landmark>> back = read_landmarks(path, 100);
  REQUIRE(back.ok());
  REQUIRE(back->size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK((*back)[i].name == marks[i].name);
    CHECK((*back)[i].vertex == marks[i].vertex);
  }

  const std::string hand = write_feature_file(dir, "hand.lm.txt", "# header\n\n  nose 3   # the tip\r\n\tchin +4\n   \n");
  Result<std::vector<Landmark>> h = read_landmarks(hand);
  REQUIRE(h.ok());
  REQUIRE(h->size() == 2);
  CHECK((*h)[0].name == "nose");
  CHECK((*h)[1].vertex == 4);
  CHECK(read_landmarks(write_feature_file(dir, "none.lm.txt", "# nothing\n"))->empty());
}

TEST_CASE("landmarks: rejected lines name file and line", "[formats]") {
  const std::string dir = test::temp_dir("formats_landmarks_errors");
  const std::string head = "# landmarks\na 1\n";  // the bad line is line 3
  auto read = [&](const std::string& bad, int num_vertices = 10) {
    return read_landmarks(write_feature_file(dir, "f.lm.txt", head + bad + "\n"), num_vertices);
  };
  const std::string path = dir + "/f.lm.txt";
  check_error(read("b"), ErrorCode::ParseError, path, 3, "got 1 fields");
  check_error(read("b 2 3"), ErrorCode::ParseError, path, 3, "got 3 fields");
  check_error(read("b two"), ErrorCode::ParseError, path, 3, "not an integer");
  check_error(read("b 2.5"), ErrorCode::ParseError, path, 3, "not an integer");
  check_error(read("b -2"), ErrorCode::InvalidInput, path, 3, "negative");
  check_error(read("b 10"), ErrorCode::InvalidInput, path, 3, "out of range (10 vertices)");
  check_error(read("b 99999999999", -1), ErrorCode::InvalidInput, path, 3, "out of range");
  check_error(read("a 2"), ErrorCode::InvalidInput, path, 3, "duplicate landmark name 'a' (first on line 2)");
  check_error(read("b 1"), ErrorCode::InvalidInput, path, 3, "vertex 1, already used by 'a'");
  CHECK(read("b 10", -1).ok());  // no mesh given: no range check

  Result<std::vector<Landmark>> missing = read_landmarks(dir + "/absent.lm.txt");
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.status().code() == ErrorCode::IoError);
  CHECK(missing.status().message().find("absent.lm.txt") != std::string::npos);

  Status bad_name = write_landmarks(dir + "/w.lm.txt", {{"two words", 1}});
  CHECK(bad_name.code() == ErrorCode::InvalidInput);
  CHECK(write_landmarks(dir + "/w.lm.txt", {{"ok", -1}}).code() == ErrorCode::InvalidInput);
  CHECK_FALSE(fs::exists(dir + "/w.lm.txt"));
}

TEST_CASE("landmarks: the shared families' sidecar files", "[formats]") {
  SPHEREKIT_REQUIRE_SHARED_MESHES(meshes);
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(meshes + "/families")) {
    const std::string p = entry.path().string();
    if (p.size() < 7 || p.substr(p.size() - 7) != ".lm.txt") continue;
    const std::string mesh_path = p.substr(0, p.size() - 7) + ".obj";
    Result<TriMesh> mesh = read_mesh(mesh_path);
    REQUIRE(mesh.ok());
    Result<std::vector<Landmark>> marks = read_landmarks(p, static_cast<int>(mesh->V.rows()));
    INFO(p << ": " << marks.status().message());
    REQUIRE(marks.ok());
    CHECK(marks->size() >= 8);
    ++files;
  }
  CHECK(files > 0);
}

TEST_CASE("sphere points: exact round trip and normalisation", "[formats]") {
  const std::string dir = test::temp_dir("formats_sphere_points");
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss;
  std::vector<SpherePoint> points;
  for (int i = 0; i < 50; ++i) {
    SpherePoint sp;
    sp.name = "p" + std::to_string(i);
    sp.p = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    points.push_back(sp);
  }
  points.push_back({"pole", Eigen::Vector3d(0, 0, -1)});
  const std::string path = dir + "/pts.txt";
  REQUIRE(write_sphere_points(path, points).ok());
  for (bool require_unit : {false, true}) {
    Result<std::vector<SpherePoint>> back = read_sphere_points(path, require_unit);
    REQUIRE(back.ok());
    REQUIRE(back->size() == points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      CHECK((*back)[i].name == points[i].name);
      CHECK((*back)[i].p == points[i].p);  // bit-exact
    }
  }

  const std::string loose = write_feature_file(dir, "loose.txt", "# comment\na 2 0 0\n\nb 0 3 4 # five\n");
  Result<std::vector<SpherePoint>> n = read_sphere_points(loose);
  REQUIRE(n.ok());
  CHECK((*n)[0].p == Eigen::Vector3d(1, 0, 0));
  CHECK(((*n)[1].p - Eigen::Vector3d(0, 0.6, 0.8)).norm() < 1e-15);
  check_error(read_sphere_points(loose, true), ErrorCode::InvalidInput, loose, 2, "length 2");
}

TEST_CASE("sphere points: huge and subnormal points become unit vectors", "[formats]") {
  // Fuzzing finding (fuzz_sphere_points): |p|^2 overflowed for p = (1e303, 0, 999999), so the
  // point was divided by inf and returned as the zero vector; subnormal points lost their
  // precision in |p|. Both must come back as unit vectors pointing the same way.
  const std::string dir = test::temp_dir("formats_sphere_points_range");
  const std::string path =
      write_feature_file(dir, "range.txt", "big 1e303 0 999999\nhuge 1.7e308 -1.7e308 1.7e308\ntiny 1e-320 1e-320 0\n");
  for (bool require_unit : {false, true}) {
    Result<std::vector<SpherePoint>> r = read_sphere_points(path, require_unit);
    if (require_unit) {
      check_error(r, ErrorCode::InvalidInput, path, 1, "has length 1e+303, not 1");
      continue;
    }
    REQUIRE(r.ok());
    REQUIRE(r->size() == 3);
    for (const SpherePoint& p : *r) {
      INFO(p.name);
      CHECK(std::abs(p.p.norm() - 1) < 1e-15);
    }
    CHECK((*r)[0].p.x() == 1.0);
    CHECK(((*r)[1].p - Eigen::Vector3d(1, -1, 1) / std::sqrt(3.0)).norm() < 1e-15);
    CHECK(((*r)[2].p - Eigen::Vector3d(1, 1, 0) / std::sqrt(2.0)).norm() < 1e-3);  // the input has few bits
  }
}

TEST_CASE("landmark targets: unit vectors, ranges and duplicates", "[formats]") {
  const std::string dir = test::temp_dir("formats_landmark_targets");
  const std::string good = write_feature_file(dir, "t.txt", "# name vertex x y z\nnose 3 0 0 1\ntail 0 0.577 0.577 0.577\n");
  Result<std::vector<formats::LandmarkTarget>> r = read_landmark_targets(good, 4);
  REQUIRE(r.ok());
  REQUIRE(r->size() == 2);
  CHECK((*r)[0].name == "nose");
  CHECK((*r)[0].vertex == 3);
  CHECK((*r)[0].p == Eigen::Vector3d(0, 0, 1));
  CHECK(std::abs((*r)[1].p.norm() - 1) < 1e-15);  // 3-decimal input within kTargetUnitTolerance

  const std::string path = dir + "/b.txt";
  auto read = [&](const std::string& bad, int num_vertices = 4) {
    return read_landmark_targets(write_feature_file(dir, "b.txt", "a 0 1 0 0\n" + bad + "\n"), num_vertices);
  };
  check_error(read("b 1 0 1"), ErrorCode::ParseError, path, 2, "got 4 fields");
  check_error(read("b one 0 1 0"), ErrorCode::ParseError, path, 2, "is not an integer");
  check_error(read("b 1 0 x 0"), ErrorCode::ParseError, path, 2, "bad number 'x'");
  check_error(read("b -1 0 1 0"), ErrorCode::InvalidInput, path, 2, "negative vertex index -1");
  check_error(read("b 4 0 1 0"), ErrorCode::InvalidInput, path, 2, "out of range (4 vertices)");
  check_error(read("b 99999999999 0 1 0", -1), ErrorCode::InvalidInput, path, 2, "out of range");
  check_error(read("b 1 nan 1 0"), ErrorCode::InvalidInput, path, 2, "not finite");
  check_error(read("b 1 0 2 0"), ErrorCode::InvalidInput, path, 2, "has length 2, not 1");
  check_error(read("b 1 0 0.99 0"), ErrorCode::InvalidInput, path, 2, "has length 0.99, not 1");
  check_error(read("b 1 1e303 0 0"), ErrorCode::InvalidInput, path, 2, "has length 1e+303, not 1");
  check_error(read("b 1 0 0 0"), ErrorCode::InvalidInput, path, 2, "has length 0, not 1");
  check_error(read("a 1 0 1 0"), ErrorCode::InvalidInput, path, 2, "duplicate target name 'a'");
  check_error(read("b 0 0 1 0"), ErrorCode::InvalidInput, path, 2, "uses vertex 0, already targeted on line 1");
}

TEST_CASE("sphere points: rejected lines name file and line", "[formats]") {
  const std::string dir = test::temp_dir("formats_sphere_points_errors");
  const std::string path = dir + "/s.txt";
  auto read = [&](const std::string& bad) {
    return read_sphere_points(write_feature_file(dir, "s.txt", "a 1 0 0\n" + bad + "\n"));
  };
  check_error(read("b 0 1"), ErrorCode::ParseError, path, 2, "got 3 fields");
  check_error(read("b 0 1 0 0"), ErrorCode::ParseError, path, 2, "got 5 fields");
  check_error(read("b 0 one 0"), ErrorCode::ParseError, path, 2, "bad number 'one'");
  check_error(read("b nan 1 0"), ErrorCode::InvalidInput, path, 2, "not finite");
  check_error(read("b 0 -inf 0"), ErrorCode::InvalidInput, path, 2, "not finite");
  check_error(read("b 0 1e400 0"), ErrorCode::InvalidInput, path, 2, "not finite");
  check_error(read("b 0 0 0"), ErrorCode::InvalidInput, path, 2, "zero length");
  check_error(read("a 0 1 0"), ErrorCode::InvalidInput, path, 2, "duplicate point name 'a'");
  CHECK(write_sphere_points(dir + "/w.txt", {{"", Eigen::Vector3d(1, 0, 0)}}).code() == ErrorCode::InvalidInput);
}
