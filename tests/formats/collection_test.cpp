// The collection folder format against formats alone (no command line): a folder made from a
// typed manifest reads back as the same manifest and bytes, the validation refuses what the
// commands cannot use, members load with their maps, and the staged folder writer leaves the
// target untouched on failure or cancellation.
#include <catch2/catch.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/formats/text_formats.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;
using formats::OrderedJson;

namespace {

// The octahedron is its own sphere map (its vertices are unit vectors).
formats::CollectionManifest two_member_manifest() {
  formats::CollectionManifest m;
  m.library_version = "test";
  m.method = "consistent (steps 1-6)";
  m.reference = "a";
  m.features.push_back({"top", Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1)});
  m.features.push_back({"side", Eigen::Vector3d(1, 0, 0), std::nullopt});
  for (const char* name : {"a", "b"}) {
    formats::CollectionMember e;
    e.name = name;
    e.map = std::string(name) + ".sphere.obj";
    e.vertices = 6;
    e.faces = 8;
    e.feature_vertices = std::vector<long long>{4, 0};
    e.added = false;
    e.result = OrderedJson{{"efficiency", 0.5}, {"times", {{"total", 1.25}}}};
    m.members.push_back(std::move(e));
  }
  m.options = OrderedJson{{"seed", 7}, {"remesh_size", 65}};
  m.extra["steps"] = OrderedJson{{"joint_efficiency", 0.25}};
  return m;
}

// A complete folder: manifest, features.txt and one map per member, with the meshes beside it.
std::string make_folder(const std::string& name, formats::CollectionManifest m) {
  const std::string dir = test::temp_dir(name);
  const TriMesh mesh = test::octahedron();
  for (formats::CollectionMember& e : m.members) {
    const std::string src = dir + "/" + e.name + ".obj";
    REQUIRE(formats::write_mesh(src, mesh).ok());
    e.source = src;
    SphereMap map;
    map.S = mesh.V;
    REQUIRE(formats::write_sphere_map(dir + "/" + e.map, mesh, map).ok());
  }
  REQUIRE(formats::write_file_atomic(dir + "/features.txt", formats::sphere_points_text(m.feature_names(), m.locations())).ok());
  REQUIRE(formats::write_file_atomic(dir + "/collection.json", formats::collection_manifest_text(m)).ok());
  return dir;
}

std::string manifest_with(const std::function<void(OrderedJson&)>& edit) {
  OrderedJson j = formats::collection_manifest_json(two_member_manifest());
  edit(j);
  return j.dump(2);
}

}  // namespace

TEST_CASE("collection manifest: written, read back and written again gives the same bytes", "[formats][collection]") {
  const formats::CollectionManifest m = two_member_manifest();
  const std::string text = formats::collection_manifest_text(m);
  auto parsed = formats::parse_collection_manifest(text, "collection.json");
  REQUIRE(parsed.ok());
  CHECK(formats::collection_manifest_text(parsed.value()) == text);
  CHECK(parsed->feature_names() == std::vector<std::string>{"top", "side"});
  CHECK(parsed->features[0].initial_location.has_value());
  CHECK_FALSE(parsed->features[1].initial_location.has_value());
  CHECK(parsed->members[1].feature_vertices == std::vector<long long>{4, 0});
  CHECK(parsed->member_index("b") == 1);
  CHECK(parsed->member_index("c") == -1);
  CHECK(parsed->options["seed"] == 7);
  // Keys the format does not know are kept, in their place among the others.
  const std::string with_extra = manifest_with([](OrderedJson& j) {
    j["meshes"][0]["note"] = "hand-written";
    j["features"][1]["label"] = "tip of the left ear";
    j["future"] = {1, 2};
  });
  auto extra = formats::parse_collection_manifest(with_extra, "collection.json");
  REQUIRE(extra.ok());
  CHECK(formats::collection_manifest_text(extra.value()) == with_extra + "\n");
}

