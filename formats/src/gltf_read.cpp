// glTF 2.0 reader (.gltf JSON with external or data: buffers, and binary .glb), using only
// nlohmann::json for the JSON (Khronos glTF 2.0 specification, sections 3.6-3.7 and 4.4).
//
// What is read: every triangle primitive (mode 4 or absent) of every mesh reached from the
// default scene's nodes, with the node's world transform applied (or all meshes untransformed
// when the file has no scenes). Positions are VEC3 float, or with KHR_mesh_quantization
// (signed or unsigned) byte/short, normalized or not; they are dequantized through the node
// transform as the extension requires (gltfpack puts its dequantization scale and offset in
// the node's matrix). Indices u8/u16/u32 or absent. Compressed geometry is decoded
// (gltf_compression.h): KHR_draco_mesh_compression primitives, whose decoded point and index
// counts must match their accessors (KHR_draco_mesh_compression README, "Conformance"), and
// EXT_meshopt_compression / KHR_meshopt_compression bufferViews (read through their fallback
// buffer's place). Points and lines are not surfaces and are skipped; strips, fans and sparse
// accessors are Unsupported.
//
// glTF splits a vertex wherever any attribute differs (normal creases, UV seams, material
// boundaries between primitives), so one surface point appears as several vertices with
// bitwise-identical positions. They are welded (weld.h) to recover the mesh's topology;
// vertices that no triangle references are dropped on the way.
//
// Errors are thrown as GltfError inside this file (the document is deeply nested and each
// level has its own checks) and turned into a Status at the single entry point.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "byte_reader.h"
#include "gltf_compression.h"
#include "gltf_uri.h"
#include "mesh_builder.h"
#include "mesh_codecs.h"
#include "spherekit/formats/atomic_file.h"
#include "text_scan.h"
#include "weld.h"

namespace spherekit::formats::detail {
namespace {

using json = nlohmann::json;

struct GltfError {
  ErrorCode code;
  std::string message;
};

[[noreturn]] void fail(ErrorCode code, std::string message) { throw GltfError{code, std::move(message)}; }

/// Library and parser messages may quote file content: keep them to one printable line.
std::string one_line(std::string_view text) {
  std::string s;
  for (char c : text.substr(0, 200)) s += (c >= 0x20 && c < 0x7f) ? c : ' ';
  return s;
}

// Component types (glTF 2.0, accessor.componentType).
constexpr std::uint64_t kUnsignedByte = 5121, kUnsignedShort = 5123, kUnsignedInt = 5125, kFloat = 5126;

std::size_t component_size(std::uint64_t type) {
  switch (type) {
    case 5120:
    case kUnsignedByte: return 1;
    case 5122:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0;
  }
}

/// A validated, bounds-checked view of an accessor's elements.
struct AccessorView {
  const char* data = nullptr;  // first element
  std::uint64_t count = 0;
  std::size_t stride = 0;
  std::uint64_t component_type = 0;
  bool normalized = false;
};

/// Component `k` of element `i` as a number: integers as they are, or mapped to [0, 1] /
/// [-1, 1] when normalized (glTF 2.0's conversion for `accessor.normalized`: c / (2^n - 1)
/// unsigned, max(c / (2^(n-1) - 1), -1) signed).
double read_component(const AccessorView& a, std::uint64_t i, int k) {
  const char* p = a.data + i * a.stride + static_cast<std::size_t>(k) * component_size(a.component_type);
  switch (a.component_type) {
    case 5120: {
      const double c = load_scalar<std::int8_t>(p, false);
      return a.normalized ? std::max(c / 127.0, -1.0) : c;
    }
    case kUnsignedByte: {
      const double c = load_scalar<std::uint8_t>(p, false);
      return a.normalized ? c / 255.0 : c;
    }
    case 5122: {
      const double c = load_scalar<std::int16_t>(p, false);
      return a.normalized ? std::max(c / 32767.0, -1.0) : c;
    }
    case kUnsignedShort: {
      const double c = load_scalar<std::uint16_t>(p, false);
      return a.normalized ? c / 65535.0 : c;
    }
    case kUnsignedInt: return load_scalar<std::uint32_t>(p, false);
    default: return load_scalar<float>(p, false);
  }
}

class GltfReader {
 public:
  GltfReader(const std::string& path, const json& doc, std::string_view glb_bin, bool has_glb_bin,
             MeshBuilder& builder)
      : path_(path), doc_(doc), glb_bin_(glb_bin), has_glb_bin_(has_glb_bin), builder_(builder), welder_(builder) {}

