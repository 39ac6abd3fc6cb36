// Folders written all-or-nothing: the files are written into a staging folder beside the
// target, which is renamed into place only once complete (the collection folder of
// `consistent`, the asset folder of `convert --collection`, the application folders).
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::formats {

/// Polled between files; returns false once the caller wants to stop (Cancelled).
using KeepGoingFn = std::function<bool()>;

/// IoError unless `dir` can become a staged folder: its parent exists, and it is absent,
/// empty, or holds `marker` (the file identifying a folder the same writer wrote before, which
/// may be replaced). A non-empty folder without the marker is never replaced.
Status require_staged_folder_target(const std::string& dir, const std::string& marker);

/// Creates the folder `dir` with the files `write_into(staging)` writes into an empty staging
/// folder beside it; the staging folder is renamed into place only once every file is
/// written, replacing an existing folder that require_staged_folder_target() accepts. On
/// failure, or when `keep_going` returns false after `write_into`, the staging folder is
/// removed and `dir` is untouched. SIGINT/SIGTERM are blocked during the swap itself, so that
/// an exit cannot leave no folder at `dir`. Errors: IoError, Cancelled, or write_into's.
Status write_staged_folder(const std::string& dir, const std::string& marker,
                           const std::function<Status(const std::string&)>& write_into,
                           const KeepGoingFn& keep_going = {});

/// Files written together: either all of them end up in place or none does (already renamed
/// files are removed again when a later one fails). Each file is written atomically.
class OutputFiles {
 public:
  void add(std::string path, std::string bytes) { files_.emplace_back(std::move(path), std::move(bytes)); }
  /// Writes every file. Errors: the first write's IoError (naming the file).
  Status write_all() const;
  const std::vector<std::pair<std::string, std::string>>& files() const { return files_; }

 private:
  std::vector<std::pair<std::string, std::string>> files_;
};

/// Replaces the folder `dir` by one holding `files` (names relative to it) through
/// write_staged_folder(). Errors: IoError naming the folder or file, Cancelled.
Status write_output_folder(const std::string& dir, const std::string& marker, const OutputFiles& files,
                           const KeepGoingFn& keep_going = {});

}  // namespace spherekit::formats
