// libFuzzer harness: the PLY (ascii, binary little and big endian) reader.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  spherekit::fuzz::fuzz_mesh("fuzz.ply", data, size);
  return 0;
}
