// Process measures for the reports (process_stats.h).
#include "spherekit/pipeline/process_stats.h"

#include <sys/resource.h>

#include <cstdio>
#include <fstream>
#include <string>

namespace spherekit::pipeline {

double cpu_seconds() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  auto secs = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return secs(usage.ru_utime) + secs(usage.ru_stime);
}

double peak_rss_mb() {
  // VmHWM ("high water mark") is the peak resident set in kB; getrusage's ru_maxrss is the
  // same number but /proc states its unit explicitly.
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      long kb = 0;
      if (std::sscanf(line.c_str() + 6, "%ld", &kb) == 1) return static_cast<double>(kb) / 1024.0;
    }
  }
  return 0;
}

}  // namespace spherekit::pipeline
