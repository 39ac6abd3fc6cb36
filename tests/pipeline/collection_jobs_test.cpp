// make_collection() and add_to_collection() as a library (spherekit/pipeline/collection.h):
// the folder they write reads back through formats, a failing mesh is named by its file (a
// value, not an index in the text), and add never grows a collection it cannot use.
#include <catch2/catch.hpp>
#include <sys/stat.h>
#include <filesystem>

#include "sample_collection.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/pipeline/collection.h"
#include "test_meshes.h"
#include "test_paths.h"
#include "spherekit/formats/mesh_io.h"

namespace fs = std::filesystem;
using namespace spherekit;

namespace {

// Three small samples on disk (meshes with their landmark files beside them).
std::vector<std::string> small_samples(const std::string& dir) {
  samples::SampleCollectionOptions so;
  so.members = 3;
  so.target_vertices = 500;
  auto c = samples::make_sample_collection(so);
  REQUIRE(c.ok());
  REQUIRE(samples::write_sample_collection(dir, c.value()).ok());
  std::vector<std::string> paths;
  for (const auto& m : c.value()) paths.push_back(dir + "/" + m.name + ".obj");
  return paths;
}

pipeline::MakeCollectionJob quick_job(std::vector<std::string> meshes, const std::string& output) {
  pipeline::MakeCollectionJob job;
  job.meshes = std::move(meshes);
  job.output = output;
  job.options.constrained.sphere.effort = 0;
  job.options.remesh_size = 17;
  return job;
}

}  // namespace

TEST_CASE("make_collection and add_to_collection: the folder formats reads", "[pipeline][collection]") {
  const std::string dir = test::temp_dir("pipeline_collection_jobs");
  const std::vector<std::string> meshes = small_samples(dir + "/in");
  auto made = pipeline::make_collection(quick_job({meshes[0], meshes[1]}, dir + "/col"));
  REQUIRE(made.ok());
  CHECK(made->members.size() == 2);
  CHECK(made->refinement_warning.empty());
  auto read = formats::read_collection(dir + "/col");
  REQUIRE(read.ok());
  CHECK(formats::collection_manifest_text(read->manifest) == formats::collection_manifest_text(made->manifest));
  CHECK(read->manifest.members[1].name == "sample_b");
  CHECK(read->manifest.members[1].result["flipped_faces"] == 0);
  CHECK(formats::check_member_maps(read.value()).ok());

  pipeline::AddToCollectionJob add;
  add.dir = dir + "/col";
  add.mesh = meshes[2];
  add.options.sphere.effort = 0;
  auto added = pipeline::add_to_collection(add);
  REQUIRE(added.ok());
  CHECK(added->map.max_feature_angle < 1e-9);
  auto grown = formats::read_collection(dir + "/col");
  REQUIRE(grown.ok());
  REQUIRE(grown->manifest.members.size() == 3);
  CHECK(grown->manifest.members[2].added == true);
  // The collection's recorded seed was used (none was given).
  CHECK(grown->manifest.options["seed"] == made->manifest.options["seed"]);

  SECTION("the same name again is refused unless replaced; a missing member map stops add") {
    auto again = pipeline::add_to_collection(add);
    CHECK(again.status().code() == ErrorCode::InvalidArgument);
    CHECK(again.status().message().find("--replace") != std::string::npos);
    // add reads no other member's map (issue 23: O(1) reads per add), it only checks that each
    // is there.
    fs::remove(dir + "/col/sample_a.sphere.obj");
    add.replace = true;
    auto broken = pipeline::add_to_collection(add);
    CHECK(broken.status().code() == ErrorCode::IoError);
    CHECK(broken.status().message().find("missing (the map of member 'sample_a'") != std::string::npos);
  }
  SECTION("replace: a new version of the folder, the other maps hard-linked, the lock file kept") {
    const std::string lock = dir + "/col/.collection.lock";
    REQUIRE(fs::exists(lock));
    // Waiters hold the lock file open: the new version must keep the same file (inode).
    auto inode = [](const std::string& p) {
      struct stat st {};
      return ::stat(p.c_str(), &st) == 0 ? static_cast<long long>(st.st_ino) : -1LL;
    };
    const long long lock_inode = inode(lock);
    add.replace = true;
    auto replaced = pipeline::add_to_collection(add);
    REQUIRE(replaced.ok());
    CHECK(replaced->manifest.members.size() == 3);
    CHECK(inode(lock) == lock_inode);
    CHECK(lock_inode > 0);
    for (const auto& e : fs::directory_iterator(dir)) CHECK(e.path().filename().string().rfind(".col.", 0) != 0);
  }
}

TEST_CASE("make_collection: a mesh param refuses is named by its file, nothing is written", "[pipeline][collection]") {
  const std::string dir = test::temp_dir("pipeline_collection_failure");
  const std::vector<std::string> meshes = small_samples(dir + "/in");
  // The second member replaced by a torus (genus 1), with the same landmark file.
  REQUIRE(formats::write_mesh(meshes[1], test::torus()).ok());
  auto made = pipeline::make_collection(quick_job({meshes[0], meshes[1]}, dir + "/col"));
  REQUIRE_FALSE(made.ok());
  INFO(made.status().message());
  CHECK(made.status().code() == ErrorCode::InvalidInput);
  CHECK(made.status().message().rfind(meshes[1] + ": ", 0) == 0);
  CHECK(made.status().message().find("genus") != std::string::npos);
  CHECK_FALSE(fs::exists(dir + "/col"));
}
