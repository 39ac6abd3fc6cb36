// Tests of the morph-target export of a same-connectivity collection
// (convert/src/gltf_morph.cpp). The uncompressed file is read back with the packaged tinygltf
// (linked, like the library, before Draco: a changed link order that lets libdraco's older
// tinygltf copy take over fails here, ECOSYSTEM.md §1.4); the Draco variant with the
// independent decoder of gltf_test_support.
#include <tiny_gltf.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <string>
#include <vector>

#include "gltf_test_support.h"
#include "spherekit/convert/gltf_morph.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

using Rows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The float data of accessor `a` of a tinygltf model (tightly packed VEC2/VEC3).
Rows float_accessor(const tinygltf::Model& model, int a) {
  const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(a)];
  REQUIRE(acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  const int dims = acc.type == TINYGLTF_TYPE_VEC2 ? 2 : 3;
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(acc.bufferView)];
  const auto& data = model.buffers[static_cast<std::size_t>(bv.buffer)].data;
  Rows M(static_cast<Eigen::Index>(acc.count), dims);
  REQUIRE(bv.byteOffset + acc.byteOffset + M.size() * sizeof(float) <= data.size());
  std::memcpy(M.data(), data.data() + bv.byteOffset + acc.byteOffset, static_cast<std::size_t>(M.size()) * sizeof(float));
  return M;
}

// The float data of accessor `a` of a parsed .glb.
Rows float_accessor(const test::GlbFile& glb, int a) {
  const auto& acc = glb.json.at("accessors").at(static_cast<std::size_t>(a));
  REQUIRE(acc.at("componentType") == 5126);
  const int dims = acc.at("type") == "VEC2" ? 2 : 3;
  const std::string bytes = test::buffer_view_bytes(glb, acc.at("bufferView").get<int>());
  Rows M(acc.at("count").get<Eigen::Index>(), dims);
  REQUIRE(bytes.size() >= static_cast<std::size_t>(M.size()) * sizeof(float));
  std::memcpy(M.data(), bytes.data(), static_cast<std::size_t>(M.size()) * sizeof(float));
  return M;
}

}  // namespace

