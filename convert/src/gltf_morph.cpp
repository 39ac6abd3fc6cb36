// A same-connectivity collection as one glTF mesh with morph targets (see gltf_morph.h).
//
// References: glTF 2.0 specification, "Morph Targets" (targets hold displacements, one value
// per vertex of the base; POSITION accessors define min/max); mesh.extras.targetNames is the
// de-facto convention for target names (read by three.js's GLTFLoader, written by Blender);
// KHR_draco_mesh_compression README; ALGORITHM.md §7 gotcha 9.
#include "spherekit/convert/gltf_morph.h"

#include <algorithm>
#include <string>
#include <utility>

#include "gltf_document.h"

namespace spherekit::convert {
namespace {

Status same_connectivity(const GltfMesh& base, const GltfMesh& m, std::size_t k) {
  const std::string who = "collection member " + std::to_string(k);
  SPHEREKIT_RETURN_IF_ERROR(check_gltf_mesh(m).with_context(who));
  if (m.V.rows() != base.V.rows() || m.F.rows() != base.F.rows() || m.F != base.F)
    return Status(ErrorCode::InvalidInput, who + " does not have the connectivity of member 0 (" +
                                               std::to_string(m.V.rows()) + " points, " + std::to_string(m.F.rows()) +
                                               " faces vs " + std::to_string(base.V.rows()) + ", " +
                                               std::to_string(base.F.rows()) + ")");
  if (m.position_index != base.position_index)
    return Status(ErrorCode::InvalidInput, who + " splits its vertices differently from member 0 (position_index)");
  if ((m.N.rows() > 0) != (base.N.rows() > 0))
    return Status(ErrorCode::InvalidInput, who + ": normals on some members but not all");
  if (m.UV.rows() != base.UV.rows() || m.UV != base.UV)
    return Status(ErrorCode::InvalidInput, who + " has texture coordinates that differ from member 0's");
  return Status();
}

/// glTF 2.0 "Animations": a sampler whose input is the key times (SCALAR floats with min/max)
/// and whose output holds, per key, one weight per morph target; the channel targets the
/// node's "weights" path. Key k shows member k: all weights 0 (the base) for k = 0, else
/// weight 1 on target k-1.
void add_weight_animation(detail::GlbBuilder& doc, std::size_t members, double seconds) {
  const std::size_t targets = members - 1;
  std::vector<float> times(members), weights(members * targets, 0.0f);
  for (std::size_t k = 0; k < members; ++k) {
    times[k] = static_cast<float>(seconds * static_cast<double>(k) / static_cast<double>(targets));
    if (k > 0) weights[k * targets + (k - 1)] = 1.0f;
  }
  auto scalar_accessor = [&](const std::vector<float>& values, bool bounds) {
    tinygltf::Accessor a;
    a.bufferView = doc.add_buffer_view(values.data(), values.size() * sizeof(float), 0);
    a.componentType = detail::kFloat;
    a.type = TINYGLTF_TYPE_SCALAR;
    a.count = values.size();
    if (bounds) {
      a.minValues = {*std::min_element(values.begin(), values.end())};
      a.maxValues = {*std::max_element(values.begin(), values.end())};
    }
    doc.model().accessors.push_back(std::move(a));
    return static_cast<int>(doc.model().accessors.size()) - 1;
  };
  tinygltf::AnimationSampler sampler;
  sampler.input = scalar_accessor(times, true);
  sampler.output = scalar_accessor(weights, false);
  sampler.interpolation = "LINEAR";
  tinygltf::AnimationChannel channel;
  channel.sampler = 0;
  channel.target_node = 0;
  channel.target_path = "weights";
  tinygltf::Animation animation;
  animation.name = "morph";
  animation.samplers.push_back(std::move(sampler));
  animation.channels.push_back(std::move(channel));
  doc.model().animations.push_back(std::move(animation));
}

}  // namespace

Result<GltfMorph> build_gltf_morph_targets(const std::vector<GltfMesh>& members, const GltfMorphOptions& options) {
  if (members.empty()) return Status(ErrorCode::InvalidInput, "an empty collection has no morph targets");
  if (!options.names.empty() && options.names.size() != members.size())
    return Status(ErrorCode::InvalidArgument, std::to_string(options.names.size()) + " names for " +
                                                  std::to_string(members.size()) + " collection members");
  SPHEREKIT_RETURN_IF_ERROR(check_gltf_mesh(members[0]).with_context("collection member 0"));
  for (std::size_t k = 1; k < members.size(); ++k) SPHEREKIT_RETURN_IF_ERROR(same_connectivity(members[0], members[k], k));

  GltfMorph out;
  out.targets = static_cast<int>(members.size()) - 1;
  const bool normals = members[0].N.rows() > 0, texcoords = members[0].UV.rows() > 0;
  detail::GlbBuilder doc;
  int mesh_index = 0;
  tinygltf::Value::Object spherekit_extras;
  spherekit_extras["encoding"] =
      detail::json_string(options.encoding == MorphEncoding::Uncompressed ? "uncompressed" : "draco_sequential");

  if (options.encoding == MorphEncoding::DracoSequential) {
    SPHEREKIT_ASSIGN_OR_RETURN(out.quantization,
                               choose_draco_quantization(members[0], options.reference_rms_error, options.budget));
    DracoEncodeOptions encode;
    encode.quantization = out.quantization.quantization;
    encode.sequential = true;
    encode.compression_level = options.compression_level;
    SPHEREKIT_ASSIGN_OR_RETURN(DracoPrimitive primitive, encode_draco_primitive(members[0], encode));
    out.base = primitive.decoded.mesh;
    spherekit_extras["quantization"] = detail::quantization_json(out.quantization, normals, texcoords);
    mesh_index = doc.add_draco_mesh(primitive, options.name, tinygltf::Value());
  } else {
    out.base = members[0];
    tinygltf::Primitive prim;
    prim.mode = detail::kTriangles;
    prim.attributes["POSITION"] = doc.add_float_accessor(out.base.V, true);
    if (normals) prim.attributes["NORMAL"] = doc.add_float_accessor(out.base.N, false);
    if (texcoords) prim.attributes["TEXCOORD_0"] = doc.add_float_accessor(out.base.UV, false);
    prim.indices = doc.add_index_accessor(out.base.F, out.base.V.rows());
    tinygltf::Mesh mesh;
    mesh.name = options.name;
    mesh.primitives.push_back(std::move(prim));
    doc.model().meshes.push_back(std::move(mesh));
  }

  // Targets: displacements from the base as stored (decoded for Draco), so that base + target
  // is the member up to float rounding.
  std::vector<std::map<std::string, int>> targets;
  for (std::size_t k = 1; k < members.size(); ++k) {
    std::map<std::string, int> target;
    const RowMat3d dV = members[k].V - out.base.V;
    target["POSITION"] = doc.add_float_accessor(dV, true);
    if (normals) {
      const RowMat3d dN = members[k].N - out.base.N;
      target["NORMAL"] = doc.add_float_accessor(dN, false);
    }
    targets.push_back(std::move(target));
  }
  tinygltf::Mesh& mesh = doc.model().meshes[static_cast<std::size_t>(mesh_index)];
  mesh.primitives[0].targets = std::move(targets);
  mesh.weights.assign(members.size() - 1, 0.0);

  std::vector<std::string> names = options.names;
  if (names.empty())
    for (std::size_t k = 0; k < members.size(); ++k) names.push_back("member" + std::to_string(k));
  tinygltf::Value::Array target_names, member_names;
  for (std::size_t k = 0; k < names.size(); ++k) {
    member_names.push_back(detail::json_string(names[k]));
    if (k > 0) target_names.push_back(detail::json_string(names[k]));
  }
  spherekit_extras["members"] = tinygltf::Value(std::move(member_names));
  tinygltf::Value::Object extras;
  extras["targetNames"] = tinygltf::Value(std::move(target_names));
  extras["spherekit"] = detail::json_object(std::move(spherekit_extras));
  mesh.extras = detail::json_object(std::move(extras));

  tinygltf::Node node;
  node.name = options.name;
  node.mesh = mesh_index;
  doc.model().nodes.push_back(std::move(node));
  if (options.animation_seconds > 0 && members.size() >= 2) add_weight_animation(doc, members.size(), options.animation_seconds);
  doc.model().scenes.emplace_back();
  doc.model().scenes[0].nodes = {0};
  doc.model().defaultScene = 0;
  tinygltf::Value::Object provenance;
  provenance["source_mesh"] = detail::json_string(options.provenance.source_mesh);
  provenance["sphere_map"] = detail::json_string(options.provenance.sphere_map);
  provenance["members"] = detail::json_int(static_cast<std::int64_t>(members.size()));
  doc.model().asset.extras = detail::provenance_json(std::move(provenance));
  SPHEREKIT_ASSIGN_OR_RETURN(out.glb, doc.to_glb());
  return out;
}

Result<GltfMorph> build_gltf_morph_targets(const std::vector<TriMesh>& members, const GltfMorphOptions& options) {
  std::vector<GltfMesh> meshes;
  meshes.reserve(members.size());
  for (std::size_t k = 0; k < members.size(); ++k) {
    auto m = gltf_mesh_from_trimesh(members[k]);
    if (!m.ok()) return m.status().with_context("collection member " + std::to_string(k));
    meshes.push_back(std::move(m).value());
  }
  return build_gltf_morph_targets(meshes, options);
}

}  // namespace spherekit::convert