  void read() {
    if (!doc_.is_object()) fail(ErrorCode::ParseError, path_ + ": glTF JSON root is not an object");
    check_version_and_extensions();
    buffers_.resize(array(doc_, "buffers", "document").size());
    // Sized once: buffer_view_bytes hands out views into these strings.
    decoded_views_.resize(array(doc_, "bufferViews", "document").size());
    const json& meshes = array(doc_, "meshes", "document");
    const json& scenes = array(doc_, "scenes", "document");
    if (scenes.empty()) {
      for (std::size_t m = 0; m < meshes.size(); ++m) add_mesh(m, Eigen::Matrix4d::Identity());
      return;
    }
    // Without a "scene" the spec leaves the choice to the loader; the first one is the
    // usual pick (what viewers show).
    const std::uint64_t scene = uint_field(doc_, "scene", 0, "document");
    if (scene >= scenes.size()) fail(ErrorCode::ParseError, path_ + ": scene " + std::to_string(scene) + " does not exist");
    walk_scene(scenes[scene], "scene " + std::to_string(scene));
  }

 private:
  // ---- JSON access with checks ----------------------------------------------------------

  /// The array member `key` of `obj`, or an empty array when absent.
  const json& array(const json& obj, const char* key, const std::string& where) {
    static const json kEmpty = json::array();
    auto it = obj.find(key);
    if (it == obj.end()) return kEmpty;
    if (!it->is_array()) fail(ErrorCode::ParseError, path_ + ": " + where + ": '" + key + "' is not an array");
    return *it;
  }

  /// A non-negative integer member; `fallback` < 0 means required.
  std::uint64_t uint_field(const json& obj, const char* key, std::int64_t fallback, const std::string& where) {
    auto it = obj.find(key);
    if (it == obj.end()) {
      if (fallback < 0) fail(ErrorCode::ParseError, path_ + ": " + where + " has no '" + key + "'");
      return static_cast<std::uint64_t>(fallback);
    }
    if (!it->is_number_unsigned()) {
      fail(ErrorCode::ParseError, path_ + ": " + where + ": '" + key + "' is not a non-negative integer");
    }
    return it->get<std::uint64_t>();
  }

  /// Element `i` of the top-level array `key` ("accessors", ...), which must exist.
  const json& element(const char* key, std::uint64_t i, const std::string& where) {
    const json& a = array(doc_, key, "document");
    if (i >= a.size() || !a[i].is_object()) {
      fail(ErrorCode::ParseError, path_ + ": " + where + " refers to missing " + std::string(key) + "[" +
                                      std::to_string(i) + "]");
    }
    return a[i];
  }

  std::vector<double> numbers(const json& obj, const char* key, std::size_t n, const std::string& where) {
    const json& a = obj.at(key);
    if (!a.is_array() || a.size() != n) {
      fail(ErrorCode::ParseError, path_ + ": " + where + ": '" + key + "' must be " + std::to_string(n) + " numbers");
    }
    std::vector<double> v;
    for (const json& x : a) {
      if (!x.is_number()) fail(ErrorCode::ParseError, path_ + ": " + where + ": '" + key + "' must be numbers");
      v.push_back(x.get<double>());
    }
    return v;
  }

  // ---- document level ---------------------------------------------------------------------

  void check_version_and_extensions() {
    auto asset = doc_.find("asset");
    if (asset != doc_.end() && asset->is_object()) {
      auto version = asset->find("version");
      if (version != asset->end() && version->is_string()) {
        const std::string v = version->get<std::string>();
        if (v.rfind("2.", 0) != 0) {
          fail(ErrorCode::Unsupported, path_ + ": glTF version " + quote_token(v) + " is not supported (need 2.x)");
        }
      }
    }
    // Required extensions are not checked: the geometry ones (Draco, meshopt, quantization)
    // are decoded where they appear, and the others (materials, textures, lights) do not
    // change positions or triangles.
  }

