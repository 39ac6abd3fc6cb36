// Internal glTF document builder over tinygltf (see gltf_document.h).
//
// References: glTF 2.0 specification (accessors, buffer views, binary glTF); the
// KHR_draco_mesh_compression README (accessors of a compressed primitive have no bufferView and
// must match the decompressed data).
#include "gltf_document.h"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <exception>
#include <limits>
#include <sstream>

#include "spherekit/version.h"

namespace spherekit::convert::detail {

int index_component_type(std::int64_t points) {
  // Largest index = points - 1 must stay below 65535, the UNSIGNED_SHORT restart value.
  return points <= 65535 ? kUnsignedShort : kUnsignedInt;
}

GlbBuilder::GlbBuilder() {
  model_.asset.version = "2.0";
  model_.asset.generator = std::string("SphereKit ") + kVersion;
  model_.buffers.emplace_back();
}

int GlbBuilder::add_buffer_view(const void* bytes, std::size_t size, int target) {
  std::vector<unsigned char>& data = model_.buffers[0].data;
  // Every view starts on a 4-byte boundary (glTF 2.0 "Data Alignment": an accessor's offset
  // must be a multiple of its component size; 4 covers float and uint32).
  data.resize((data.size() + 3) & ~static_cast<std::size_t>(3), 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), p, p + size);
  model_.bufferViews.push_back(std::move(view));
  return static_cast<int>(model_.bufferViews.size()) - 1;
}

int GlbBuilder::add_accessor_without_data(int component_type, int type, std::size_t count,
                                          const std::vector<double>& min, const std::vector<double>& max) {
  tinygltf::Accessor a;
  a.bufferView = -1;  // tinygltf omits the property (KHR_draco_mesh_compression: must not be defined)
  a.componentType = component_type;
  a.type = type;
  a.count = count;
  a.minValues = min;
  a.maxValues = max;
  model_.accessors.push_back(std::move(a));
  return static_cast<int>(model_.accessors.size()) - 1;
}

int GlbBuilder::add_float_accessor(const RowMatXd& M, bool with_bounds) {
  const auto rows = static_cast<std::size_t>(M.rows()), cols = static_cast<std::size_t>(M.cols());
  std::vector<float> values(rows * cols);
  std::vector<double> lo(cols, std::numeric_limits<double>::infinity()), hi(cols, -lo[0]);
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < cols; ++c) {
      const float x = static_cast<float>(M(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)));
      values[r * cols + c] = x;
      // Bounds of the stored floats, exactly (a float converts to double without rounding).
      lo[c] = std::min(lo[c], static_cast<double>(x));
      hi[c] = std::max(hi[c], static_cast<double>(x));
    }
  tinygltf::Accessor a;
  a.bufferView = add_buffer_view(values.data(), values.size() * sizeof(float), kArrayBuffer);
  a.componentType = kFloat;
  a.type = cols == 2 ? TINYGLTF_TYPE_VEC2 : TINYGLTF_TYPE_VEC3;
  a.count = rows;
  if (with_bounds) {
    a.minValues = lo;
    a.maxValues = hi;
  }
  model_.accessors.push_back(std::move(a));
  return static_cast<int>(model_.accessors.size()) - 1;
}

int GlbBuilder::add_index_accessor(const RowMat3i& F, std::int64_t points) {
  const int type = index_component_type(points);
  const auto n = static_cast<std::size_t>(F.size());
  tinygltf::Accessor a;
  if (type == kUnsignedShort) {
    std::vector<std::uint16_t> idx(n);
    for (std::size_t k = 0; k < n; ++k) idx[k] = static_cast<std::uint16_t>(F.data()[k]);
    a.bufferView = add_buffer_view(idx.data(), n * sizeof(std::uint16_t), kElementArrayBuffer);
  } else {
    std::vector<std::uint32_t> idx(n);
    for (std::size_t k = 0; k < n; ++k) idx[k] = static_cast<std::uint32_t>(F.data()[k]);
    a.bufferView = add_buffer_view(idx.data(), n * sizeof(std::uint32_t), kElementArrayBuffer);
  }
  a.componentType = type;
  a.type = TINYGLTF_TYPE_SCALAR;
  a.count = n;
  model_.accessors.push_back(std::move(a));
  return static_cast<int>(model_.accessors.size()) - 1;
}

double shortest_float_decimal(float x) {
  // std::to_chars without a precision writes the shortest decimal that reads back as x;
  // that decimal as a double is printed the same way by the JSON writer (shortest round trip).
  // (to_chars/from_chars: no locale, unlike strtod.)
  char buf[32];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, x);
  double d = static_cast<double>(x);
  std::from_chars(buf, r.ptr, d);
  // Decimal -> double -> float rounds twice; keep the exact value in the (rare) case that
  // changes the float.
  return static_cast<float>(d) == x ? d : static_cast<double>(x);
}

