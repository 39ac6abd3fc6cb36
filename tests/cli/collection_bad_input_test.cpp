// Malformed collection folders (issue 8, the collection part of the tests/data/bad/ corpus):
// `spherekit add DIR MESH` and `spherekit correspond DIR A B --points P -o OUT` on a folder
// with a broken manifest, a missing or wrong sphere map, or a features.txt that disagrees
// with the manifest. Each case: the documented exit code, exactly one stderr line
// `spherekit: error: FILE: problem` naming the file and the problem, every file of the
// folder unchanged byte for byte with nothing added, and no -o output.
//
// The cases are made at test time from one good collection (`consistent` on two small
// built-in samples), each one defect away from it; the good folder itself is accepted by
// both commands, so every case fails for its own defect.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "test_paths.h"
#include "test_files.h"

#include "cli_test_prelude.h"

namespace {

using spherekit::test::require_failure;
using spherekit::test::write_text;

// Every file of a folder (names, including hidden temporary files) with its bytes.
std::map<std::string, std::string> snapshot(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) files[e.path().filename().string()] = slurp(e.path().string());
  return files;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

/// What a command must say about a broken folder.
struct Expect {
  int exit_code;
  std::string file;     // the file name the message must contain
  std::string problem;  // a phrase it must contain
};

struct Case {
  std::string name;
  std::function<void(const std::string& dir)> damage;  // applied to a copy of the good folder
  Expect add, correspond;
  // Mesh paths given to the commands (default: the members' and sample_c's real files).
  std::string add_mesh, correspond_a;
};

}  // namespace

