// Staged folder writes (staged_folder.h): build beside, swap in once complete.
#include "spherekit/formats/staged_folder.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"

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
  std::error_code ec;
  const fs::path target = fs::absolute(dir, ec).lexically_normal();
  const fs::path base = target.has_filename() ? target : target.parent_path();
  // (append, not operator+: GCC 12 warns falsely about "." + std::string, -Wrestrict)
  const std::string pid = std::to_string(::getpid());
  const fs::path staging = base.parent_path() / std::string(".").append(base.filename().string()).append(".partial.").append(pid);
  fs::remove_all(staging, ec);
  if (!fs::create_directory(staging, ec))
    return Status(ErrorCode::IoError, staging.string() + ": cannot create staging folder (" + ec.message() + ")");
  // A cancellation while the files are written (the caller's keep_going) removes the
  // staging folder here, instead of leaving it behind.
  Status s = write_into(staging.string());
  if (s.ok() && keep_going && !keep_going()) s = Status(ErrorCode::Cancelled, "cancelled");
  if (!s.ok()) {
    fs::remove_all(staging, ec);
    return s;
  }
  // Swap: the old folder aside, the new one in, the old one removed. Readers see the old
  // folder or the new one (a brief moment with none in between). SIGINT/SIGTERM wait
  // until it is done: an exit between the renames would leave no folder at DIR, the old one
  // hidden as .DIR.old.PID.
  sigset_t stop_signals, saved_mask;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, &saved_mask);
  const Status swapped = [&]() -> Status {
    const fs::path old = base.parent_path() / std::string(".").append(base.filename().string()).append(".old.").append(pid);
    const bool had_old = fs::exists(base, ec);
    if (had_old) {
      fs::remove_all(old, ec);
      fs::rename(base, old, ec);
      if (ec) {
        fs::remove_all(staging, ec);
        return Status(ErrorCode::IoError, dir + ": cannot replace the existing folder (" + ec.message() + ")");
      }
    }
    fs::rename(staging, base, ec);
    if (ec) {
      const std::string why = ec.message();
      if (had_old) fs::rename(old, base, ec);
      fs::remove_all(staging, ec);
      return Status(ErrorCode::IoError, dir + ": cannot move the new folder into place (" + why + ")");
    }
    if (had_old) fs::remove_all(old, ec);
    return Status();
  }();
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
