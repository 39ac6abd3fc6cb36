// libFuzzer harness: the OFF reader.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  spherekit::fuzz::fuzz_mesh("fuzz.off", data, size);
  return 0;
}