TEST_CASE("bad input: collection folders refused by add and correspond", "[cli][collection]") {
  const std::string dir = spherekit::test::temp_dir("bad_input_collection");
  const std::string s = dir + "/samples", good = dir + "/good";
  REQUIRE(sk("samples -o " + q(s) + " --members 3 --vertices 600", dir).exit_code == 0);
  const CliRun made = sk("consistent -o " + q(good) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_b.obj") +
                             " --effort 1 --remesh-size 17 --quiet",
                         dir);
  INFO("consistent stderr: " << made.err);
  REQUIRE(made.exit_code == 0);
  const std::string a = s + "/sample_a.obj", b = s + "/sample_b.obj", c = s + "/sample_c.obj";
  const std::string points = dir + "/points.txt", out = dir + "/on_b.txt";
  write_text(points, "0 0 0\n0.1 0.2 0.3\n");

  const json manifest = read_json(good + "/collection.json");
  REQUIRE(manifest["features"].size() == 13);
  REQUIRE(manifest["meshes"].size() == 2);
  REQUIRE(manifest["meshes"][1]["map"] == "sample_b.sphere.obj");
  const std::string first_feature = manifest["features"][0]["name"].get<std::string>();
  const int b_vertices = manifest["meshes"][1]["vertices"].get<int>();
  const std::string features = slurp(good + "/features.txt");
  const std::vector<std::string> feature_lines = lines_of(features);
  REQUIRE(feature_lines.size() == 13);
  REQUIRE(feature_lines[0].rfind(first_feature + " ", 0) == 0);

  auto edit_manifest = [](const std::function<void(json&)>& edit) {
    return [edit](const std::string& d) {
      json j = read_json(d + "/collection.json");
      edit(j);
      write_text(d + "/collection.json", j.dump(2) + "\n");
    };
  };
  auto replace_file = [](const std::string& name, const std::string& text) {
    return [name, text](const std::string& d) { write_text(d + "/" + name, text); };
  };
  const std::string manifest_text = slurp(good + "/collection.json");
  const std::string b_map = slurp(good + "/sample_b.sphere.obj");
  // features.txt with the first feature's line replaced.
  auto first_feature_at = [&](const std::string& xyz) {
    std::vector<std::string> l = feature_lines;
    l[0] = first_feature + " " + xyz;
    return joined(l);
  };
  // The first feature's coordinates in another order: still a unit vector, another place.
  std::string swapped;
  {
    std::istringstream f(feature_lines[0]);
    std::string name, x, y, z;
    f >> name >> x >> y >> z;
    swapped = first_feature_at(y + " " + x + " " + z);
  }

  const std::string nb = std::to_string(b_vertices);
  const std::vector<Case> cases = {
      // "t" opens the literal `true`; the "h" at byte 2 breaks it.
      {"manifest not JSON", replace_file("collection.json", "this is not json\n"),
       {3, "collection.json", "not valid JSON (syntax error at byte 2)"},
       {3, "collection.json", "not valid JSON (syntax error at byte 2)"}},
      {"manifest truncated", replace_file("collection.json", manifest_text.substr(0, manifest_text.size() / 2)),
       {3, "collection.json", "not valid JSON: ends early after"},
       {3, "collection.json", "not valid JSON: ends early after"}},
      {"manifest empty", replace_file("collection.json", ""), {3, "collection.json", "file is empty"},
       {3, "collection.json", "file is empty"}},
      {"manifest missing", [](const std::string& d) { fs::remove(d + "/collection.json"); },
       {4, "collection.json", "missing (not a collection folder"},
       {4, "collection.json", "missing (not a collection folder"}},
      {"wrong format tag", edit_manifest([](json& j) { j["format"] = "spherekit-network"; }),
       {3, "collection.json", "not a spherekit-collection manifest"},
       {3, "collection.json", "not a spherekit-collection manifest"}},
      {"format tag not a string", edit_manifest([](json& j) { j["format"] = 5; }),
       {3, "collection.json", "not a spherekit-collection manifest"},
       {3, "collection.json", "not a spherekit-collection manifest"}},
      // Valid JSON syntax, but the number does not fit a double.
      {"manifest with a number out of range",
       replace_file("collection.json", "{\"format\": \"spherekit-collection\", \"format_version\": 1e400}\n"),
       {3, "collection.json", "not valid JSON (number overflow parsing '1e400')"},
       {3, "collection.json", "not valid JSON (number overflow parsing '1e400')"}},
      {"future format version", edit_manifest([](json& j) { j["format_version"] = 2; }),
       {3, "collection.json", "unsupported format_version 2 (this spherekit reads up to 1)"},
       {3, "collection.json", "unsupported format_version 2"}},
      {"format version 0", edit_manifest([](json& j) { j["format_version"] = 0; }),
       {3, "collection.json", "unsupported format_version 0"},
       {3, "collection.json", "unsupported format_version 0"}},
      {"format version not a number", edit_manifest([](json& j) { j["format_version"] = "1"; }),
       {3, "collection.json", "unsupported format_version \"1\""},
       {3, "collection.json", "unsupported format_version \"1\""}},
      {"feature location not unit (manifest)",
       edit_manifest([](json& j) { j["features"][0]["location"] = json::array({0, 0, 2}); }),
       {3, "collection.json", "location of feature '" + first_feature + "' is not a unit vector"},
       {3, "collection.json", "location of feature '" + first_feature + "' is not a unit vector"}},
      {"duplicate feature name", edit_manifest([](json& j) { j["features"].push_back(j["features"][0]); }),
       {3, "collection.json", "duplicate feature name '" + first_feature + "'"},
       {3, "collection.json", "duplicate feature name '" + first_feature + "'"}},
      {"map path outside the folder",
       edit_manifest([](json& j) { j["meshes"][1]["map"] = "../good/sample_b.sphere.obj"; }),
       {3, "collection.json", "is not a file name in the collection folder"},
       {3, "collection.json", "is not a file name in the collection folder"}},
      {"duplicate mesh name", edit_manifest([](json& j) { j["meshes"][1]["name"] = "sample_a"; }),
       {3, "collection.json", "duplicate mesh name 'sample_a'"},
       {3, "collection.json", "duplicate mesh name 'sample_a'"}},
      {"sphere map missing", [](const std::string& d) { fs::remove(d + "/sample_b.sphere.obj"); },
       {4, "sample_b.sphere.obj", "missing (the map of member 'sample_b'"},
       {4, "sample_b.sphere.obj", "missing (the map of member 'sample_b'"}},
      // add reads no other member's map (O(1) reads per add, issue 23): a damaged map is the
      // business of the commands that read it.
      {"sphere map with an extra vertex", replace_file("sample_b.sphere.obj", b_map + "v 1 0 0\n"),
       {0, "", ""},
       {3, "sample_b.sphere.obj", "has " + std::to_string(b_vertices + 1) + " vertices, mesh has " + nb}},
      {"vertex count in the manifest wrong", edit_manifest([](json& j) { j["meshes"][1]["vertices"] = 5; }),
       {0, "", ""},
       // correspond reads B's mesh, which no longer matches its entry.
       {3, "sample_b.obj", "has " + nb + " vertices, but member 'sample_b'"}},
      {"features.txt missing", [](const std::string& d) { fs::remove(d + "/features.txt"); },
       {4, "features.txt", "missing"},
       {4, "features.txt", "missing"}},
      {"features.txt with a non-unit vector", replace_file("features.txt", first_feature_at("0 0 2")),
       {3, "features.txt", ":1: point '" + first_feature + "' has length 2, not 1"},
       {3, "features.txt", ":1: point '" + first_feature + "' has length 2, not 1"}},
      {"features.txt without a feature",
       replace_file("features.txt", joined({feature_lines.begin() + 1, feature_lines.end()})),
       {3, "features.txt", "no feature '" + first_feature + "'"},
       {3, "features.txt", "no feature '" + first_feature + "'"}},
      {"features.txt with an extra feature", replace_file("features.txt", features + "extra_feature 1 0 0\n"),
       {3, "features.txt", "has 14 features"},
       {3, "features.txt", "has 14 features"}},
      {"manifest with a feature fewer than features.txt", edit_manifest([](json& j) { j["features"].erase(12); }),
       {3, "features.txt", "has 13 features"},
       {3, "features.txt", "has 13 features"}},
      {"features.txt moves a feature", replace_file("features.txt", swapped),
       {3, "features.txt", "feature '" + first_feature + "' is not where"},
       {3, "features.txt", "feature '" + first_feature + "' is not where"}},
      {"a listed mesh file missing", [](const std::string&) {},
       {4, "sample_c.obj", "cannot open"},
       {4, "sample_a.obj", "cannot open"},
       dir + "/deleted/sample_c.obj",
       dir + "/deleted/sample_a.obj"},
  };

  for (const Case& k : cases) {
    INFO("case: " << k.name);
    const std::string col = dir + "/case";
    fs::remove_all(col);
    fs::copy(good, col);
    k.damage(col);
    const auto before = snapshot(col);

    const std::string mesh = k.add_mesh.empty() ? c : k.add_mesh;
    CliRun r = sk("add " + q(col) + " " + q(mesh) + " --effort 0 -q", dir);
    if (k.add.exit_code == 0) {
      // Accepted (see the case); correspond below must still refuse the folder, which add
      // grew by one member: compare against that.
      INFO("add: " << r.err);
      CHECK(r.exit_code == 0);
      fs::remove_all(col);
      fs::copy(good, col);
      k.damage(col);
    } else {
      INFO("add");
      require_failure(r, k.add.exit_code, k.add.file, k.add.problem);
      CHECK(snapshot(col) == before);
    }
    const std::string from = k.correspond_a.empty() ? a : k.correspond_a;
    r = sk("correspond " + q(col) + " " + q(from) + " " + q(b) + " --points " + q(points) + " -o " + q(out), dir);
    {
      INFO("correspond");
      require_failure(r, k.correspond.exit_code, k.correspond.file, k.correspond.problem);
      CHECK(snapshot(col) == before);
      CHECK_FALSE(fs::exists(out));
    }
  }

  // The good folder is accepted by both (last: add changes it).
  const std::string col = dir + "/case";
  fs::remove_all(col);
  fs::copy(good, col);
  {
    // A member name with a path would write its map outside the folder.
    INFO("add --name with a path");
    const auto before = snapshot(col);
    const CliRun bad_name = sk("add " + q(col) + " " + q(c) + " --name ../escaped -q", dir);
    require_failure(bad_name, 2, "--name '../escaped'", "must be a plain file name");
    CHECK(snapshot(col) == before);
    CHECK_FALSE(fs::exists(dir + "/escaped.sphere.obj"));
  }
  CliRun r = sk("correspond " + q(col) + " " + q(a) + " " + q(b) + " --points " + q(points) + " -o " + q(out), dir);
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 0);
  CHECK(lines_of(slurp(out)).size() == 2);
  r = sk("add " + q(col) + " " + q(c) + " --effort 0 -q", dir);
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 0);
  CHECK(read_json(col + "/collection.json")["meshes"].size() == 3);
}