int GlbBuilder::add_draco_mesh(const DracoPrimitive& primitive, const std::string& name, tinygltf::Value extras) {
  const GltfMesh& d = primitive.decoded.mesh;
  const auto points = static_cast<std::size_t>(d.V.rows());
  tinygltf::Primitive prim;
  prim.mode = kTriangles;
  tinygltf::Value::Object draco_attributes;

  // POSITION must define min and max (glTF 2.0 "Meshes"); they are the decoded floats' bounds,
  // which is what a loader sees after decompression.
  std::vector<float> flo(3, std::numeric_limits<float>::infinity()), fhi(3, -flo[0]);
  for (std::size_t p = 0; p < points; ++p)
    for (int c = 0; c < 3; ++c) {
      const auto x = static_cast<float>(d.V(static_cast<Eigen::Index>(p), c));
      flo[static_cast<std::size_t>(c)] = std::min(flo[static_cast<std::size_t>(c)], x);
      fhi[static_cast<std::size_t>(c)] = std::max(fhi[static_cast<std::size_t>(c)], x);
    }
  std::vector<double> lo, hi;
  for (int c = 0; c < 3; ++c) {
    lo.push_back(shortest_float_decimal(flo[static_cast<std::size_t>(c)]));
    hi.push_back(shortest_float_decimal(fhi[static_cast<std::size_t>(c)]));
  }
  prim.attributes["POSITION"] = add_accessor_without_data(kFloat, TINYGLTF_TYPE_VEC3, points, lo, hi);
  draco_attributes["POSITION"] = tinygltf::Value(primitive.decoded.position_id);
  if (d.N.rows() > 0) {
    prim.attributes["NORMAL"] = add_accessor_without_data(kFloat, TINYGLTF_TYPE_VEC3, points, {}, {});
    draco_attributes["NORMAL"] = tinygltf::Value(primitive.decoded.normal_id);
  }
  if (d.UV.rows() > 0) {
    prim.attributes["TEXCOORD_0"] = add_accessor_without_data(kFloat, TINYGLTF_TYPE_VEC2, points, {}, {});
    draco_attributes["TEXCOORD_0"] = tinygltf::Value(primitive.decoded.texcoord_id);
  }
  prim.indices = add_accessor_without_data(index_component_type(static_cast<std::int64_t>(points)),
                                           TINYGLTF_TYPE_SCALAR, static_cast<std::size_t>(d.F.size()), {}, {});
  tinygltf::Value::Object ext;
  // The bitstream gets its own view, with no target (it is not vertex data).
  ext["bufferView"] = tinygltf::Value(add_buffer_view(primitive.bytes.data(), primitive.bytes.size(), 0));
  ext["attributes"] = tinygltf::Value(std::move(draco_attributes));
  prim.extensions["KHR_draco_mesh_compression"] = tinygltf::Value(std::move(ext));
  use_extension("KHR_draco_mesh_compression", true);

  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(std::move(prim));
  mesh.extras = std::move(extras);  // a null Value is not written
  model_.meshes.push_back(std::move(mesh));
  return static_cast<int>(model_.meshes.size()) - 1;
}

void GlbBuilder::use_extension(const std::string& name, bool required) {
  auto add = [&](std::vector<std::string>& list) {
    if (std::find(list.begin(), list.end(), name) == list.end()) list.push_back(name);
  };
  add(model_.extensionsUsed);
  if (required) add(model_.extensionsRequired);
}

Result<std::string> GlbBuilder::to_glb() {
  if (model_.buffers[0].data.empty()) model_.buffers.clear();
  std::ostringstream out(std::ios::binary);
  try {
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model_, out, /*prettyPrint=*/false, /*writeBinary=*/true))
      return Status(ErrorCode::Internal, "tinygltf could not serialize the glTF document");
  } catch (const std::exception& e) {
    return Status(ErrorCode::Internal, std::string("tinygltf failed: ") + e.what());
  }
  return out.str();
}

tinygltf::Value json_number(double x) { return tinygltf::Value(x); }
tinygltf::Value json_int(std::int64_t x) {
  // tinygltf's integer Value is an int; larger counts are written as numbers.
  if (x >= std::numeric_limits<int>::min() && x <= std::numeric_limits<int>::max())
    return tinygltf::Value(static_cast<int>(x));
  return tinygltf::Value(static_cast<double>(x));
}
tinygltf::Value json_string(const std::string& s) { return tinygltf::Value(s); }
tinygltf::Value json_array(const std::vector<double>& xs) {
  tinygltf::Value::Array a;
  for (double x : xs) a.emplace_back(x);
  return tinygltf::Value(std::move(a));
}
tinygltf::Value json_object(tinygltf::Value::Object o) { return tinygltf::Value(std::move(o)); }

tinygltf::Value quantization_json(const QuantizationChoice& choice, bool has_normals, bool has_texcoords) {
  // What a user needs to know about the error the quantization adds; the grids themselves are
  // in the Draco bitstream (and in the convert report). Kept short: the JSON is part of every
  // level's size.
  const DracoQuantization& q = choice.quantization;
  tinygltf::Value::Object o;
  o["position_bits"] = json_int(q.position_bits);
  o["position_max_error"] = json_number(choice.position_max_error);
  tinygltf::Value::Object budget;
  budget["reference_rms_error"] = json_number(choice.reference_rms_error);
  budget["decided_by"] = json_string(choice.rate_distortion        ? "rate-distortion"
                                     : choice.reference_rms_error > 0 ? "error budget"
                                                                      : "minimum bits");
  o["budget"] = json_object(std::move(budget));
  if (has_normals) o["normal_bits"] = json_int(q.normal_bits);
  if (has_texcoords) o["texcoord_bits"] = json_int(q.texcoord_bits);
  return json_object(std::move(o));
}

tinygltf::Value provenance_json(tinygltf::Value::Object fields) {
  fields["version"] = json_string(kVersion);
  fields["format_version"] = json_int(kFormatVersion);
  tinygltf::Value::Object o;
  o["spherekit"] = json_object(std::move(fields));
  return json_object(std::move(o));
}

}  // namespace spherekit::convert::detail