  /// Depth-first over the scene's node trees, composing transforms parent * local.
  void walk_scene(const json& scene, const std::string& where) {
    const json& nodes = array(doc_, "nodes", "document");
    std::vector<char> visited(nodes.size(), 0);
    struct Item {
      std::uint64_t node;
      Eigen::Matrix4d parent;
    };
    std::vector<Item> stack;
    const json& roots = array(scene, "nodes", where);
    for (std::size_t i = roots.size(); i-- > 0;) {
      if (!roots[i].is_number_unsigned()) fail(ErrorCode::ParseError, path_ + ": " + where + ": bad node index");
      stack.push_back({roots[i].get<std::uint64_t>(), Eigen::Matrix4d::Identity()});
    }
    while (!stack.empty()) {
      Item item = stack.back();
      stack.pop_back();
      const std::string name = "node " + std::to_string(item.node);
      if (item.node >= nodes.size() || !nodes[item.node].is_object()) {
        fail(ErrorCode::ParseError, path_ + ": " + where + " refers to missing " + name);
      }
      // glTF requires disjoint trees; a node reached twice would be a cycle or a shared
      // child, and a cycle would make this loop endless.
      if (visited[item.node]) fail(ErrorCode::ParseError, path_ + ": " + name + " is reached twice (nodes must form trees)");
      visited[item.node] = 1;
      const json& node = nodes[item.node];
      const Eigen::Matrix4d world = item.parent * local_transform(node, name);
      if (node.contains("mesh")) add_mesh(uint_field(node, "mesh", -1, name), world);
      const json& children = array(node, "children", name);
      for (std::size_t i = children.size(); i-- > 0;) {
        if (!children[i].is_number_unsigned()) fail(ErrorCode::ParseError, path_ + ": " + name + ": bad child index");
        stack.push_back({children[i].get<std::uint64_t>(), world});
      }
    }
  }

