// The listener behind SPHEREKIT_SKIP (test_skip.h): prints "SPHEREKIT-SKIP: reason" when a
// test case that noted a skip ends without a failed assertion.
#define CATCH_CONFIG_EXTERNAL_INTERFACES
#include "test_skip.h"

#include <cstdio>
#include <vector>

namespace spherekit::test {
namespace {

std::vector<std::string>& skip_reasons() {
  static std::vector<std::string> reasons;
  return reasons;
}

struct SkipListener : Catch::TestEventListenerBase {
  using TestEventListenerBase::TestEventListenerBase;
  void testCaseStarting(const Catch::TestCaseInfo& info) override {
    TestEventListenerBase::testCaseStarting(info);
    skip_reasons().clear();
  }
  void testCaseEnded(const Catch::TestCaseStats& stats) override {
    if (stats.totals.assertions.failed == 0)
      for (const std::string& reason : skip_reasons()) std::printf("SPHEREKIT-SKIP: %s\n", reason.c_str());
    std::fflush(stdout);
    skip_reasons().clear();
    TestEventListenerBase::testCaseEnded(stats);
  }
};

}  // namespace

CATCH_REGISTER_LISTENER(SkipListener)

void note_skip(const std::string& reason) { skip_reasons().push_back(reason); }

}  // namespace spherekit::test
