// Test helpers for the glTF writers (see gltf_test_support.h).
#include "gltf_test_support.h"

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/mesh/mesh.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>

#include "cli_runner.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace spherekit::test {
namespace {

std::uint32_t read_u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, s.data() + at, 4);  // GLB is little-endian, like the test machines
  return v;
}

constexpr int kFloat = 5126, kUnsignedShort = 5123, kUnsignedInt = 5125;

}  // namespace

GeometryImage blob_geometry_image(int size, int level, std::uint64_t seed) {
  const TriMesh blob = random_blob(level, seed);
  auto r = sample_geometry_image(blob, blob.V.rowwise().normalized(), size);
  REQUIRE(r.ok());
  return std::move(r).value();
}

GeometryImage lod_test_image() { return blob_geometry_image(65); }

HoledLodImages holed_lod_images(int size, int levels) {
  HoledLodImages out;
  out.mesh = sphere_with_holes(2, 3);
  out.S = out.mesh.V.rowwise().normalized();
  GeometryImageOptions fit;
  fit.fit_positions = true;
  auto fine = sample_geometry_image(out.mesh, out.S, size, fit);
  REQUIRE(fine.ok());
  REQUIRE(fine->texels_in_holes > 0);
  auto images = convert::lod_geometry_images(out.mesh, out.S, std::move(fine).value(), levels, fit);
  REQUIRE(images.ok());
  out.levels = std::move(images).value();
  return out;
}

convert::GltfLodOptions lod_test_options() {
  convert::GltfLodOptions options;
  options.levels = 3;
  options.reference_rms_error = 1e-4;
  // The budget's bits: these tests check the budget's rule and the shared grid across levels;
  // position_bits_test.cpp covers the rate-distortion rule.
  options.position_bits_rule = convert::PositionBitsRule::ErrorBudget;
  options.name = "blob";
  options.provenance = {"blob.obj", "blob.sphere.obj"};
  return options;
}

std::vector<convert::GltfMesh> collection_test_meshes(int size, int members) {
  std::vector<convert::GltfMesh> out;
  for (int k = 0; k < members; ++k) {
    auto m = convert::gltf_mesh_from_geometry_image(blob_geometry_image(size, 3, 7 + static_cast<std::uint64_t>(k)));
    REQUIRE(m.ok());
    out.push_back(std::move(m).value());
  }
  return out;
}

void write_blob_inputs(const std::string& dir) {
  const TriMesh blob = random_blob(3, 21);
  REQUIRE(formats::write_mesh(dir + "/blob.obj", blob).ok());
  SphereMap map;
  map.S = blob.V.rowwise().normalized();
  map.provenance.method = "radial";
  REQUIRE(formats::write_sphere_map(dir + "/blob.sphere.obj", blob, map).ok());
}

GlbFile parse_glb(const std::string& bytes) {
  // glTF 2.0 "Binary glTF Layout": 12-byte header (magic, version 2, length), then chunks
  // (length, type, data) with the JSON chunk first, every chunk 4-byte aligned.
  REQUIRE(bytes.size() >= 20);
  REQUIRE(bytes.compare(0, 4, "glTF") == 0);
  REQUIRE(read_u32(bytes, 4) == 2);
  REQUIRE(read_u32(bytes, 8) == bytes.size());
  GlbFile out;
  std::size_t at = 12;
  bool first = true;
  while (at < bytes.size()) {
    REQUIRE(at + 8 <= bytes.size());
    const std::uint32_t length = read_u32(bytes, at), type = read_u32(bytes, at + 4);
    REQUIRE(length % 4 == 0);
    REQUIRE(at + 8 + length <= bytes.size());
    const std::string chunk = bytes.substr(at + 8, length);
    if (first) {
      REQUIRE(type == 0x4E4F534Au);  // "JSON"
      out.json = nlohmann::json::parse(chunk);
    } else if (type == 0x004E4942u) {  // "BIN\0"
      out.bin = chunk;
    }
    first = false;
    at += 8 + length;
  }
  return out;
}

std::string buffer_view_bytes(const GlbFile& glb, int view) {
  const auto& bv = glb.json.at("bufferViews").at(static_cast<std::size_t>(view));
  REQUIRE(bv.at("buffer").get<int>() == 0);
  const std::size_t offset = bv.value("byteOffset", 0), length = bv.at("byteLength").get<std::size_t>();
  REQUIRE(offset % 4 == 0);
  REQUIRE(offset + length <= glb.bin.size());
  return glb.bin.substr(offset, length);
}

