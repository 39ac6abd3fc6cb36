// libFuzzer harness: the glTF JSON (.gltf; buffers as data URIs or files beside it) reader.
// The path names a folder that does not exist, so a relative buffer uri fails to open instead
// of reading whatever lies in the fuzzer's working folder.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  spherekit::fuzz::fuzz_mesh("/nonexistent-spherekit-fuzz/fuzz.gltf", data, size);
  return 0;
}
