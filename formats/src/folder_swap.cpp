// Staged folders swapped in atomically (folder_swap.h).
#include "spherekit/formats/folder_swap.h"

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace spherekit::formats {
namespace {

std::atomic<unsigned> g_counter{0};

// The target's absolute path without a trailing slash, and the prefix of its hidden
// siblings.
fs::path normal_target(const std::string& target) {
  std::error_code ec;
  fs::path t = fs::absolute(target, ec).lexically_normal();
  if (!t.has_filename()) t = t.parent_path();
  return t;
}

std::string sibling_prefix(const fs::path& t, const char* kind) {
  std::string p = ".";
  p.append(t.filename().string()).append(".").append(kind).append(".");
  return p;
}

void fsync_dir(const fs::path& dir) noexcept {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  (void)::fsync(fd);
  ::close(fd);
}

// Whether a writer still holds the lock beside `entry`. A missing lock file means the
// writer is gone (it removes its lock file last).
bool writer_alive(const fs::path& entry) noexcept {
  const std::string lock = entry.string() + ".lock";
  const int fd = ::open(lock.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  const bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  ::close(fd);
  return !free;
}

}  // namespace

Result<StagingFolder> StagingFolder::create(const std::string& target) {
  const fs::path t = normal_target(target);
  const std::string name = sibling_prefix(t, "partial") + std::to_string(::getpid()) + "." +
                           std::to_string(g_counter.fetch_add(1));
  const fs::path staging = t.parent_path() / name;
  const std::string lock_path = staging.string() + ".lock";
  // The lock first, then the folder: a folder without a held lock is always a dead writer's.
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0 || ::flock(fd, LOCK_EX) != 0) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    return Status(ErrorCode::IoError, lock_path + ": cannot create the staging lock (" + why + ")");
  }
  std::error_code ec;
  fs::remove_all(staging, ec);
  if (!fs::create_directory(staging, ec)) {
    ::unlink(lock_path.c_str());
    ::close(fd);
    return Status(ErrorCode::IoError, staging.string() + ": cannot create staging folder (" + ec.message() + ")");
  }
  return StagingFolder(t.string(), staging.string(), lock_path, fd);
}

StagingFolder::StagingFolder(StagingFolder&& o) noexcept
    : target_(std::move(o.target_)), path_(std::move(o.path_)), lock_path_(std::move(o.lock_path_)), lock_fd_(o.lock_fd_) {
  o.lock_fd_ = -1;
  o.path_.clear();
}

StagingFolder::~StagingFolder() { discard(); }

void StagingFolder::discard() noexcept {
  if (lock_fd_ < 0) return;
  std::error_code ec;
  if (!path_.empty()) fs::remove_all(path_, ec);
  ::unlink(lock_path_.c_str());
  ::close(lock_fd_);
  lock_fd_ = -1;
}

Status StagingFolder::commit() {
  const fs::path t(target_), parent = fs::path(target_).parent_path();
  std::error_code ec;
  const bool exists = fs::exists(t, ec);
  const bool empty = exists && fs::is_directory(t, ec) && fs::is_empty(t, ec);
  if (!exists || empty) {
    // rename(2) replaces an absent name or an empty folder in one step.
    if (::rename(path_.c_str(), target_.c_str()) != 0)
      return Status(ErrorCode::IoError, target_ + ": cannot move the new folder into place (" + std::strerror(errno) + ")");
    fsync_dir(parent);
    path_.clear();
    discard();
    return Status();
  }
  if (::renameat2(AT_FDCWD, path_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
    // The old contents are now at the staging name, still covered by our lock until removed.
    fsync_dir(parent);
    discard();
    return Status();
  }
  if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP)
    return Status(ErrorCode::IoError, target_ + ": cannot replace the existing folder (" + std::strerror(errno) + ")");
  // No exchange on this file system: old aside (under a name our lock covers), new in.
  const fs::path old = parent / (sibling_prefix(t, "old") + fs::path(path_).filename().string().substr(1));
  const std::string old_lock = old.string() + ".lock";
  const int fd = ::open(old_lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0 || ::flock(fd, LOCK_EX) != 0) {
    if (fd >= 0) ::close(fd);
    return Status(ErrorCode::IoError, old_lock + ": cannot create the swap lock (" + std::strerror(errno) + ")");
  }
  Status s;
  if (::rename(target_.c_str(), old.c_str()) != 0) {
    s = Status(ErrorCode::IoError, target_ + ": cannot replace the existing folder (" + std::strerror(errno) + ")");
  } else if (::rename(path_.c_str(), target_.c_str()) != 0) {
    s = Status(ErrorCode::IoError, target_ + ": cannot move the new folder into place (" + std::strerror(errno) + ")");
    (void)::rename(old.c_str(), target_.c_str());
  } else {
    fsync_dir(parent);
    path_.clear();
    fs::remove_all(old, ec);
  }
  ::unlink(old_lock.c_str());
  ::close(fd);
  if (s.ok()) discard();
  return s;
}

void recover_folder(const std::string& target) noexcept {
  try {
    const fs::path t = normal_target(target);
    const std::string partial = sibling_prefix(t, "partial"), old = sibling_prefix(t, "old");
    std::error_code ec;
    std::vector<fs::path> found;
    for (const auto& e : fs::directory_iterator(t.parent_path(), ec)) {
      const std::string n = e.path().filename().string();
      if ((n.rfind(partial, 0) == 0 || n.rfind(old, 0) == 0) &&
          !(n.size() > 5 && n.compare(n.size() - 5, 5, ".lock") == 0))
        found.push_back(e.path());
    }
    for (const fs::path& p : found) {
      if (writer_alive(p)) continue;
      const bool is_old = p.filename().string().rfind(old, 0) == 0;
      if (is_old && !fs::exists(t, ec))
        (void)::rename(p.c_str(), t.c_str());  // the old folder was set aside and the new never came
      else
        fs::remove_all(p, ec);
      ::unlink((p.string() + ".lock").c_str());
    }
    // Lock files whose folder is gone (the writer died after removing it).
    std::vector<fs::path> locks;
    for (const auto& e : fs::directory_iterator(t.parent_path(), ec)) {
      const std::string n = e.path().filename().string();
      if ((n.rfind(partial, 0) == 0 || n.rfind(old, 0) == 0) && n.size() > 5 &&
          n.compare(n.size() - 5, 5, ".lock") == 0)
        locks.push_back(e.path());
    }
    for (const fs::path& l : locks) {
      const std::string n = l.string();
      const fs::path dir = n.substr(0, n.size() - 5);
      if (!fs::exists(dir, ec) && !writer_alive(dir)) ::unlink(l.c_str());
    }
  } catch (...) {
    // Best effort: directory iteration can throw on allocation failure only.
  }
}

}  // namespace spherekit::formats
