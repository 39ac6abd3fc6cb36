// Atomic writes and whole-file reads: content, no leftovers, failures that leave no trace,
// and the signal-handler cleanup of temporary files.
#include "spherekit/formats/atomic_file.h"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "test_paths.h"

namespace {

namespace fs = std::filesystem;
using namespace spherekit;
using namespace spherekit::formats;

std::vector<std::string> listing(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

bool has_temp_file(const std::string& dir) {
  for (const std::string& n : listing(dir)) {
    if (n.find(".tmp.") != std::string::npos) return true;
  }
  return false;
}

void check_one_line_error(const Status& s, const std::string& path, const std::string& word) {
  INFO(s.message());
  REQUIRE_FALSE(s.ok());
  CHECK(s.code() == ErrorCode::IoError);
  CHECK(s.message().rfind(path, 0) == 0);
  CHECK(s.message().find(word) != std::string::npos);
  CHECK(s.message().find('\n') == std::string::npos);
}

}  // namespace

TEST_CASE("write_file_atomic writes, replaces and leaves no temporary file", "[formats]") {
  const std::string dir = test::temp_dir("formats_atomic");
  const std::string path = dir + "/out.txt";
  REQUIRE(write_file_atomic(path, "first").ok());
  CHECK(read_file(path).value() == "first");

  std::string big(3 << 20, '\0');
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>(i * 7919 % 251);
  REQUIRE(write_file_atomic(path, big).ok());
  CHECK(read_file(path).value() == big);
  REQUIRE(write_file_atomic(path, "").ok());
  CHECK(read_file(path).value().empty());
  CHECK(listing(dir) == std::vector<std::string>{"out.txt"});

  // A relative path without a folder lands in the working directory.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  Status relative = write_file_atomic("rel.txt", "r");
  fs::current_path(cwd);
  REQUIRE(relative.ok());
  CHECK(read_file(dir + "/rel.txt").value() == "r");
}

TEST_CASE("write_file_atomic keeps the permissions of the file it replaces", "[formats]") {
  const std::string dir = test::temp_dir("formats_atomic_mode");
  const std::string path = dir + "/private.txt";
  REQUIRE(write_file_atomic(path, "a").ok());
  REQUIRE(::chmod(path.c_str(), 0600) == 0);
  REQUIRE(write_file_atomic(path, "b").ok());
  struct stat st {};
  REQUIRE(::stat(path.c_str(), &st) == 0);
  CHECK((st.st_mode & 07777) == 0600);
}

TEST_CASE("write_file_atomic failures create nothing and leave no temporary file", "[formats]") {
  const std::string dir = test::temp_dir("formats_atomic_fail");
  SECTION("missing folder") {
    const std::string path = dir + "/no/such/folder/out.obj";
    check_one_line_error(write_file_atomic(path, "x"), path, "does not exist");
    CHECK_FALSE(fs::exists(dir + "/no"));
    CHECK(listing(dir).empty());
  }
  SECTION("target is a directory") {
    fs::create_directories(dir + "/taken");
    check_one_line_error(write_file_atomic(dir + "/taken", "x"), dir + "/taken", "cannot replace");
    CHECK(fs::is_directory(dir + "/taken"));
    CHECK_FALSE(has_temp_file(dir));
  }
  SECTION("folder given instead of a file name") {
    check_one_line_error(write_file_atomic(dir + "/", "x"), dir + "/", "not a file name");
  }
}

// Its own test case, so that as root (the CI) it shows as skipped while the others run.
TEST_CASE("write_file_atomic into a read-only folder creates nothing", "[formats]") {
  if (::geteuid() == 0) SPHEREKIT_SKIP("running as root, folder permissions are not enforced");
  const std::string dir = test::temp_dir("formats_atomic_read_only");
  fs::create_directories(dir + "/ro");
  fs::permissions(dir + "/ro", fs::perms::owner_read | fs::perms::owner_exec);
  Status s = write_file_atomic(dir + "/ro/out.txt", "x");
  fs::permissions(dir + "/ro", fs::perms::owner_all);
  check_one_line_error(s, dir + "/ro/out.txt", "temporary");
  CHECK(listing(dir + "/ro").empty());
}

TEST_CASE("read_file reports missing files and directories", "[formats]") {
  const std::string dir = test::temp_dir("formats_read_file");
  Result<std::string> missing = read_file(dir + "/absent.txt");
  check_one_line_error(missing.status(), dir + "/absent.txt", "cannot open");
  Result<std::string> folder = read_file(dir);
  check_one_line_error(folder.status(), dir, "directory");
  std::ofstream(dir + "/empty.txt").close();
  CHECK(read_file(dir + "/empty.txt").value().empty());
}

TEST_CASE("remove_pending_temp_files cleans up after an interrupted write", "[formats]") {
  const std::string dir = test::temp_dir("formats_atomic_signal");
  std::ofstream(dir + "/.keep.tmp.1.0") << "not ours";  // looks like a temp file, is not pending
  remove_pending_temp_files();  // nothing pending: touches nothing
  CHECK(fs::exists(dir + "/.keep.tmp.1.0"));
  fs::remove(dir + "/.keep.tmp.1.0");

  // A child rewrites a large file in a loop; once a temporary file is visible, SIGINT makes
  // its handler call remove_pending_temp_files() and exit, as the CLI's Ctrl-C handler does.
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    struct sigaction sa {};
    sa.sa_handler = [](int) {
      remove_pending_temp_files();
      ::_exit(0);
    };
    ::sigaction(SIGINT, &sa, nullptr);
    const std::string big(32 << 20, 'x');
    for (;;) (void)write_file_atomic(dir + "/big.bin", big);
  }
  bool seen = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!seen && std::chrono::steady_clock::now() < deadline) {
    seen = has_temp_file(dir);
    if (!seen) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ::kill(child, SIGINT);
  int status = 0;
  ::waitpid(child, &status, 0);
  CHECK(seen);
  CHECK(WIFEXITED(status));
  CHECK_FALSE(has_temp_file(dir));
}
