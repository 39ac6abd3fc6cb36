#include "compressed_glb.h"

#include <meshoptimizer.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <vector>

namespace spherekit::test {
namespace {

std::uint32_t u32_at(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}
void put_u32(std::string& s, std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

/// Appends `bytes` to `bin` at a 4-byte boundary and returns its offset.
std::size_t append_aligned(std::string& bin, const std::string& bytes) {
  while (bin.size() % 4 != 0) bin.push_back('\0');
  const std::size_t at = bin.size();
  bin += bytes;
  return at;
}

template <typename T>
std::string as_bytes(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

constexpr int kBits = 14;

}  // namespace

GlbParts glb_parts(const std::string& glb) {
  REQUIRE(glb.size() >= 20);
  REQUIRE(u32_at(glb, 0) == 0x46546C67u);
  const std::uint32_t json_length = u32_at(glb, 12);
  REQUIRE(20 + std::size_t{json_length} <= glb.size());
  GlbParts parts;
  parts.json = nlohmann::json::parse(glb.substr(20, json_length));
  const std::size_t bin_at = 20 + json_length;
  if (bin_at + 8 <= glb.size()) parts.bin = glb.substr(bin_at + 8, u32_at(glb, bin_at));
  return parts;
}

std::string glb_bytes(const GlbParts& parts) {
  std::string json = parts.json.dump();
  while (json.size() % 4 != 0) json.push_back(' ');
  std::string bin = parts.bin;
  while (bin.size() % 4 != 0) bin.push_back('\0');
  std::string out;
  put_u32(out, 0x46546C67u);
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
  put_u32(out, static_cast<std::uint32_t>(json.size()));
  put_u32(out, 0x4E4F534Au);
  out += json;
  if (!bin.empty()) {
    put_u32(out, static_cast<std::uint32_t>(bin.size()));
    put_u32(out, 0x004E4942u);
    out += bin;
  }
  return out;
}

std::string normalized_short_glb(const TriMesh& mesh, double& tolerance) {
  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  const Eigen::RowVector3d centre = (lo + hi) / 2;
  const double half = (hi - lo).maxCoeff() / 2;
  const auto nv = static_cast<std::size_t>(mesh.V.rows());
  std::vector<std::int16_t> q(4 * nv, 0);  // padded to 8 bytes: attributes align to 4
  for (std::size_t v = 0; v < nv; ++v)
    for (int c = 0; c < 3; ++c)
      q[4 * v + static_cast<std::size_t>(c)] = static_cast<std::int16_t>(
          std::lround((mesh.V(static_cast<Eigen::Index>(v), c) - centre[c]) / half * 32767.0));
  std::vector<std::uint32_t> indices(static_cast<std::size_t>(mesh.F.size()));
  for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<std::uint32_t>(mesh.F.data()[i]);
  GlbParts parts;
  append_aligned(parts.bin, as_bytes(q));
  const std::size_t i_at = append_aligned(parts.bin, as_bytes(indices));
  using nlohmann::json;
  json doc;
  doc["asset"] = {{"version", "2.0"}};
  doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  doc["buffers"] = json::array({json{{"byteLength", parts.bin.size()}}});
  doc["bufferViews"] = json::array({json{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 8 * nv}, {"byteStride", 8}},
                                    json{{"buffer", 0}, {"byteOffset", i_at}, {"byteLength", 4 * indices.size()}}});
  doc["accessors"] = json::array(
      {json{{"bufferView", 0}, {"componentType", 5122}, {"normalized", true}, {"count", nv}, {"type", "VEC3"}},
       json{{"bufferView", 1}, {"componentType", 5125}, {"count", indices.size()}, {"type", "SCALAR"}}});
  doc["meshes"] = json::array({json{{"primitives", json::array({json{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}})}}});
  doc["nodes"] = json::array({json{{"mesh", 0}, {"translation", {centre[0], centre[1], centre[2]}}, {"scale", {half, half, half}}}});
  doc["scenes"] = json::array({json{{"nodes", {0}}}});
  parts.json = doc;
  tolerance = 0.5 * half / 32767.0 * (1 + 1e-9);
  return glb_bytes(parts);
}

void require_read_error(const Status& status, ErrorCode code, const std::string& path, const std::string& phrase) {
  INFO("message: " << status.message());
  REQUIRE_FALSE(status.ok());
  CHECK(status.code() == code);
  CHECK(status.message().rfind(path + ": ", 0) == 0);
  CHECK(status.message().find(phrase) != std::string::npos);
  CHECK(status.message().find('\n') == std::string::npos);
}

double meshopt_glb_tolerance(const TriMesh& mesh, MeshoptGlb kind) {
  const double extent = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).maxCoeff();
  if (kind == MeshoptGlb::ExponentialIndices) {
    // 15-bit mantissa shared by the vector: the largest component keeps 14 bits after the sign.
    return mesh.V.cwiseAbs().maxCoeff() * std::ldexp(1.0, -14);
  }
  return 0.5 * extent / ((1 << kBits) - 1) + 1e-12 * extent;  // half a grid step
}

std::string meshopt_glb(const TriMesh& mesh, MeshoptGlb kind) {
  const auto nv = static_cast<std::size_t>(mesh.V.rows());
  const auto nc = static_cast<std::size_t>(mesh.F.size());
  const bool khr = kind == MeshoptGlb::QuantizedTrianglesKhr;
  const std::string ext = khr ? "KHR_meshopt_compression" : "EXT_meshopt_compression";
  const bool quantized = kind != MeshoptGlb::ExponentialIndices;
  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff();
  const double extent = (mesh.V.colwise().maxCoeff() - lo).maxCoeff();
  const double scale = extent / ((1 << kBits) - 1);

  // Vertex stream.
  std::string vertex_bytes;
  std::size_t stride = 0;
  if (quantized) {
    std::vector<std::uint16_t> q(4 * nv, 0);
    for (std::size_t v = 0; v < nv; ++v)
      for (int c = 0; c < 3; ++c)
        q[4 * v + static_cast<std::size_t>(c)] =
            static_cast<std::uint16_t>(std::lround((mesh.V(static_cast<Eigen::Index>(v), c) - lo[c]) / scale));
    vertex_bytes = as_bytes(q);
    stride = 8;
  } else {
    std::vector<float> f(3 * nv);
    for (std::size_t v = 0; v < nv; ++v)
      for (int c = 0; c < 3; ++c) f[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(mesh.V(static_cast<Eigen::Index>(v), c));
    std::vector<std::uint32_t> filtered(3 * nv);
    meshopt_encodeFilterExp(filtered.data(), nv, 12, 15, f.data());
    vertex_bytes = as_bytes(filtered);
    stride = 12;
  }
  std::vector<unsigned char> vbuf(meshopt_encodeVertexBufferBound(nv, stride));
  vbuf.resize(meshopt_encodeVertexBuffer(vbuf.data(), vbuf.size(), vertex_bytes.data(), nv, stride));

  // Index stream.
  std::vector<unsigned int> indices(nc);
  for (std::size_t i = 0; i < nc; ++i) indices[i] = static_cast<unsigned int>(mesh.F.data()[i]);
  std::vector<unsigned char> ibuf;
  std::size_t index_size = 4;
  if (quantized) {
    ibuf.resize(meshopt_encodeIndexBufferBound(nc, nv));
    ibuf.resize(meshopt_encodeIndexBuffer(ibuf.data(), ibuf.size(), indices.data(), nc));
  } else {
    index_size = 2;
    ibuf.resize(meshopt_encodeIndexSequenceBound(nc, nv));
    ibuf.resize(meshopt_encodeIndexSequence(ibuf.data(), ibuf.size(), indices.data(), nc));
  }

  GlbParts parts;
  const std::size_t v_at = append_aligned(parts.bin, std::string(vbuf.begin(), vbuf.end()));
  const std::size_t i_at = append_aligned(parts.bin, std::string(ibuf.begin(), ibuf.end()));
  const std::size_t decoded_v = nv * stride, decoded_i = nc * index_size;
  using nlohmann::json;
  json doc;
  doc["asset"] = {{"version", "2.0"}};
  doc["extensionsUsed"] = quantized ? json{ext, "KHR_mesh_quantization"} : json{ext};
  doc["extensionsRequired"] = doc["extensionsUsed"];
  doc["buffers"] = json::array({json{{"byteLength", parts.bin.size() + (4 - parts.bin.size() % 4) % 4}},
                                json{{"byteLength", decoded_v + decoded_i},
                                     {"extensions", {{ext, {{"fallback", true}}}}}}});
  doc["bufferViews"] = json::array(
      {json{{"buffer", 1}, {"byteOffset", 0}, {"byteLength", decoded_v}, {"byteStride", stride},
            {"extensions", {{ext, {{"buffer", 0}, {"byteOffset", v_at}, {"byteLength", vbuf.size()},
                                   {"byteStride", stride}, {"count", nv}, {"mode", "ATTRIBUTES"},
                                   {"filter", quantized ? "NONE" : "EXPONENTIAL"}}}}}},
       json{{"buffer", 1}, {"byteOffset", decoded_v}, {"byteLength", decoded_i},
            {"extensions", {{ext, {{"buffer", 0}, {"byteOffset", i_at}, {"byteLength", ibuf.size()},
                                   {"byteStride", index_size}, {"count", nc},
                                   {"mode", quantized ? "TRIANGLES" : "INDICES"}}}}}}});
  doc["accessors"] = json::array(
      {json{{"bufferView", 0}, {"componentType", quantized ? 5123 : 5126}, {"count", nv}, {"type", "VEC3"}},
       json{{"bufferView", 1}, {"componentType", quantized ? 5125 : 5123}, {"count", nc}, {"type", "SCALAR"}}});
  doc["meshes"] = json::array({json{{"primitives", json::array({json{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}})}}});
  json node{{"mesh", 0}};
  if (kind == MeshoptGlb::QuantizedTriangles) {
    node["matrix"] = {scale, 0, 0, 0, 0, scale, 0, 0, 0, 0, scale, 0, lo[0], lo[1], lo[2], 1};
  } else if (khr) {
    node["translation"] = {lo[0], lo[1], lo[2]};
    node["scale"] = {scale, scale, scale};
  }
  doc["nodes"] = json::array({node});
  doc["scenes"] = json::array({json{{"nodes", {0}}}});
  doc["scene"] = 0;
  parts.json = doc;
  return glb_bytes(parts);
}

}  // namespace spherekit::test
