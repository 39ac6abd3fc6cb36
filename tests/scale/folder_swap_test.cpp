// The folder lock and the crash-safe folder swap (formats/folder_lock.h, folder_swap.h).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli_runner.h"
#include "spherekit/formats/folder_lock.h"
#include "spherekit/formats/folder_swap.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using spherekit::formats::FolderLock;
using spherekit::formats::StagingFolder;

namespace {

void put(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

int entries(const std::string& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

TEST_CASE("folder lock: exclusive between open files, released by release()", "[formats][scale]") {
  const std::string dir = spherekit::test::temp_dir("scale_lock");
  auto a = FolderLock::acquire(dir);
  REQUIRE(a.ok());
  CHECK(a->held());
  CHECK(fs::exists(dir + "/" + spherekit::formats::kFolderLockFile));
  // flock locks belong to the open file: a second open in this process conflicts like
  // another process would.
  auto b = FolderLock::try_acquire(dir);
  REQUIRE(b.ok());
  CHECK_FALSE(b->held());
  a->release();
  auto c = FolderLock::try_acquire(dir);
  REQUIRE(c.ok());
  CHECK(c->held());
  auto missing = FolderLock::acquire(dir + "/no/such/folder");
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.status().code() == spherekit::ErrorCode::IoError);
  CHECK(missing.status().message().find(".collection.lock") != std::string::npos);
}

TEST_CASE("staging folder: swapped in whole, removed when abandoned, no leftovers", "[formats][scale]") {
  const std::string dir = spherekit::test::temp_dir("scale_swap");
  const std::string target = dir + "/col";
  {
    auto st = StagingFolder::create(target);
    REQUIRE(st.ok());
    CHECK(fs::path(st->path()).filename().string().rfind(".col.partial.", 0) == 0);
    put(st->path() + "/a.txt", "one");
  }  // abandoned
  CHECK(entries(dir) == 0);
  {
    auto st = StagingFolder::create(target);
    REQUIRE(st.ok());
    put(st->path() + "/a.txt", "one");
    REQUIRE(st->commit().ok());
  }
  CHECK(spherekit::test::slurp(target + "/a.txt") == "one");
  CHECK(entries(dir) == 1);
  {
    // Over an existing folder: exchanged, the old contents gone.
    auto st = StagingFolder::create(target);
    REQUIRE(st.ok());
    put(st->path() + "/b.txt", "two");
    REQUIRE(st->commit().ok());
  }
  CHECK_FALSE(fs::exists(target + "/a.txt"));
  CHECK(spherekit::test::slurp(target + "/b.txt") == "two");
  CHECK(entries(dir) == 1);
}

TEST_CASE("recover_folder: dead writers' leftovers removed, a set-aside old folder restored, live ones kept",
          "[formats][scale]") {
  const std::string dir = spherekit::test::temp_dir("scale_recover");
  const std::string target = dir + "/col";
  fs::create_directory(target);
  put(target + "/m.txt", "current");
  // A writer killed while staging (its lock file is not held by anyone), and one alive.
  fs::create_directory(dir + "/.col.partial.999999.0");
  put(dir + "/.col.partial.999999.0/m.txt", "half");
  put(dir + "/.col.partial.999999.0.lock", "");
  auto live = StagingFolder::create(target);
  REQUIRE(live.ok());
  spherekit::formats::recover_folder(target);
  CHECK_FALSE(fs::exists(dir + "/.col.partial.999999.0"));
  CHECK_FALSE(fs::exists(dir + "/.col.partial.999999.0.lock"));
  CHECK(fs::is_directory(live->path()));
  CHECK(spherekit::test::slurp(target + "/m.txt") == "current");
  // A crash inside the two-rename fallback: the old folder aside, no folder at the target.
  fs::rename(target, dir + "/.col.old.999999.1");
  spherekit::formats::recover_folder(target);
  CHECK(spherekit::test::slurp(target + "/m.txt") == "current");
  CHECK_FALSE(fs::exists(dir + "/.col.old.999999.1"));
}
