// Progress reporting and cancellation: the library never prints; it calls back.
#pragma once

#include <functional>
#include <string_view>

namespace spherekit {

/// One progress report. Called on the calling thread between units of work.
struct ProgressEvent {
  std::string_view stage;  ///< e.g. "simplify", "refine", "optimize"
  int level = 0;           ///< stage-specific level (e.g. current vertex count)
  double fraction = 0;     ///< 0..1 progress within the stage; negative = unknown (a heartbeat)
};

/// Return false to cancel; the stage then returns ErrorCode::Cancelled.
using ProgressFn = std::function<bool(const ProgressEvent&)>;

/// Calls `fn` if set; true means "keep going".
inline bool report_progress(const ProgressFn& fn, std::string_view stage, int level, double fraction) {
  return !fn || fn(ProgressEvent{stage, level, fraction});
}

}  // namespace spherekit