std::vector<DecodedPrimitive> decode_and_check_draco(const GlbFile& glb) {
  std::vector<DecodedPrimitive> out;
  const auto& j = glb.json;
  const auto& accessors = j.at("accessors");
  for (std::size_t mi = 0; mi < j.at("meshes").size(); ++mi) {
    const auto& prims = j["meshes"][mi].at("primitives");
    for (std::size_t pi = 0; pi < prims.size(); ++pi) {
      const auto& prim = prims[pi];
      if (!prim.contains("extensions") || !prim["extensions"].contains("KHR_draco_mesh_compression")) continue;
      INFO("mesh " << mi << " primitive " << pi);
      const auto& ext = prim["extensions"]["KHR_draco_mesh_compression"];
      CHECK(prim.value("mode", 4) == 4);
      const std::string data = buffer_view_bytes(glb, ext.at("bufferView").get<int>());
      draco::DecoderBuffer buffer;
      buffer.Init(data.data(), data.size());
      draco::Decoder decoder;
      auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
      REQUIRE(decoded.ok());
      std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
      REQUIRE(mesh);
      const auto points = static_cast<Eigen::Index>(mesh->num_points());
      DecodedPrimitive d;
      d.mesh = static_cast<int>(mi);
      d.primitive = static_cast<int>(pi);

      // The extension's attributes and the primitive's are the same set.
      CHECK(ext.at("attributes").size() == prim.at("attributes").size());
      for (const auto& [name, uid] : ext.at("attributes").items()) {
        INFO("attribute " << name);
        REQUIRE(prim.at("attributes").contains(name));
        const draco::PointAttribute* att = mesh->GetAttributeByUniqueId(uid.get<std::uint32_t>());
        REQUIRE(att != nullptr);
        const auto& acc = accessors.at(prim["attributes"][name].get<std::size_t>());
        CHECK_FALSE(acc.contains("bufferView"));
        CHECK_FALSE(acc.contains("byteOffset"));
        CHECK(acc.at("componentType").get<int>() == kFloat);
        CHECK(acc.at("count").get<Eigen::Index>() == points);
        const int dims = att->num_components();
        CHECK(acc.at("type").get<std::string>() == (dims == 2 ? "VEC2" : "VEC3"));
        Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> M(points, dims);
        float v[4];
        for (Eigen::Index p = 0; p < points; ++p) {
          REQUIRE(att->ConvertValue<float>(att->mapped_index(draco::PointIndex(static_cast<std::uint32_t>(p))),
                                           static_cast<std::int8_t>(dims), v));
          for (int c = 0; c < dims; ++c) M(p, c) = v[c];
        }
        if (name == "POSITION") {
          REQUIRE(dims == 3);
          d.V = M;
          // min/max are the decoded floats' bounds, exactly.
          REQUIRE(acc.contains("min"));
          REQUIRE(acc.contains("max"));
          for (int c = 0; c < 3; ++c) {
            CHECK(acc["min"][static_cast<std::size_t>(c)].get<float>() == d.V.col(c).minCoeff());
            CHECK(acc["max"][static_cast<std::size_t>(c)].get<float>() == d.V.col(c).maxCoeff());
          }
        } else if (name == "NORMAL") {
          REQUIRE(dims == 3);
          d.N = M;
        } else if (name == "TEXCOORD_0") {
          REQUIRE(dims == 2);
          d.UV = M;
        }
      }
      const auto& idx = accessors.at(prim.at("indices").get<std::size_t>());
      CHECK_FALSE(idx.contains("bufferView"));
      CHECK(idx.at("type").get<std::string>() == "SCALAR");
      CHECK(idx.at("count").get<std::size_t>() == 3 * static_cast<std::size_t>(mesh->num_faces()));
      CHECK(idx.at("componentType").get<int>() == (points <= 65535 ? kUnsignedShort : kUnsignedInt));
      d.F.resize(static_cast<Eigen::Index>(mesh->num_faces()), 3);
      for (std::uint32_t f = 0; f < mesh->num_faces(); ++f)
        for (int k = 0; k < 3; ++k) d.F(static_cast<Eigen::Index>(f), k) = mesh->face(draco::FaceIndex(f))[k].value();
      REQUIRE(d.V.rows() == points);
      out.push_back(std::move(d));
    }
  }
  return out;
}

const NpmTools& npm_tools() {
  static NpmTools tools;
  static std::once_flag once;
  std::call_once(once, [] {
    if (const char* env = std::getenv("SPHEREKIT_NPM_DIR"); env && *env)
      tools.node_dir = env;
    else if (const char* home = std::getenv("HOME"); home && *home)
      tools.node_dir = std::string(home) + "/.cache/spherekit/npm-tools";
    else
      tools.node_dir = std::string(SPHEREKIT_BINARY_DIR) + "/npm-tools";
    const std::string log_dir = temp_dir("npm_setup");
    const int rc = run_shell("bash " + shell_quote(std::string(SPHEREKIT_SOURCE_DIR) + "/scripts/setup_npm_tools.sh") +
                                 " " + shell_quote(tools.node_dir),
                             log_dir + "/out.txt", log_dir + "/err.txt");
    tools.available = rc == 0;
    if (!tools.available) tools.why = slurp(log_dir + "/err.txt") + slurp(log_dir + "/out.txt");
  });
  return tools;
}

nlohmann::json run_npm_validators(const NpmTools& tools, const std::vector<std::string>& files) {
  std::string cmd = "node " + shell_quote(std::string(SPHEREKIT_SOURCE_DIR) + "/tests/convert/validate_gltf.mjs") +
                    " " + shell_quote(tools.node_dir);
  for (const std::string& f : files) cmd += " " + shell_quote(f);
  const std::string dir = temp_dir("npm_validate");
  const int rc = run_shell(cmd, dir + "/out.json", dir + "/err.txt");
  INFO("node stderr: " << slurp(dir + "/err.txt"));
  REQUIRE(rc == 0);
  return nlohmann::json::parse(slurp(dir + "/out.json"));
}

}  // namespace spherekit::test
