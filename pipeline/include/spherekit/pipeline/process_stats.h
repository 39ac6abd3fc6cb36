// What the reports record about the process that made them.
#pragma once

namespace spherekit::pipeline {

/// CPU seconds (user + system, all threads) this process has used so far.
double cpu_seconds();
/// Peak resident set size of this process in MB (VmHWM), or 0 if unknown.
double peak_rss_mb();

}  // namespace spherekit::pipeline