TEST_CASE("collection manifest: what the commands cannot use is refused, naming the file", "[formats][collection]") {
  struct Case {
    const char* what;
    std::function<void(OrderedJson&)> edit;
    const char* problem;
  };
  const std::vector<Case> cases = {
      {"wrong format", [](OrderedJson& j) { j["format"] = "other"; }, "not a spherekit-collection manifest"},
      {"future version", [](OrderedJson& j) { j["format_version"] = 2; }, "unsupported format_version 2"},
      {"no features", [](OrderedJson& j) { j["features"] = OrderedJson::array(); }, "no features"},
      {"non-unit location", [](OrderedJson& j) { j["features"][0]["location"] = {0, 0, 2}; }, "is not a unit vector"},
      {"duplicate feature", [](OrderedJson& j) { j["features"][1]["name"] = "top"; }, "duplicate feature name 'top'"},
      {"map with a path", [](OrderedJson& j) { j["meshes"][0]["map"] = "../a.obj"; }, "is not a file name"},
      {"duplicate member", [](OrderedJson& j) { j["meshes"][1]["name"] = "a"; }, "duplicate mesh name 'a'"},
      {"shared map", [](OrderedJson& j) { j["meshes"][1]["map"] = "a.sphere.obj"; }, "listed for two meshes"},
      {"bad vertex count", [](OrderedJson& j) { j["meshes"][0]["vertices"] = 2; }, "is not a vertex count"},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    auto r = formats::parse_collection_manifest(manifest_with(c.edit), "DIR/collection.json");
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::InvalidInput);
    CHECK(r.status().message().rfind("DIR/collection.json: ", 0) == 0);
    CHECK(r.status().message().find(c.problem) != std::string::npos);
  }
  auto empty = formats::parse_collection_manifest("", "m.json");
  CHECK(empty.status().code() == ErrorCode::ParseError);
  auto cut = formats::parse_collection_manifest(manifest_with([](OrderedJson&) {}).substr(0, 40), "m.json");
  CHECK(cut.status().message().find("ends early") != std::string::npos);
}

TEST_CASE("collection folder: read, members loaded with their maps and feature positions", "[formats][collection]") {
  const std::string dir = make_folder("collection_read", two_member_manifest());
  auto c = formats::read_collection(dir);
  REQUIRE(c.ok());
  CHECK(formats::check_member_maps(c.value()).ok());
  CHECK(formats::find_member(c.value(), dir + "/b.obj") == 1);
  CHECK(formats::find_member(c.value(), "/elsewhere/a.ply") == 0);  // by stem
  CHECK(formats::find_member(c.value(), "nobody") == -1);
  auto members = formats::load_collection_members(c.value());
  REQUIRE(members.ok());
  REQUIRE(members->size() == 2);
  CHECK(members->at(1).name == "b");
  CHECK(members->at(1).mesh.V.rows() == 6);
  CHECK(members->at(1).map.S.rows() == 6);
  REQUIRE(members->at(0).features.rows() == 2);
  CHECK(members->at(0).features.row(0).isApprox(members->at(0).mesh.V.row(4)));
  auto missing = formats::load_collection_member(c.value(), std::string("nobody"));
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.status().message().find("(members: a, b)") != std::string::npos);

  SECTION("features.txt must agree with the manifest") {
    REQUIRE(formats::write_file_atomic(dir + "/features.txt", "top 0 0 1\n").ok());
    auto missing = formats::read_collection(dir);
    REQUIRE_FALSE(missing.ok());
    CHECK(missing.status().message().find("no feature 'side'") != std::string::npos);
    REQUIRE(formats::write_file_atomic(dir + "/features.txt", "top 0 0 1\nside 1 0 0\nextra 0 1 0\n").ok());
    auto extra = formats::read_collection(dir);
    REQUIRE_FALSE(extra.ok());
    CHECK(extra.status().message().find("has 3 features") != std::string::npos);
  }
  SECTION("a map with another vertex count is found before the collection grows") {
    REQUIRE(formats::write_mesh(dir + "/b.sphere.obj", test::tetrahedron()).ok());
    const Status s = formats::check_member_maps(c.value());
    CHECK(s.code() == ErrorCode::InvalidInput);
    CHECK(s.message().find("member 'b'") != std::string::npos);
    CHECK(formats::check_member_maps(c.value(), /*skip=*/1).ok());
  }
  SECTION("a feature vertex beyond the mesh is refused when the member is loaded") {
    formats::CollectionManifest m = c->manifest;
    m.members[0].feature_vertices = std::vector<long long>{4, 6};
    REQUIRE(formats::write_file_atomic(dir + "/collection.json", formats::collection_manifest_text(m)).ok());
    auto again = formats::read_collection(dir);
    REQUIRE(again.ok());
    auto a = formats::load_collection_member(again.value(), 0);
    REQUIRE_FALSE(a.ok());
    CHECK(a.status().message().find("feature vertex out of range") != std::string::npos);
  }
}

