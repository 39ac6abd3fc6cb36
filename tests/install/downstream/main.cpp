// Downstream use of the installed library: generate a bumpy closed mesh, map it onto the
// sphere with spherekit::parameterize_sphere, and check the map is a bijection by recounting
// its flipped faces with the exact predicate (count_flipped_faces), not only trusting the
// result's own count. Built twice: `downstream_param` links SphereKit::param alone;
// `downstream_convert` (SPHEREKIT_DOWNSTREAM_CONVERT) links SphereKit::convert and also writes
// and reads back a geometry image (OpenEXR, through convert's static link interface).
// Prints one line; exit 0 on success.   downstream_{param,convert} [SCRATCH_DIR]
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <utility>
#include <vector>

#include "spherekit/metrics.h"
#include "spherekit/sphere_param.h"
#include "spherekit/version.h"
#ifdef SPHEREKIT_DOWNSTREAM_CONVERT
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/geometry_image.h"
#endif

namespace {

// An octahedron split `levels` times (each triangle into four), pushed onto a lumpy,
// stretched shape: genus 0, closed, 8 * 4^levels faces.
spherekit::TriMesh lumpy_mesh(int levels) {
  std::vector<Eigen::Vector3d> v = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<std::array<int, 3>> f = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& t : f) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({ab, t[1], bc});
      next.push_back({ca, bc, t[2]});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  spherekit::TriMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector3d& p = v[i];
    const double r = 1.0 + 0.3 * std::sin(3 * p.x()) * std::cos(2 * p.y()) + 0.2 * p.z() * p.z();
    mesh.V.row(static_cast<Eigen::Index>(i)) = Eigen::Vector3d(2.0 * p.x(), p.y(), 0.7 * p.z()) * r;
  }
  mesh.F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i)
    mesh.F.row(static_cast<Eigen::Index>(i)) << f[i][0], f[i][1], f[i][2];
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  if (std::strcmp(spherekit::kVersion, EXPECTED_VERSION) != 0) {
    std::fprintf(stderr, "downstream: installed version.h says %s, the package config %s\n", spherekit::kVersion,
                 EXPECTED_VERSION);
    return 1;
  }
  const spherekit::TriMesh mesh = lumpy_mesh(4);  // 1026 vertices, 2048 faces
  int progress_calls = 0;
  auto result = spherekit::parameterize_sphere(mesh, {}, [&](const spherekit::ProgressEvent&) {
    ++progress_calls;
    return true;
  });
  if (!result.ok()) {
    std::fprintf(stderr, "downstream: parameterize_sphere failed: %s\n", result.status().message().c_str());
    return 1;
  }
  const int flips = spherekit::count_flipped_faces(mesh.F, result->map.S);
  std::printf("downstream: spherekit %s, %d vertices, %d faces, efficiency %.4f, flipped faces %d (result says %d), %d progress calls\n",
              spherekit::kVersion, static_cast<int>(mesh.V.rows()), static_cast<int>(mesh.F.rows()),
              result->efficiency, flips, result->flipped_faces, progress_calls);
  if (flips != 0 || result->flipped_faces != 0 || result->map.S.rows() != mesh.V.rows() || progress_calls == 0) return 1;
#ifdef SPHEREKIT_DOWNSTREAM_CONVERT
  if (argc < 2) return 2;
  auto image = spherekit::sample_geometry_image(mesh, result->map.S, 17);
  if (!image.ok()) return 1;
  const std::string path = std::string(argv[1]) + "/downstream.exr";
  if (auto s = spherekit::convert::write_geometry_image_exr(path, image.value()); !s.ok()) {
    std::fprintf(stderr, "downstream: %s\n", s.message().c_str());
    return 1;
  }
  auto back = spherekit::convert::read_geometry_image_exr(path);
  if (!back.ok() || back->image.size != 17 || back->image.positions != image->positions) {
    std::fprintf(stderr, "downstream: the geometry image did not read back equal\n");
    return 1;
  }
  std::printf("downstream: 17 x 17 geometry image written and read back equal (%s)\n", path.c_str());
#else
  (void)argc;
  (void)argv;
#endif
  return 0;
}
