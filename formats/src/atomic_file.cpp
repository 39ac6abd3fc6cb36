// Whole-file reads and atomic writes (POSIX).
//
// An atomic write is: create `.<base>.tmp.<pid>.<n>` in the target's folder (same file
// system, so rename() is atomic), write everything, fsync, close, rename over the target,
// then fsync the folder so the rename itself survives a crash. Readers of the target see
// the old file or the new one, never a partial one.
//
// Temporary paths are also kept in a fixed table of plain char buffers, so that a signal
// handler can unlink them with remove_pending_temp_files(): no allocation, no locks, only
// lock-free atomics and unlink(), all async-signal-safe.
#include "spherekit/formats/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace spherekit::formats {
namespace {

// 64 concurrent writes are far more than the CLI ever has in flight; a write that finds the
// table full still works, it just cannot be cleaned up by a signal handler.
constexpr int kMaxPending = 64;
constexpr std::size_t kMaxPathBytes = 4096;  // PATH_MAX on Linux

enum SlotState : int { kFree = 0, kBusy = 1, kPending = 2 };

struct PendingSlot {
  std::atomic<int> state{kFree};
  char path[kMaxPathBytes];
};
PendingSlot g_pending[kMaxPending];
std::atomic<std::uint64_t> g_temp_counter{0};
static_assert(std::atomic<int>::is_always_lock_free, "signal handlers need lock-free atomics");

/// Records `path` as pending; returns the slot or -1 when it cannot be recorded.
int register_pending(const std::string& path) {
  if (path.size() >= kMaxPathBytes) return -1;
  for (int i = 0; i < kMaxPending; ++i) {
    int expected = kFree;
    if (g_pending[i].state.compare_exchange_strong(expected, kBusy)) {
      std::memcpy(g_pending[i].path, path.c_str(), path.size() + 1);
      g_pending[i].state.store(kPending);  // publish only a complete string
      return i;
    }
  }
  return -1;
}

void unregister_pending(int slot) {
  if (slot >= 0) g_pending[slot].state.store(kFree);
}

std::string errno_text(int err) { return std::strerror(err); }

/// Writes all of `bytes`, retrying on EINTR and short writes.
bool write_all(int fd, const std::string& bytes, int& err) {
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    // Chunks of at most 1 GiB: Linux caps a single write() near 2 GiB anyway.
    ssize_t n = ::write(fd, p, left < (std::size_t{1} << 30) ? left : (std::size_t{1} << 30));
    if (n < 0) {
      if (errno == EINTR) continue;
      err = errno;
      return false;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

Status write_file_atomic(const std::string& path, const std::string& bytes) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const std::string base = target.filename().string();
  if (base.empty() || base == "." || base == "..") {
    return Status(ErrorCode::IoError, path + ": not a file name");
  }
  const std::string dir = target.has_parent_path() ? target.parent_path().string() : std::string(".");
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    return Status(ErrorCode::IoError, path + ": folder '" + dir + "' does not exist");
  }

  const std::string temp = (fs::path(dir) / ("." + base + ".tmp." + std::to_string(::getpid()) + "." +
                                             std::to_string(g_temp_counter.fetch_add(1))))
                               .string();
  const int slot = register_pending(temp);
  int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    int err = errno;
    unregister_pending(slot);
    return Status(ErrorCode::IoError, path + ": cannot create a temporary file in '" + dir + "' (" +
                                          errno_text(err) + ")");
  }
  // Replacing a file keeps its permissions; a new file gets the umask default.
  struct stat old {};
  if (::stat(path.c_str(), &old) == 0 && S_ISREG(old.st_mode)) (void)::fchmod(fd, old.st_mode & 07777);

  int err = 0;
  std::string what;
  if (!write_all(fd, bytes, err)) {
    what = "cannot write";
  } else if (::fsync(fd) != 0) {
    err = errno;
    what = "cannot sync";
  }
  if (::close(fd) != 0 && what.empty()) {
    err = errno;
    what = "cannot close";
  }
  if (what.empty() && ::rename(temp.c_str(), path.c_str()) != 0) {
    err = errno;
    what = "cannot replace";
  }
  if (!what.empty()) {
    ::unlink(temp.c_str());
    unregister_pending(slot);
    return Status(ErrorCode::IoError, path + ": " + what + " (" + errno_text(err) + ")");
  }
  unregister_pending(slot);

  // Persist the rename. Best effort: some file systems refuse fsync on a directory.
  int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
  return {};
}

Result<std::string> read_file(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    int err = errno;
    return Status(ErrorCode::IoError, path + ": cannot open (" + errno_text(err) + ")");
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    int err = errno;
    ::close(fd);
    return Status(ErrorCode::IoError, path + ": cannot open (" + errno_text(err) + ")");
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd);
    return Status(ErrorCode::IoError, path + ": is a directory, not a file");
  }
  std::string bytes;
  // st_size is only a hint (pipes report 0, files may change while we read): read to EOF.
  if (S_ISREG(st.st_mode) && st.st_size > 0) bytes.resize(static_cast<std::size_t>(st.st_size));
  std::size_t used = 0;
  char chunk[65536];
  for (;;) {
    // Fill the pre-sized buffer first; anything beyond the hint goes through `chunk`.
    const bool direct = used < bytes.size();
    char* dst = direct ? bytes.data() + used : chunk;
    const std::size_t cap = direct ? bytes.size() - used : sizeof chunk;
    ssize_t n = ::read(fd, dst, cap);
    if (n < 0) {
      if (errno == EINTR) continue;
      int err = errno;
      ::close(fd);
      return Status(ErrorCode::IoError, path + ": cannot read (" + errno_text(err) + ")");
    }
    if (n == 0) break;
    if (!direct) bytes.append(chunk, static_cast<std::size_t>(n));
    used += static_cast<std::size_t>(n);
  }
  ::close(fd);
  bytes.resize(used);
  return bytes;
}

void remove_pending_temp_files() noexcept {
  for (PendingSlot& slot : g_pending) {
    if (slot.state.load() == kPending) ::unlink(slot.path);
  }
}

}  // namespace spherekit::formats
