// An exclusive lock on a folder, for read-modify-write updates of a file in it (a collection's
// manifest grown by concurrent `spherekit add`s, on one machine or on a shared file system).
//
// The lock is flock(2) on a lock file inside the folder. flock locks belong to the open file,
// are released by the kernel when the holder dies (kill -9 included: no stale lock to clean up),
// and work on local file systems and NFSv4 (Lustre needs its `flock` mount option). Because a
// whole folder may be replaced (folder_swap.h) while someone waits for its lock, acquire()
// checks after locking that the path still names the file it locked, and locks again otherwise.
#pragma once

#include <string>

#include "spherekit/status.h"

namespace spherekit::formats {

/// The lock file a collection folder holds (created on first use; empty).
inline constexpr const char* kFolderLockFile = ".collection.lock";

class FolderLock {
 public:
  FolderLock() = default;
  FolderLock(FolderLock&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  FolderLock& operator=(FolderLock&& o) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock() { release(); }

  /// Blocks until this process holds the exclusive lock of `dir` (its file `lock_file`,
  /// created if missing). Errors: IoError naming the lock file (folder missing, read-only,
  /// a file system without flock).
  static Result<FolderLock> acquire(const std::string& dir, const char* lock_file = kFolderLockFile);
  /// As acquire, but returns an unlocked FolderLock (held() false) at once when another
  /// process holds it.
  static Result<FolderLock> try_acquire(const std::string& dir, const char* lock_file = kFolderLockFile);

  bool held() const { return fd_ >= 0; }
  void release() noexcept;

 private:
  explicit FolderLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace spherekit::formats
