// libFuzzer harness: sphere-point files (`name x y z`). The first byte's low bit selects
// require_unit, the rest is the file.
#include <cmath>
#include <set>

#include "feature_codecs.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace spherekit;
  if (size == 0) return 0;
  const bool require_unit = (data[0] & 1) != 0;
  const std::string path = "fuzz.points.txt";
  auto read = formats::detail::parse_sphere_points(path, fuzz::bytes_of(data + 1, size - 1), require_unit);
  if (!read.ok()) {
    fuzz::require_good_error(read.status(), path);
    return 0;
  }
  // Contract: finite unit vectors (normalised on reading), unique names.
  std::set<std::string> names;
  for (const SpherePoint& p : read.value()) {
    fuzz::require(p.p.allFinite());
    fuzz::require(std::abs(p.p.norm() - 1) < 1e-12);
    fuzz::require(!p.name.empty() && names.insert(p.name).second);
  }
  return 0;
}
