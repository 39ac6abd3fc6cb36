// libFuzzer harness: landmark targets (`name vertex_index x y z`, eval --targets). The first
// byte, if any, picks the mesh's vertex count (0..254, or 255: unchecked), the rest is the file.
#include <cmath>
#include <set>

#include "feature_codecs.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace spherekit;
  if (size == 0) return 0;
  const int num_vertices = data[0] == 255 ? -1 : data[0];
  const std::string path = "fuzz.targets.txt";
  auto read = formats::detail::parse_landmark_targets(path, fuzz::bytes_of(data + 1, size - 1), num_vertices);
  if (!read.ok()) {
    fuzz::require_good_error(read.status(), path);
    return 0;
  }
  std::set<std::string> names;
  std::set<int> vertices;
  for (const formats::LandmarkTarget& t : read.value()) {
    fuzz::require(t.vertex >= 0 && (num_vertices < 0 || t.vertex < num_vertices));
    fuzz::require(t.p.allFinite() && std::abs(t.p.norm() - 1) < 1e-12);
    fuzz::require(names.insert(t.name).second && vertices.insert(t.vertex).second);
  }
  return 0;
}
