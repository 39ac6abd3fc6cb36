// The mapped sample collection shared by the application tests (see the header).
//
// ctest runs every test case in its own process, and the consistent stage takes a few seconds,
// so the maps are cached on disk between processes: build/test_tmp/app_collection/<key>.bin,
// key = a hash of the members' vertices and faces and of the options below, so a change to the
// samples or the options computes fresh maps. The stage is deterministic, so a cached map is
// the map this build would compute for the same meshes (up to a change of the stage's code,
// which can only give another valid consistent map). Written to a temporary name and renamed:
// concurrent test processes never read a partial file.
#include "collection_fixture.h"

#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "spherekit/consistent_param.h"

namespace fs = std::filesystem;

namespace spherekit::test {
namespace {

constexpr int kRemeshSize = 33, kEffort = 1, kMembers = 3, kVertices = 1200;

std::uint64_t fnv1a(std::uint64_t h, const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

std::string cache_path(const std::vector<samples::SampleMesh>& members) {
  std::uint64_t h = 1469598103934665603ull;
  const int options[] = {kRemeshSize, kEffort, kMembers, kVertices};
  h = fnv1a(h, options, sizeof options);
  for (const auto& m : members) {
    h = fnv1a(h, m.mesh.V.data(), sizeof(double) * static_cast<std::size_t>(m.mesh.V.size()));
    h = fnv1a(h, m.mesh.F.data(), sizeof(std::int32_t) * static_cast<std::size_t>(m.mesh.F.size()));
  }
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.bin", static_cast<unsigned long long>(h));
  return (fs::path(SPHEREKIT_BINARY_DIR) / "test_tmp" / "app_collection" / name).string();
}

bool read_cache(const std::string& path, std::vector<RowMat3d>& maps, const std::vector<samples::SampleMesh>& members) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string bytes = ss.str();
  std::size_t need = 0;
  for (const auto& m : members) need += sizeof(double) * 3 * static_cast<std::size_t>(m.mesh.V.rows());
  if (bytes.size() != need) return false;
  std::size_t at = 0;
  for (const auto& m : members) {
    RowMat3d S(m.mesh.V.rows(), 3);
    std::memcpy(S.data(), bytes.data() + at, sizeof(double) * static_cast<std::size_t>(S.size()));
    at += sizeof(double) * static_cast<std::size_t>(S.size());
    maps.push_back(std::move(S));
  }
  return true;
}

void write_cache(const std::string& path, const std::vector<RowMat3d>& maps) {
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    for (const RowMat3d& S : maps) out.write(reinterpret_cast<const char*>(S.data()), static_cast<std::streamsize>(sizeof(double) * S.size()));
  }
  fs::rename(tmp, path, ec);
  if (ec) fs::remove(tmp, ec);
}

}  // namespace

const MappedCollection& mapped_sample_collection() {
  static const MappedCollection c = [] {
    MappedCollection out;
    samples::SampleCollectionOptions o;
    o.members = kMembers;
    o.target_vertices = kVertices;
    auto made = samples::make_sample_collection(o);
    REQUIRE(made.ok());
    out.members = std::move(made).value();
    std::vector<TriMesh> meshes;
    std::vector<std::vector<int>> features;
    for (const samples::SampleMesh& m : out.members) {
      meshes.push_back(m.mesh);
      std::vector<int> f;
      RowMat3d pos(static_cast<Eigen::Index>(m.landmarks.size()), 3);
      for (std::size_t k = 0; k < m.landmarks.size(); ++k) {
        f.push_back(m.landmarks[k].vertex);
        pos.row(static_cast<Eigen::Index>(k)) = m.mesh.V.row(m.landmarks[k].vertex);
      }
      features.push_back(f);
      out.features.push_back(pos);
    }
    const std::string cache = cache_path(out.members);
    if (read_cache(cache, out.maps, out.members)) return out;
    ConsistentParamOptions po;
    po.remesh_size = kRemeshSize;
    po.constrained.sphere.effort = kEffort;
    po.threads = 2;
    auto r = parameterize_consistent(meshes, features, po);
    INFO(r.status().message());
    REQUIRE(r.ok());
    for (const auto& m : r->maps) out.maps.push_back(m.map.S);
    write_cache(cache, out.maps);
    return out;
  }();
  return c;
}

}  // namespace spherekit::test
