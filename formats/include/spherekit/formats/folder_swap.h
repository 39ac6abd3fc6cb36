// Crash-safe replacement of a whole folder (a collection, a converted asset folder): the new
// contents are written into a staging folder beside the target and swapped in with one
// atomic rename, so that a reader at any moment (and after a kill -9 at any moment) finds
// either the complete old folder or the complete new one at the target path.
//
// The swap is renameat2(RENAME_EXCHANGE) (Linux >= 3.15; ext4, xfs, btrfs, tmpfs, overlayfs):
// one system call exchanges the two names, there is no moment without a folder at the target.
// Where the file system refuses it (NFS), it falls back to two renames (the old folder aside,
// the new one in); a crash between them leaves the old folder beside the target under a
// hidden name, and recover_folder() (which every writer calls first) moves it back.
//
// Each staging folder `.<name>.partial.<pid>.<n>` has a lock file beside it
// (`….lock`, flock(2) held by its writer while it lives); a staging or set-aside folder
// whose lock nobody holds belongs to a dead writer, and recover_folder() removes it.
#pragma once

#include <string>

#include "spherekit/status.h"

namespace spherekit::formats {

class StagingFolder {
 public:
  /// Creates an empty staging folder beside `target` (same parent, so the swap is a rename
  /// on one file system). Errors: IoError naming the staging folder.
  static Result<StagingFolder> create(const std::string& target);

  StagingFolder(StagingFolder&& o) noexcept;
  StagingFolder& operator=(StagingFolder&&) = delete;
  StagingFolder(const StagingFolder&) = delete;
  ~StagingFolder();  ///< removes the staging folder unless committed

  const std::string& path() const { return path_; }

  /// Puts the staging folder's contents at the target: renamed there when the target is
  /// absent or an empty folder, else exchanged atomically with it (the old contents are then
  /// removed). Errors: IoError naming the target (nothing changed then).
  Status commit();

 private:
  StagingFolder(std::string target, std::string path, std::string lock_path, int lock_fd)
      : target_(std::move(target)), path_(std::move(path)), lock_path_(std::move(lock_path)), lock_fd_(lock_fd) {}
  void discard() noexcept;

  std::string target_, path_, lock_path_;
  int lock_fd_ = -1;
};

/// Cleans up after writers of `target` that died: a set-aside old folder is moved back when
/// the target is missing (a crash inside the two-rename fallback), other leftovers are
/// removed. Folders of live writers (their lock held) are left alone. Best effort, never fails.
void recover_folder(const std::string& target) noexcept;

}  // namespace spherekit::formats