  /// `matrix` (column-major) or translation * rotation * scale (glTF 2.0, 3.5.3).
  Eigen::Matrix4d local_transform(const json& node, const std::string& where) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (node.contains("matrix")) {
      std::vector<double> a = numbers(node, "matrix", 16, where);
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) m(r, c) = a[static_cast<std::size_t>(4 * c + r)];
      }
      return m;
    }
    if (node.contains("scale")) {
      std::vector<double> s = numbers(node, "scale", 3, where);
      m = Eigen::Vector4d(s[0], s[1], s[2], 1.0).asDiagonal();
    }
    if (node.contains("rotation")) {
      std::vector<double> q = numbers(node, "rotation", 4, where);  // x y z w
      Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
      // The spec requires unit quaternions; normalising forgives rounding in writers.
      if (rotation.norm() > 0) rotation.normalize();
      Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
      r.topLeftCorner<3, 3>() = rotation.toRotationMatrix();
      m = r * m;
    }
    if (node.contains("translation")) {
      std::vector<double> t = numbers(node, "translation", 3, where);
      Eigen::Matrix4d tm = Eigen::Matrix4d::Identity();
      tm.topRightCorner<3, 1>() = Eigen::Vector3d(t[0], t[1], t[2]);
      m = tm * m;
    }
    return m;
  }

  // ---- meshes -------------------------------------------------------------------------------

  void add_mesh(std::uint64_t mesh_index, const Eigen::Matrix4d& world) {
    const std::string mesh_name = "mesh " + std::to_string(mesh_index);
    const json& mesh = element("meshes", mesh_index, "a node");
    const json& primitives = array(mesh, "primitives", mesh_name);
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      const std::string where = mesh_name + " primitive " + std::to_string(p);
      if (!primitives[p].is_object()) fail(ErrorCode::ParseError, path_ + ": " + where + " is not an object");
      add_primitive(primitives[p], world, where);
    }
  }

  void add_primitive(const json& prim, const Eigen::Matrix4d& world, const std::string& where) {
    const std::uint64_t mode = uint_field(prim, "mode", 4, where);
    if (mode < 4) return;  // points and lines: no surface
    if (mode == 5 || mode == 6) {
      fail(ErrorCode::Unsupported, path_ + ": " + where + " uses triangle " + (mode == 5 ? "strips" : "fans") +
                                       " (mode " + std::to_string(mode) + "), not supported");
    }
    if (mode != 4) fail(ErrorCode::ParseError, path_ + ": " + where + " has unknown mode " + std::to_string(mode));

    auto attributes = prim.find("attributes");
    if (attributes == prim.end() || !attributes->is_object() || !attributes->contains("POSITION")) {
      fail(ErrorCode::ParseError, path_ + ": " + where + " has no POSITION attribute");
    }
    const std::uint64_t pos_index = uint_field(*attributes, "POSITION", -1, where);
    auto ext = prim.find("extensions");
    if (ext != prim.end() && ext->is_object() && ext->contains("KHR_draco_mesh_compression")) {
      add_draco_primitive(prim, (*ext)["KHR_draco_mesh_compression"], pos_index, world, where);
      return;
    }
    const AccessorView pos = accessor(pos_index, "VEC3", where + " POSITION");
    if (pos.component_type == kUnsignedInt) {
      fail(ErrorCode::ParseError, path_ + ": " + where + " POSITION has component type unsigned int (glTF allows "
                                      "float, and byte or short with KHR_mesh_quantization)");
    }
    AccessorView idx;
    const bool indexed = prim.contains("indices");
    if (indexed) {
      idx = accessor(uint_field(prim, "indices", -1, where), "SCALAR", where + " indices");
      if (idx.component_type != kUnsignedByte && idx.component_type != kUnsignedShort &&
          idx.component_type != kUnsignedInt) {
        fail(ErrorCode::ParseError, path_ + ": " + where + " indices have component type " +
                                        std::to_string(idx.component_type) + " (need unsigned byte, short or int)");
      }
    }
    const std::uint64_t corner_count = indexed ? idx.count : pos.count;
    if (corner_count % 3 != 0) {
      fail(ErrorCode::ParseError, path_ + ": " + where + " has " + std::to_string(corner_count) +
                                      " corners, not a multiple of 3");
    }
    // A transform with negative determinant mirrors the mesh; glTF then reverses the
    // winding (spec 3.7.4) so faces stay counter-clockwise seen from outside.
    const bool mirrored = world.topLeftCorner<3, 3>().determinant() < 0;
    std::vector<std::int64_t> welded(pos.count, -1);  // accessor vertex -> mesh vertex
    for (std::uint64_t t = 0; t < corner_count / 3; ++t) {
      std::int64_t corners[3];
      for (int k = 0; k < 3; ++k) {
        const std::uint64_t c = 3 * t + static_cast<std::uint64_t>(k);
        const std::uint64_t v = indexed ? read_index(idx, c) : c;
        if (v >= pos.count) {
          fail(ErrorCode::InvalidInput, path_ + ": " + where + ": index " + std::to_string(v) + " out of range (" +
                                            std::to_string(pos.count) + " vertices)");
        }
        if (welded[v] < 0) {
          welded[v] = add_vertex(world, read_component(pos, v, 0), read_component(pos, v, 1), read_component(pos, v, 2));
        }
        corners[k] = welded[v];
      }
      add_triangle(corners, mirrored);
    }
  }

  /// A KHR_draco_mesh_compression primitive: decode the bufferView with Draco's core decoder;
  /// the primitive's accessors describe the decoded data (their counts must match it).
  void add_draco_primitive(const json& prim, const json& draco, std::uint64_t pos_index, const Eigen::Matrix4d& world,
                           const std::string& where) {
    const std::string ext_where = where + " KHR_draco_mesh_compression";
    if (!draco.is_object()) fail(ErrorCode::ParseError, path_ + ": " + ext_where + " is not an object");
    const std::uint64_t view = uint_field(draco, "bufferView", -1, ext_where);
    auto attributes = draco.find("attributes");
    if (attributes == draco.end() || !attributes->is_object() || !attributes->contains("POSITION"))
      fail(ErrorCode::ParseError, path_ + ": " + ext_where + " has no POSITION attribute");
    const std::uint64_t uid = uint_field(*attributes, "POSITION", -1, ext_where);
    if (uid > 0xffffffffu) fail(ErrorCode::ParseError, path_ + ": " + ext_where + ": POSITION id out of range");
    Result<DracoPositions> decoded = decode_draco_positions(buffer_view_bytes(view), static_cast<std::uint32_t>(uid));
    if (!decoded.ok()) {
      fail(decoded.status().code(), path_ + ": " + ext_where + " (bufferView " + std::to_string(view) +
                                        "): " + decoded.status().message());
    }
    const DracoPositions& d = decoded.value();
    const std::uint64_t points = d.xyz.size() / 3;
    // Counts only: the accessors have no data of their own (no bufferView).
    const std::uint64_t pos_count = uint_field(element("accessors", pos_index, where), "count", -1,
                                               "accessor " + std::to_string(pos_index));
    if (pos_count != points) {
      fail(ErrorCode::ParseError, path_ + ": " + where + " POSITION accessor count " + std::to_string(pos_count) +
                                      " != Draco decoded points " + std::to_string(points));
    }
    if (prim.contains("indices")) {
      const std::uint64_t idx_index = uint_field(prim, "indices", -1, where);
      const std::uint64_t idx_count = uint_field(element("accessors", idx_index, where), "count", -1,
                                                 "accessor " + std::to_string(idx_index));
      if (idx_count != d.triangles.size()) {
        fail(ErrorCode::ParseError, path_ + ": " + where + " indices accessor count " + std::to_string(idx_count) +
                                        " != Draco decoded corners " + std::to_string(d.triangles.size()));
      }
    }
    const bool mirrored = world.topLeftCorner<3, 3>().determinant() < 0;
    std::vector<std::int64_t> welded(points, -1);
    for (std::size_t t = 0; t < d.triangles.size() / 3; ++t) {
      std::int64_t corners[3];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = d.triangles[3 * t + static_cast<std::size_t>(k)];
        if (welded[v] < 0) welded[v] = add_vertex(world, d.xyz[3 * v], d.xyz[3 * v + 1], d.xyz[3 * v + 2]);
        corners[k] = welded[v];
      }
      add_triangle(corners, mirrored);
    }
  }

  /// The welded mesh vertex at world * (x, y, z).
  std::int64_t add_vertex(const Eigen::Matrix4d& world, double x, double y, double z) {
    const Eigen::Vector4d p = world * Eigen::Vector4d(x, y, z, 1.0);
    std::int64_t index = -1;
    Status s = welder_.add(p[0], p[1], p[2], index);
    if (!s.ok()) fail(s.code(), s.message());
    return index;
  }

  void add_triangle(std::int64_t (&corners)[3], bool mirrored) {
    if (mirrored) std::swap(corners[1], corners[2]);
    Status s = builder_.add_face(corners, 3, FaceSource::element(face_count_++));
    if (!s.ok()) fail(s.code(), s.message());
  }

  static std::uint64_t read_index(const AccessorView& a, std::uint64_t i) {
    const char* p = a.data + i * a.stride;
    switch (a.component_type) {
      case kUnsignedByte: return load_scalar<std::uint8_t>(p, false);
      case kUnsignedShort: return load_scalar<std::uint16_t>(p, false);
      default: return load_scalar<std::uint32_t>(p, false);
    }
  }

  /// Resolves accessor -> bufferView -> buffer and checks that every element lies inside.
  AccessorView accessor(std::uint64_t index, const char* type, const std::string& where) {
    const std::string name = "accessor " + std::to_string(index);
    const json& acc = element("accessors", index, where);
    if (acc.contains("sparse")) fail(ErrorCode::Unsupported, path_ + ": " + name + " is sparse (not supported)");
    auto t = acc.find("type");
    if (t == acc.end() || !t->is_string() || t->get<std::string>() != type) {
      fail(ErrorCode::ParseError, path_ + ": " + where + ": " + name + " is not of type " + type);
    }
    const std::size_t components = std::string_view(type) == "VEC3" ? 3 : 1;
    AccessorView view;
    view.component_type = uint_field(acc, "componentType", -1, name);
    const std::size_t csize = component_size(view.component_type);
    if (csize == 0) {
      fail(ErrorCode::ParseError, path_ + ": " + name + " has unknown componentType " +
                                      std::to_string(view.component_type));
    }
    view.count = uint_field(acc, "count", -1, name);
    if (auto n = acc.find("normalized"); n != acc.end()) {
      if (!n->is_boolean()) fail(ErrorCode::ParseError, path_ + ": " + name + ": 'normalized' is not a boolean");
      view.normalized = n->get<bool>();
    }
    if (!acc.contains("bufferView")) {
      fail(ErrorCode::Unsupported, path_ + ": " + name + " has no bufferView (implicit zeros are not supported)");
    }
    const std::uint64_t bv_index = uint_field(acc, "bufferView", -1, name);
    const std::string bv_name = "bufferView " + std::to_string(bv_index);
    const json& bv = element("bufferViews", bv_index, name);
    const std::string_view data = buffer_view_bytes(bv_index);
    const std::uint64_t bv_length = data.size();
    const std::size_t element_size = csize * components;
    // The spec bounds byteStride to [4, 252]; the bound also keeps count * stride small.
    const std::uint64_t stride = uint_field(bv, "byteStride", 0, bv_name);
    if (stride > 252 || (stride != 0 && stride < element_size)) {
      fail(ErrorCode::ParseError, path_ + ": " + bv_name + " has byteStride " + std::to_string(stride) +
                                      " (need " + std::to_string(element_size) + " to 252 for " + name + ")");
    }
    view.stride = stride == 0 ? element_size : static_cast<std::size_t>(stride);
    const std::uint64_t acc_offset = uint_field(acc, "byteOffset", 0, name);
    // bv_length <= file size, so after the first test count * stride cannot overflow.
    const bool fits = view.count == 0 ||
                      (acc_offset <= bv_length && view.count <= bv_length &&
                       (view.count - 1) * view.stride + element_size <= bv_length - acc_offset);
    if (!fits) fail(ErrorCode::ParseError, path_ + ": " + name + " lies outside " + bv_name);
    view.data = data.data() + acc_offset;
    return view;
  }

  /// The bytes of bufferView `index`: a slice of its buffer, or for a meshopt-compressed view
  /// (EXT_meshopt_compression / KHR_meshopt_compression) its decoded data, decoded once.
  std::string_view buffer_view_bytes(std::uint64_t index) {
    const std::string bv_name = "bufferView " + std::to_string(index);
    const json& bv = element("bufferViews", index, "an accessor");
    DecodedView& cached = decoded_views_[static_cast<std::size_t>(index)];
    if (cached.done) return cached.bytes;
    const std::uint64_t length = uint_field(bv, "byteLength", -1, bv_name);
    const json* meshopt = nullptr;
    std::string ext_name;
    if (auto ext = bv.find("extensions"); ext != bv.end() && ext->is_object()) {
      for (const char* name : {"KHR_meshopt_compression", "EXT_meshopt_compression"}) {
        if (auto it = ext->find(name); it != ext->end() && !meshopt) {
          meshopt = &*it;
          ext_name = name;
        }
      }
    }
    if (!meshopt) {
      const std::uint64_t buffer_index = uint_field(bv, "buffer", -1, bv_name);
      std::string_view data = buffer(buffer_index);
      const std::uint64_t offset = uint_field(bv, "byteOffset", 0, bv_name);
      if (offset > data.size() || length > data.size() - offset) {
        fail(ErrorCode::ParseError, path_ + ": " + bv_name + " lies outside buffer " + std::to_string(buffer_index));
      }
      return data.substr(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
    }
    // The compressed bytes are in the extension's buffer; the view's own buffer is usually a
    // fallback without data (EXT_meshopt_compression README, "Fallback buffers").
    const std::string where = bv_name + " " + ext_name;
    if (!meshopt->is_object()) fail(ErrorCode::ParseError, path_ + ": " + where + " is not an object");
    const std::uint64_t buffer_index = uint_field(*meshopt, "buffer", -1, where);
    std::string_view data = buffer(buffer_index);
    const std::uint64_t offset = uint_field(*meshopt, "byteOffset", 0, where);
    const std::uint64_t compressed = uint_field(*meshopt, "byteLength", -1, where);
    if (offset > data.size() || compressed > data.size() - offset) {
      fail(ErrorCode::ParseError, path_ + ": " + where + " lies outside buffer " + std::to_string(buffer_index));
    }
    const std::uint64_t stride = uint_field(*meshopt, "byteStride", -1, where);
    const std::uint64_t count = uint_field(*meshopt, "count", -1, where);
    auto text = [&](const char* key, const char* fallback) {
      auto it = meshopt->find(key);
      if (it == meshopt->end()) return std::string(fallback);
      if (!it->is_string()) fail(ErrorCode::ParseError, path_ + ": " + where + ": '" + key + "' is not a string");
      return it->get<std::string>();
    };
    const std::string mode_name = text("mode", "");
    MeshoptMode mode = MeshoptMode::Attributes;
    if (mode_name == "TRIANGLES") {
      mode = MeshoptMode::Triangles;
    } else if (mode_name == "INDICES") {
      mode = MeshoptMode::Indices;
    } else if (mode_name != "ATTRIBUTES") {
      fail(ErrorCode::ParseError, path_ + ": " + where + " has unknown mode " + quote_token(mode_name));
    }
    const std::string filter_name = text("filter", "NONE");
    MeshoptFilter filter = MeshoptFilter::None;
    if (filter_name == "OCTAHEDRAL") {
      filter = MeshoptFilter::Octahedral;
    } else if (filter_name == "QUATERNION") {
      filter = MeshoptFilter::Quaternion;
    } else if (filter_name == "EXPONENTIAL") {
      filter = MeshoptFilter::Exponential;
    } else if (filter_name != "NONE") {
      fail(ErrorCode::Unsupported, path_ + ": " + where + " uses filter " + quote_token(filter_name) + " (not supported)");
    }
    Status s = decode_meshopt(data.substr(static_cast<std::size_t>(offset), static_cast<std::size_t>(compressed)), count,
                              stride, mode, filter, cached.bytes);
    if (!s.ok()) fail(s.code(), path_ + ": " + where + ": " + s.message());
    if (cached.bytes.size() < length) {
      fail(ErrorCode::ParseError, path_ + ": " + where + " decodes to " + std::to_string(cached.bytes.size()) +
                                      " bytes, byteLength says " + std::to_string(length));
    }
    cached.bytes.resize(static_cast<std::size_t>(length));
    cached.done = true;
    return cached.bytes;
  }

  /// The bytes of buffer `i`, loading external files and data URIs on first use.
  std::string_view buffer(std::uint64_t i) {
    const std::string name = "buffer " + std::to_string(i);
    if (i >= buffers_.size()) fail(ErrorCode::ParseError, path_ + ": refers to missing " + name);
    if (buffers_[i].loaded) return buffers_[i].view;
    const json& b = element("buffers", i, "a bufferView");
    const std::uint64_t length = uint_field(b, "byteLength", -1, name);
    Buffer& out = buffers_[i];
    auto uri_it = b.find("uri");
    if (uri_it == b.end()) {
      // GLB: the first buffer without a uri is the BIN chunk (spec 4.4.3.3).
      if (i != 0 || !has_glb_bin_) fail(ErrorCode::ParseError, path_ + ": " + name + " has no uri");
      out.view = glb_bin_;
    } else {
      if (!uri_it->is_string()) fail(ErrorCode::ParseError, path_ + ": " + name + ": uri is not a string");
      const std::string uri = uri_it->get<std::string>();
      if (uri.rfind("data:", 0) == 0) {
        const std::size_t comma = uri.find(',');
        if (comma == std::string::npos || uri.substr(0, comma).find(";base64") == std::string::npos) {
          fail(ErrorCode::Unsupported, path_ + ": " + name + ": data URI is not base64");
        }
        if (!decode_base64(std::string_view(uri).substr(comma + 1), out.owned)) {
          fail(ErrorCode::ParseError, path_ + ": " + name + ": invalid base64 in data URI");
        }
      } else {
        if (uri.find("://") != std::string::npos) {
          fail(ErrorCode::Unsupported, path_ + ": " + name + ": uri " + quote_token(uri) + " is not a local file");
        }
        const std::filesystem::path file = std::filesystem::path(path_).parent_path() / percent_decode(uri);
        // Only regular files: read_file reads to the end, which never comes for a uri naming
        // /dev/zero or a FIFO (a hostile file would hang the reader or exhaust memory).
        std::error_code ec;
        const std::filesystem::file_status st = std::filesystem::status(file, ec);
        if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)) {
          fail(ErrorCode::InvalidInput, path_ + ": " + name + ": uri " + quote_token(uri) + " is not a regular file");
        }
        Result<std::string> bytes = read_file(file.string());
        if (!bytes.ok()) {
          // read_file's message is "<file>: why". The file name comes from the document and
          // may hold anything (a newline would break the one-line message): quote the uri.
          std::string why = bytes.status().message();
          if (why.rfind(file.string() + ": ", 0) == 0) why.erase(0, file.string().size() + 2);
          fail(ErrorCode::IoError, path_ + ": " + name + ": uri " + quote_token(uri) + ": " + one_line(why));
        }
        out.owned = std::move(bytes).value();
      }
      out.view = out.owned;
    }
    if (out.view.size() < length) {
      fail(ErrorCode::ParseError, path_ + ": " + name + " has " + std::to_string(out.view.size()) +
                                      " bytes, byteLength says " + std::to_string(length));
    }
    out.view = out.view.substr(0, length);
    out.loaded = true;
    return out.view;
  }

  // buffers_ is sized once in read() and never grows, so `view` may point into `owned`.
  struct Buffer {
    bool loaded = false;
    std::string owned;
    std::string_view view;
  };

  const std::string& path_;
  const json& doc_;
  std::string_view glb_bin_;
  bool has_glb_bin_;
  MeshBuilder& builder_;
  PositionWelder welder_;
  std::vector<Buffer> buffers_;
  // Decoded meshopt bufferViews, one per bufferView (sized once in read(), never grown, so the
  // views handed out into `bytes` stay valid).
  struct DecodedView {
    bool done = false;
    std::string bytes;
  };
  std::vector<DecodedView> decoded_views_;
  std::uint64_t face_count_ = 0;
};

