// Staged folder writes (staged_folder.h): build beside, swap in once complete (atomically,
// folder_swap.h).
#include "spherekit/formats/staged_folder.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/folder_lock.h"
#include "spherekit/formats/folder_swap.h"

namespace fs = std::filesystem;

namespace spherekit::formats {
namespace {

bool has_marker(const fs::path& dir, const std::string& marker) {
  std::error_code ec;
  return fs::is_regular_file(dir / marker, ec);
}

bool is_empty_dir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_empty(dir, ec);
}

}  // namespace

Status require_staged_folder_target(const std::string& dir, const std::string& marker) {
  std::error_code ec;
  const fs::path p(dir);
  const fs::path parent = fs::absolute(p, ec).parent_path();
  if (!fs::is_directory(parent, ec)) return Status(ErrorCode::IoError, dir + ": parent folder does not exist");
  if (!fs::exists(p, ec)) return Status();
  if (!fs::is_directory(p, ec)) return Status(ErrorCode::IoError, dir + ": exists and is not a folder");
  if (is_empty_dir(p) || has_marker(p, marker)) return Status();
  // The collection folder's marker is its manifest: say what the folder is not.
  if (marker == "collection.json")
    return Status(ErrorCode::IoError, dir + ": folder is not empty and not a collection; refusing to replace it");
  return Status(ErrorCode::IoError, dir + ": folder is not empty and has no " + marker + "; refusing to replace it");
}

Status write_staged_folder(const std::string& dir, const std::string& marker,
                           const std::function<Status(const std::string&)>& write_into, const KeepGoingFn& keep_going) {
  SPHEREKIT_RETURN_IF_ERROR(require_staged_folder_target(dir, marker));
  // Leftovers of writers killed earlier first (folder_swap.h).
  recover_folder(dir);
  SPHEREKIT_ASSIGN_OR_RETURN(StagingFolder staging, StagingFolder::create(dir));
  const bool collection = marker == "collection.json";
  // A collection carries its lock file from the start, so that `add`s never race on creating it.
  if (collection)
    SPHEREKIT_RETURN_IF_ERROR(write_file_atomic((fs::path(staging.path()) / kFolderLockFile).string(), ""));
  // A cancellation while the files are written (the caller's keep_going) removes the
  // staging folder (~StagingFolder), instead of leaving it behind.
  Status s = write_into(staging.path());
  if (s.ok() && keep_going && !keep_going()) s = Status(ErrorCode::Cancelled, "cancelled");
  if (!s.ok()) return s;
  // The swap: one atomic exchange (folder_swap.h), so that readers, and a kill -9 at any
  // moment, find the old folder or the new one, never none. An `add` growing the old
  // collection holds its lock around its manifest update: wait for it, so that its member is
  // not written into a folder being replaced (it then finds the new folder and re-reads it).
  // SIGINT/SIGTERM wait until the swap is done.
  sigset_t stop_signals, saved_mask;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, &saved_mask);
  Status swapped;
  {
    FolderLock old_lock;
    if (collection && has_marker(dir, marker)) {
      auto l = FolderLock::acquire(dir);
      if (l.ok()) old_lock = std::move(l).value();
    }
    swapped = staging.commit();
  }
  pthread_sigmask(SIG_SETMASK, &saved_mask, nullptr);  // a pending signal ends the program here
  return swapped;
}

Status OutputFiles::write_all() const {
  for (std::size_t k = 0; k < files_.size(); ++k) {
    Status s = write_file_atomic(files_[k].first, files_[k].second);
    if (s.ok()) continue;
    std::error_code ec;
    for (std::size_t j = 0; j < k; ++j) fs::remove(files_[j].first, ec);
    return s;
  }
  return Status();
}

Status write_output_folder(const std::string& dir, const std::string& marker, const OutputFiles& files,
                           const KeepGoingFn& keep_going) {
  return write_staged_folder(
      dir, marker,
      [&](const std::string& staging) -> Status {
        for (const auto& [name, bytes] : files.files())
          SPHEREKIT_RETURN_IF_ERROR(write_file_atomic((fs::path(staging) / name).string(), bytes));
        return Status();
      },
      keep_going);
}

}  // namespace spherekit::formats