TEST_CASE("staged folder: complete or untouched, never an unrelated folder replaced", "[formats][collection]") {
  const std::string root = test::temp_dir("staged_folder");
  const std::string dir = root + "/out";
  auto write_one = [](const std::string& name) {
    return [name](const std::string& staging) { return formats::write_file_atomic(staging + "/" + name, "x"); };
  };
  REQUIRE(formats::write_staged_folder(dir, "marker.json", write_one("marker.json")).ok());
  CHECK(fs::is_regular_file(dir + "/marker.json"));
  // A failing writer: the old folder stays as it was, no staging folder is left.
  const Status failed = formats::write_staged_folder(dir, "marker.json", [](const std::string& staging) {
    (void)formats::write_file_atomic(staging + "/marker.json", "y");
    return Status(ErrorCode::IoError, "disk full");
  });
  CHECK(failed.message() == "disk full");
  CHECK(formats::read_file(dir + "/marker.json").value() == "x");
  // Cancelled after the files: nothing replaced either.
  const Status cancelled = formats::write_staged_folder(dir, "marker.json", write_one("marker.json"), [] { return false; });
  CHECK(cancelled.code() == ErrorCode::Cancelled);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(root)) names.push_back(e.path().filename().string());
  CHECK(names == std::vector<std::string>{"out"});
  // A folder with other files and no marker is refused.
  fs::create_directories(root + "/mine");
  REQUIRE(formats::write_file_atomic(root + "/mine/notes.txt", "keep").ok());
  const Status refused = formats::write_staged_folder(root + "/mine", "marker.json", write_one("marker.json"));
  CHECK(refused.code() == ErrorCode::IoError);
  CHECK(refused.message().find("refusing to replace it") != std::string::npos);
  CHECK(fs::is_regular_file(root + "/mine/notes.txt"));
  // All-or-nothing file sets: a failing second file removes the first.
  formats::OutputFiles files;
  files.add(root + "/one.txt", "1");
  files.add(root + "/no/such/folder/two.txt", "2");
  CHECK_FALSE(files.write_all().ok());
  CHECK_FALSE(fs::exists(root + "/one.txt"));
}

TEST_CASE("text formats: vertex-index lists, point lists, the path network OBJ", "[formats]") {
  const std::string dir = test::temp_dir("text_formats");
  REQUIRE(formats::write_file_atomic(dir + "/a.corr.txt", "3 -1\n 7\n").ok());
  CHECK(formats::read_vertex_indices(dir + "/a.corr.txt").value() == std::vector<int>{3, -1, 7});
  REQUIRE(formats::write_file_atomic(dir + "/b.corr.txt", "3\n4 x\n").ok());
  const Status bad = formats::read_vertex_indices(dir + "/b.corr.txt").status();
  CHECK(bad.code() == ErrorCode::ParseError);
  CHECK(bad.message() == dir + "/b.corr.txt:2: 'x' is not a vertex index");
  REQUIRE(formats::write_file_atomic(dir + "/p.txt", "# points\n1 2 3\n\n4 5 6 # last\n").ok());
  auto points = formats::read_points(dir + "/p.txt");
  REQUIRE(points.ok());
  REQUIRE(points->size() == 2);
  CHECK(points->at(1) == Eigen::Vector3d(4, 5, 6));
  REQUIRE(formats::write_file_atomic(dir + "/q.txt", "1 2\n").ok());
  CHECK(formats::read_points(dir + "/q.txt").status().message() == dir + "/q.txt:1: expected 'x y z'");
  const std::string obj = formats::path_network_obj_text({{Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0)}}, {{0, 1}},
                                                         {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0)});
  CHECK(obj.find("g paths\nv 0 0 1\nv 1 0 0\nl 1 2\ng arcs\n") != std::string::npos);
  CHECK(std::count(obj.begin(), obj.end(), 'v') >= 2 + 17);
  CHECK(obj.find("l 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19\n") != std::string::npos);
}
