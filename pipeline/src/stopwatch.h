// Wall-clock seconds of a stage, for the results' `times` (steady clock: immune to clock changes).
#pragma once

#include <chrono>

namespace spherekit::pipeline {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace spherekit::pipeline