TEST_CASE("glTF morph targets, uncompressed: the members' own point order, base + target = member", "[convert]") {
  const std::vector<GltfMesh> members = test::collection_test_meshes(17);
  GltfMorphOptions options;
  options.names = {"a", "b", "c"};
  auto built = build_gltf_morph_targets(members, options);
  REQUIRE(built.ok());
  CHECK(built->targets == 2);

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool loaded = loader.LoadBinaryFromMemory(&model, &err, &warn,
                                                  reinterpret_cast<const unsigned char*>(built->glb.data()),
                                                  static_cast<unsigned int>(built->glb.size()));
  INFO(err << warn);
  REQUIRE(loaded);
  REQUIRE(model.meshes.size() == 1);
  const tinygltf::Primitive& prim = model.meshes[0].primitives[0];
  CHECK(model.extensionsUsed.empty());
  CHECK(model.meshes[0].weights == std::vector<double>{0.0, 0.0});
  REQUIRE(prim.targets.size() == 2);

  const Rows V = float_accessor(model, prim.attributes.at("POSITION"));
  const Rows UV = float_accessor(model, prim.attributes.at("TEXCOORD_0"));
  // Identical vertex order: the base is member 0 point for point ...
  CHECK(V == members[0].V.cast<float>());
  CHECK(UV == members[0].UV.cast<float>());
  // ... and the indices are the members' faces.
  const tinygltf::Accessor& idx = model.accessors[static_cast<std::size_t>(prim.indices)];
  REQUIRE(idx.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
  const tinygltf::BufferView& ibv = model.bufferViews[static_cast<std::size_t>(idx.bufferView)];
  std::vector<std::uint16_t> indices(idx.count);
  std::memcpy(indices.data(), model.buffers[0].data.data() + ibv.byteOffset, idx.count * sizeof(std::uint16_t));
  REQUIRE(indices.size() == static_cast<std::size_t>(members[0].F.size()));
  for (std::size_t k = 0; k < indices.size(); ++k) REQUIRE(indices[k] == static_cast<std::uint16_t>(members[0].F.data()[k]));
  // Weight 1 on target k-1 shows member k.
  for (std::size_t k = 1; k < members.size(); ++k) {
    const Rows dV = float_accessor(model, prim.targets[k - 1].at("POSITION"));
    const Rows dN = float_accessor(model, prim.targets[k - 1].at("NORMAL"));
    CHECK(((V + dV).cast<double>() - members[k].V).cwiseAbs().maxCoeff() < 1e-6);
    CHECK(((float_accessor(model, prim.attributes.at("NORMAL")) + dN).cast<double>() - members[k].N).cwiseAbs().maxCoeff() <
          1e-6);
    // POSITION accessors of targets carry min/max too.
    CHECK(model.accessors[static_cast<std::size_t>(prim.targets[k - 1].at("POSITION"))].minValues.size() == 3);
  }
  const tinygltf::Value& names = model.meshes[0].extras.Get("targetNames");
  REQUIRE(names.ArrayLen() == 2);
  CHECK(names.Get(0).Get<std::string>() == "b");
  CHECK(names.Get(1).Get<std::string>() == "c");
}

TEST_CASE("glTF morph targets, Draco sequential: the decoded base keeps the members' point order", "[convert]") {
  const std::vector<GltfMesh> members = test::collection_test_meshes(17);
  GltfMorphOptions options;
  options.encoding = MorphEncoding::DracoSequential;
  auto built = build_gltf_morph_targets(members, options);
  REQUIRE(built.ok());
  const test::GlbFile glb = test::parse_glb(built->glb);
  CHECK(glb.json.at("extensionsRequired") == nlohmann::json::array({"KHR_draco_mesh_compression"}));
  const auto decoded = test::decode_and_check_draco(glb);
  REQUIRE(decoded.size() == 1);
  const test::DecodedPrimitive& d = decoded[0];
  // Same points in the same order (within the quantization), same faces.
  REQUIRE(d.V.rows() == members[0].V.rows());
  const double half_step = built->quantization.quantization.position_step() / 2;
  CHECK((d.V.cast<double>() - members[0].V).cwiseAbs().maxCoeff() <= half_step + 1e-6);
  CHECK((d.UV.cast<double>() - members[0].UV).cwiseAbs().maxCoeff() < 1e-6);
  CHECK(d.F.cast<std::int32_t>() == members[0].F);
  // Targets are displacements from the decoded base: base + target = member to float rounding.
  const auto& prim = glb.json["meshes"][0]["primitives"][0];
  REQUIRE(prim.at("targets").size() == 2);
  for (std::size_t k = 1; k < members.size(); ++k) {
    const Rows dV = float_accessor(glb, prim["targets"][k - 1].at("POSITION").get<int>());
    CHECK(((d.V + dV).cast<double>() - members[k].V).cwiseAbs().maxCoeff() < 1e-6);
  }
  CHECK(glb.json["meshes"][0].at("extras").at("spherekit").at("encoding") == "draco_sequential");
  // Smaller than the uncompressed file.
  auto plain = build_gltf_morph_targets(members, GltfMorphOptions{});
  REQUIRE(plain.ok());
  CHECK(built->glb.size() < plain->glb.size());
}

TEST_CASE("glTF morph targets from triangle meshes of one connectivity", "[convert]") {
  const TriMesh a = test::random_blob(2, 1), b = test::random_blob(2, 2);
  REQUIRE(a.F == b.F);
  auto built = build_gltf_morph_targets(std::vector<TriMesh>{a, b});
  REQUIRE(built.ok());
  CHECK(built->targets == 1);
  const test::GlbFile glb = test::parse_glb(built->glb);
  const auto& prim = glb.json["meshes"][0]["primitives"][0];
  CHECK_FALSE(prim.at("attributes").contains("TEXCOORD_0"));
  CHECK(float_accessor(glb, prim["attributes"]["POSITION"].get<int>()) == a.V.cast<float>());
  // A collection of one is a plain mesh: no targets, no weights.
  auto single = build_gltf_morph_targets(std::vector<TriMesh>{a});
  REQUIRE(single.ok());
  CHECK(single->targets == 0);
  const auto mesh = test::parse_glb(single->glb).json.at("meshes").at(0);
  CHECK_FALSE(mesh.contains("weights"));
  CHECK_FALSE(mesh.at("primitives").at(0).contains("targets"));
}

TEST_CASE("glTF morph targets: errors", "[convert]") {
  std::vector<GltfMesh> members = test::collection_test_meshes(9, 2);
  CHECK(build_gltf_morph_targets(std::vector<GltfMesh>{}).status().code() == ErrorCode::InvalidInput);
  GltfMorphOptions options;
  options.names = {"only one"};
  CHECK(build_gltf_morph_targets(members, options).status().code() == ErrorCode::InvalidArgument);
  // Different connectivity.
  std::vector<GltfMesh> mixed = members;
  auto other = gltf_mesh_from_geometry_image(test::blob_geometry_image(17));
  REQUIRE(other.ok());
  mixed[1] = other.value();
  auto r = build_gltf_morph_targets(mixed);
  CHECK(r.status().code() == ErrorCode::InvalidInput);
  CHECK(r.status().message().find("member 1") != std::string::npos);
  // Texture coordinates cannot morph.
  mixed = members;
  mixed[1].UV(0, 0) += 0.01;
  CHECK(build_gltf_morph_targets(mixed).status().code() == ErrorCode::InvalidInput);
  // Normals on some members only.
  mixed = members;
  mixed[1].N.resize(0, 3);
  CHECK(build_gltf_morph_targets(mixed).status().code() == ErrorCode::InvalidInput);
  const TriMesh ico = test::icosphere(1), ico2 = test::icosphere(2);
  CHECK(build_gltf_morph_targets(std::vector<TriMesh>{ico, ico2}).status().code() == ErrorCode::InvalidInput);
}
