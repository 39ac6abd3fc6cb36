// libFuzzer harness: landmark files (`name vertex_index`). The first byte, if any, picks the
// mesh's vertex count (0..254, or 255: unchecked), the rest is the file.
#include <set>
#include <vector>

#include "feature_codecs.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace spherekit;
  if (size == 0) return 0;
  const int num_vertices = data[0] == 255 ? -1 : data[0];
  const std::string path = "fuzz.lm.txt";
  auto read = formats::detail::parse_landmarks(path, fuzz::bytes_of(data + 1, size - 1), num_vertices);
  if (!read.ok()) {
    fuzz::require_good_error(read.status(), path);
    return 0;
  }
  // Contract: indices in range, names and vertices unique, names readable back (one token).
  std::set<std::string> names;
  std::set<int> vertices;
  for (const Landmark& l : read.value()) {
    fuzz::require(l.vertex >= 0 && (num_vertices < 0 || l.vertex < num_vertices));
    fuzz::require(!l.name.empty() && l.name.front() != '#');
    fuzz::require(names.insert(l.name).second && vertices.insert(l.vertex).second);
  }
  return 0;
}
