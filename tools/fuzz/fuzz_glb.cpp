// libFuzzer harness: the binary glTF (.glb) reader.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  spherekit::fuzz::fuzz_mesh("fuzz.glb", data, size);
  return 0;
}