/// Splits a .glb into its JSON text and optional BIN chunk (spec 4.4).
void split_glb(const std::string& path, std::string_view bytes, std::string_view& json_text, std::string_view& bin,
               bool& has_bin) {
  constexpr std::uint32_t kMagic = 0x46546C67;      // "glTF"
  constexpr std::uint32_t kJsonChunk = 0x4E4F534A;  // "JSON"
  constexpr std::uint32_t kBinChunk = 0x004E4942;   // "BIN\0"
  if (bytes.size() < 12) fail(ErrorCode::ParseError, path + ": too short for a GLB (" + std::to_string(bytes.size()) + " bytes)");
  if (load_scalar<std::uint32_t>(bytes.data(), false) != kMagic) {
    fail(ErrorCode::ParseError, path + ": not a GLB file (bad magic)");
  }
  const std::uint32_t version = load_scalar<std::uint32_t>(bytes.data() + 4, false);
  if (version != 2) fail(ErrorCode::Unsupported, path + ": GLB version " + std::to_string(version) + " is not supported");
  const std::uint64_t length = load_scalar<std::uint32_t>(bytes.data() + 8, false);
  if (length > bytes.size()) {
    fail(ErrorCode::ParseError, path + ": GLB is truncated (header says " + std::to_string(length) +
                                    " bytes, file has " + std::to_string(bytes.size()) + ")");
  }
  ByteReader in(bytes.data(), static_cast<std::size_t>(length));
  in.skip(12);
  has_bin = false;
  for (int chunk = 0; in.remaining() > 0; ++chunk) {
    std::uint32_t chunk_length = 0, chunk_type = 0;
    if (!in.read(chunk_length, false) || !in.read(chunk_type, false) || chunk_length > in.remaining()) {
      fail(ErrorCode::ParseError, path + ": GLB chunk " + std::to_string(chunk) + " is truncated");
    }
    std::string_view data = bytes.substr(in.position(), chunk_length);
    in.skip(chunk_length);
    if (chunk == 0) {
      if (chunk_type != kJsonChunk) fail(ErrorCode::ParseError, path + ": first GLB chunk is not JSON");
      json_text = data;
    } else if (chunk == 1 && chunk_type == kBinChunk) {
      bin = data;
      has_bin = true;
    }  // other chunk types are reserved for extensions: skipped
  }
  if (json_text.data() == nullptr) fail(ErrorCode::ParseError, path + ": GLB has no JSON chunk");
}

}  // namespace

Result<TriMesh> read_gltf(const std::string& path, std::string_view bytes, bool glb, const ReadOptions& options,
                          ReadInfo& info) {
  info.format = glb ? "glb" : "gltf";
  MeshBuilder builder(path, options.polygons);
  try {
    std::string_view json_text, bin;
    bool has_bin = false;
    if (glb) {
      split_glb(path, bytes, json_text, bin, has_bin);
    } else {
      json_text = bytes;
    }
    json doc;
    try {
      doc = json::parse(json_text.begin(), json_text.end());
    } catch (const json::parse_error& e) {
      return Status(ErrorCode::ParseError, path + ": invalid JSON (" + one_line(e.what()) + ")");
    }
    GltfReader(path, doc, bin, has_bin, builder).read();
  } catch (const GltfError& e) {
    return Status(e.code, e.message);
  } catch (const json::exception& e) {
    // Safety net for a type mismatch a check above missed: still a clean one-line error.
    return Status(ErrorCode::ParseError, path + ": invalid glTF (" + one_line(e.what()) + ")");
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::ParseError, path + ": glTF too large to load");
  }
  return builder.finish(info);
}

}  // namespace spherekit::formats::detail
