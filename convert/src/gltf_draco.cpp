// Draco encoding and decoding of glTF primitives, and quantization from an error budget (see
// gltf_draco.h).
//
// References: Draco bitstream specification v2.2 (quantization, sequential and edgebreaker
// connectivity); google/draco 1.5.5 headers (Encoder, Decoder, Mesh, PointAttribute);
// KHR_draco_mesh_compression README; ALGORITHM.md §5.2-5.3 and §7 gotchas 9-10.
//
// Draco builds the edgebreaker connectivity on the position attribute's value indices
// (CreateCornerTableFromPositionAttribute), so points that share a position value index are one
// vertex and a texture seam (different texture-coordinate values at one vertex) is coded as
// attribute connectivity. The Draco mesh is therefore built with explicit point -> value maps
// from GltfMesh::position_index, never by merging equal values (two texels may hold equal
// positions without being the same vertex).
#include "spherekit/convert/gltf_draco.h"

#include <draco/attributes/geometry_attribute.h>
#include <draco/attributes/point_attribute.h>
#include <draco/compression/config/compression_shared.h>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace spherekit::convert {
namespace {

constexpr int kMaxDracoBits = 30;  // draco_encoder's limit for every attribute

double grid_step(float range, int bits) {
  return static_cast<double>(range) / (std::ldexp(1.0, bits) - 1.0);
}

bool bits_ok(int bits) { return bits >= 1 && bits <= kMaxDracoBits; }

// Point -> attribute value map: the points of each vertex share one value when their values
// are bit-identical (so the attribute follows the position connectivity), otherwise every
// point keeps its own value (identity map).
struct ValueMap {
  bool identity = true;
  std::vector<std::int32_t> value_of_point;  // when !identity
  std::int32_t values = 0;
};

template <class Matrix>
ValueMap map_values(const Matrix& M, const std::vector<std::int32_t>& vertex_of_point, std::int32_t vertices) {
  ValueMap map;
  map.values = static_cast<std::int32_t>(M.rows());
  if (vertex_of_point.empty()) return map;
  std::vector<std::int32_t> first(static_cast<std::size_t>(vertices), -1);
  for (std::size_t p = 0; p < vertex_of_point.size(); ++p) {
    std::int32_t& f = first[static_cast<std::size_t>(vertex_of_point[p])];
    if (f < 0) {
      f = static_cast<std::int32_t>(p);
      continue;
    }
    for (Eigen::Index c = 0; c < M.cols(); ++c)
      if (static_cast<float>(M(f, c)) != static_cast<float>(M(static_cast<Eigen::Index>(p), c))) return map;
  }
  map.identity = false;
  map.values = vertices;
  map.value_of_point = vertex_of_point;
  return map;
}

// Adds a float attribute of `M`'s columns with the given point -> value map.
template <class Matrix>
int add_attribute(draco::Mesh& mesh, draco::GeometryAttribute::Type type, const Matrix& M, const ValueMap& map) {
  const int dims = static_cast<int>(M.cols());
  draco::GeometryAttribute ga;
  ga.Init(type, nullptr, static_cast<std::int8_t>(dims), draco::DT_FLOAT32, false,
          static_cast<std::int64_t>(sizeof(float)) * dims, 0);
  const int id = mesh.AddAttribute(ga, map.identity, static_cast<std::uint32_t>(map.values));
  if (id < 0) return id;
  draco::PointAttribute* att = mesh.attribute(id);
  std::vector<bool> written(static_cast<std::size_t>(map.values), false);
  float value[3];
  for (Eigen::Index p = 0; p < M.rows(); ++p) {
    const std::int32_t v = map.identity ? static_cast<std::int32_t>(p) : map.value_of_point[static_cast<std::size_t>(p)];
    if (!map.identity) att->SetPointMapEntry(draco::PointIndex(static_cast<std::uint32_t>(p)),
                                             draco::AttributeValueIndex(static_cast<std::uint32_t>(v)));
    if (written[static_cast<std::size_t>(v)]) continue;
    written[static_cast<std::size_t>(v)] = true;
    for (int c = 0; c < dims; ++c) value[c] = static_cast<float>(M(p, c));
    att->SetAttributeValue(draco::AttributeValueIndex(static_cast<std::uint32_t>(v)), value);
  }
  return id;
}

// True if every point's float coordinates lie in [origin, origin + range] as Draco computes it
// (float subtraction), so no quantized value exceeds 2^bits - 1.
template <class Matrix, std::size_t D>
bool inside_grid(const Matrix& M, const std::array<float, D>& origin, float range) {
  for (Eigen::Index p = 0; p < M.rows(); ++p)
    for (std::size_t c = 0; c < D; ++c) {
      const float d = static_cast<float>(M(p, static_cast<Eigen::Index>(c))) - origin[c];
      if (!(d >= 0.0f && d <= range)) return false;
    }
  return true;
}

}  // namespace

double DracoQuantization::position_step() const { return grid_step(position_range, position_bits); }
double DracoQuantization::texcoord_step() const { return grid_step(texcoord_range, texcoord_bits); }

Result<QuantizationChoice> choose_draco_quantization(const GltfMesh& finest, double reference_rms_error,
                                                     const QuantizationBudget& budget) {
  SPHEREKIT_RETURN_IF_ERROR(check_gltf_mesh(finest));
  if (!bits_ok(budget.min_position_bits) || !bits_ok(budget.max_position_bits) ||
      budget.min_position_bits > budget.max_position_bits || !bits_ok(budget.normal_bits) ||
      !bits_ok(budget.min_texcoord_bits))
    return Status(ErrorCode::InvalidArgument, "quantization bits must be in 1..30 (and min <= max)");
  if (!(budget.position_error_fraction > 0) || !std::isfinite(budget.position_error_fraction))
    return Status(ErrorCode::InvalidArgument, "position_error_fraction must be > 0");

  QuantizationChoice out;
  DracoQuantization& q = out.quantization;
  // Position grid: bounding box of the stored floats, a cube of the largest extent (Draco's
  // convention: one range for all axes, so the grid is isotropic).
  std::array<float, 3> lo, hi;
  lo.fill(std::numeric_limits<float>::infinity());
  hi.fill(-std::numeric_limits<float>::infinity());
  for (Eigen::Index p = 0; p < finest.V.rows(); ++p)
    for (int c = 0; c < 3; ++c) {
      const auto x = static_cast<float>(finest.V(p, c));
      lo[static_cast<std::size_t>(c)] = std::min(lo[static_cast<std::size_t>(c)], x);
      hi[static_cast<std::size_t>(c)] = std::max(hi[static_cast<std::size_t>(c)], x);
    }
  float range = 0;
  // Computed in float exactly as Draco computes each point's offset, so the largest offset
  // equals the range and quantizes to 2^bits - 1.
  for (std::size_t c = 0; c < 3; ++c) range = std::max(range, hi[c] - lo[c]);
  // A single point (or all points equal): any positive range represents it exactly.
  if (!(range > 0)) range = 1;
  q.position_origin = lo;
  q.position_range = range;

  int bits = budget.min_position_bits;
  if (reference_rms_error > 0 && std::isfinite(reference_rms_error)) {
    out.reference_rms_error = reference_rms_error;
    // RMS displacement step/2 <= fraction * reference  <=>  2^bits - 1 >= range / (2 f ref).
    const double needed = static_cast<double>(range) / (2.0 * budget.position_error_fraction * reference_rms_error);
    const double b = std::ceil(std::log2(needed + 1.0));
    bits = static_cast<int>(std::clamp(b, static_cast<double>(budget.min_position_bits),
                                       static_cast<double>(budget.max_position_bits)));
  }
  out.position_error_fraction = budget.position_error_fraction;
  q.position_bits = bits;
  out.position_max_error = q.position_step() / 2;
  q.normal_bits = budget.normal_bits;

  q.texcoord_bits = budget.min_texcoord_bits;
  if (finest.UV.rows() > 0) {
    const int T = finest.texture_size;
    if (T > 1) {
      // Texel-centre grid: origin 1/(2T), step 1/(T m) with m = floor((2^b - 1)/(T - 1)) >= 1,
      // so texel centre j is grid value j*m and the last centre, (T-1)/T past the origin, fits.
      // The fewest bits that hold the lattice (m = 1 for T = 2^k + 1; QuantizationBudget).
      q.texcoord_bits = 1;
      while (q.texcoord_bits < kMaxDracoBits && std::ldexp(1.0, q.texcoord_bits) - 1.0 < T - 1) ++q.texcoord_bits;
      const double levels = std::ldexp(1.0, q.texcoord_bits) - 1.0;
      const double m = std::floor(levels / (T - 1));
      q.texcoord_origin = {static_cast<float>(0.5 / T), static_cast<float>(0.5 / T)};
      q.texcoord_range = static_cast<float>(levels / (T * m));
    } else {
      std::array<float, 2> tlo{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()};
      std::array<float, 2> thi{-tlo[0], -tlo[1]};
      for (Eigen::Index p = 0; p < finest.UV.rows(); ++p)
        for (int c = 0; c < 2; ++c) {
          const auto x = static_cast<float>(finest.UV(p, c));
          tlo[static_cast<std::size_t>(c)] = std::min(tlo[static_cast<std::size_t>(c)], x);
          thi[static_cast<std::size_t>(c)] = std::max(thi[static_cast<std::size_t>(c)], x);
        }
      float trange = std::max(thi[0] - tlo[0], thi[1] - tlo[1]);
      if (!(trange > 0)) trange = 1;
      q.texcoord_origin = tlo;
      q.texcoord_range = trange;
    }
  }
  return out;
}

Result<DecodedDraco> decode_draco_primitive(std::string_view bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) return Status(ErrorCode::ParseError, "Draco decoding failed: " + decoded.status().error_msg_string());
  std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) return Status(ErrorCode::ParseError, "Draco data holds no mesh");

  DecodedDraco out;
  const auto points = static_cast<Eigen::Index>(mesh->num_points());
  auto read = [&](draco::GeometryAttribute::Type type, int dims, auto& M, int& id) -> Status {
    const draco::PointAttribute* att = mesh->GetNamedAttribute(type);
    if (!att) return Status();
    if (att->num_components() != dims)
      return Status(ErrorCode::Unsupported, "Draco attribute with " + std::to_string(att->num_components()) +
                                                " components where " + std::to_string(dims) + " were expected");
    id = static_cast<int>(att->unique_id());
    M.resize(points, dims);
    float v[3];
    for (Eigen::Index p = 0; p < points; ++p) {
      if (!att->ConvertValue<float>(att->mapped_index(draco::PointIndex(static_cast<std::uint32_t>(p))),
                                    static_cast<std::int8_t>(dims), v))
        return Status(ErrorCode::ParseError, "Draco attribute value of point " + std::to_string(p) + " unreadable");
      for (int c = 0; c < dims; ++c) M(p, c) = v[c];
    }
    return Status();
  };
  SPHEREKIT_RETURN_IF_ERROR(read(draco::GeometryAttribute::POSITION, 3, out.mesh.V, out.position_id));
  if (out.position_id < 0) return Status(ErrorCode::Unsupported, "Draco mesh has no POSITION attribute");
  SPHEREKIT_RETURN_IF_ERROR(read(draco::GeometryAttribute::NORMAL, 3, out.mesh.N, out.normal_id));
  SPHEREKIT_RETURN_IF_ERROR(read(draco::GeometryAttribute::TEX_COORD, 2, out.mesh.UV, out.texcoord_id));
  out.mesh.F.resize(static_cast<Eigen::Index>(mesh->num_faces()), 3);
  for (std::uint32_t f = 0; f < mesh->num_faces(); ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t p = face[k].value();
      if (p >= mesh->num_points()) return Status(ErrorCode::ParseError, "Draco face index out of range");
      out.mesh.F(static_cast<Eigen::Index>(f), k) = static_cast<std::int32_t>(p);
    }
  }
  return out;
}

Result<DracoPrimitive> encode_draco_primitive(const GltfMesh& mesh, const DracoEncodeOptions& options) {
  SPHEREKIT_RETURN_IF_ERROR(check_gltf_mesh(mesh));
  const DracoQuantization& q = options.quantization;
  if (options.compression_level < 0 || options.compression_level > 10)
    return Status(ErrorCode::InvalidArgument, "compression_level must be in 0..10");
  if (!bits_ok(q.position_bits) || !bits_ok(q.normal_bits) || !bits_ok(q.texcoord_bits) ||
      !(q.position_range > 0) || !(q.texcoord_range > 0) || !std::isfinite(q.position_range) ||
      !std::isfinite(q.texcoord_range))
    return Status(ErrorCode::InvalidArgument, "quantization bits must be in 1..30 and grid ranges > 0");
  if (!inside_grid(mesh.V, q.position_origin, q.position_range))
    return Status(ErrorCode::InvalidInput, "a position lies outside the quantization grid");
  if (mesh.UV.rows() > 0 && !inside_grid(mesh.UV, q.texcoord_origin, q.texcoord_range))
    return Status(ErrorCode::InvalidInput, "a texture coordinate lies outside the quantization grid");

  const auto points = static_cast<std::uint32_t>(mesh.V.rows());
  // Vertices numbered densely in order of first appearance, so that every attribute value
  // belongs to some point (position_index may skip numbers).
  std::int32_t vertices = 0;
  const std::vector<std::int32_t> vertex_of_point = gltf_point_vertices(mesh, &vertices);

  draco::Mesh dm;
  dm.set_num_points(points);
  const ValueMap position_map = map_values(mesh.V, vertex_of_point, vertices);
  if (!vertex_of_point.empty() && position_map.identity)
    return Status(ErrorCode::InvalidInput, "points sharing a position_index have different positions");
  if (add_attribute(dm, draco::GeometryAttribute::POSITION, mesh.V, position_map) < 0)
    return Status(ErrorCode::Internal, "Draco rejected the POSITION attribute");
  if (mesh.N.rows() > 0 &&
      add_attribute(dm, draco::GeometryAttribute::NORMAL, mesh.N, map_values(mesh.N, vertex_of_point, vertices)) < 0)
    return Status(ErrorCode::Internal, "Draco rejected the NORMAL attribute");
  if (mesh.UV.rows() > 0 &&
      add_attribute(dm, draco::GeometryAttribute::TEX_COORD, mesh.UV, map_values(mesh.UV, vertex_of_point, vertices)) < 0)
    return Status(ErrorCode::Internal, "Draco rejected the TEX_COORD attribute");
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    draco::Mesh::Face face;
    for (int k = 0; k < 3; ++k) face[k] = draco::PointIndex(static_cast<std::uint32_t>(mesh.F(f, k)));
    dm.AddFace(face);
  }

  auto encode = [&](bool texcoord_parallelogram) -> Result<std::string> {
    draco::Encoder encoder;
    encoder.SetAttributeExplicitQuantization(draco::GeometryAttribute::POSITION, q.position_bits, 3,
                                             q.position_origin.data(), q.position_range);
    if (mesh.N.rows() > 0) encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, q.normal_bits);
    if (mesh.UV.rows() > 0) {
      encoder.SetAttributeExplicitQuantization(draco::GeometryAttribute::TEX_COORD, q.texcoord_bits, 2,
                                               q.texcoord_origin.data(), q.texcoord_range);
      // Texel-lattice coordinates: parallelogram prediction (the fourth corner of the
      // parallelogram over the neighbouring triangle) is exact on a grid, so they cost almost
      // nothing. Draco's default texture-coordinate predictor extrapolates from the 3D triangle
      // shapes and spent about a third of a geometry-image LOD's bytes on them (bunny,
      // 257 x 257: 310 KB -> 225 KB).
      if (texcoord_parallelogram) {
        const draco::Status ps =
            encoder.SetAttributePredictionScheme(draco::GeometryAttribute::TEX_COORD, draco::MESH_PREDICTION_PARALLELOGRAM);
        if (!ps.ok()) return Status(ErrorCode::Internal, "Draco rejected the prediction scheme: " + ps.error_msg_string());
      }
    }
    const int speed = 10 - options.compression_level;
    encoder.SetSpeedOptions(speed, speed);
    encoder.SetEncodingMethod(options.sequential ? draco::MESH_SEQUENTIAL_ENCODING : draco::MESH_EDGEBREAKER_ENCODING);
    draco::EncoderBuffer buffer;
    const draco::Status st = encoder.EncodeMeshToBuffer(dm, &buffer);
    if (!st.ok()) return Status(ErrorCode::Internal, "Draco encoding failed: " + st.error_msg_string());
    return std::string(buffer.data(), buffer.size());
  };
  const bool lattice = mesh.UV.rows() > 0 && mesh.texture_size > 0 && !options.sequential;
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, encode(lattice));
  if (options.smallest_texcoord_prediction && mesh.UV.rows() > 0 && !lattice && !options.sequential) {
    SPHEREKIT_ASSIGN_OR_RETURN(std::string other, encode(true));
    if (other.size() < bytes.size()) bytes = std::move(other);
  }

  DracoPrimitive out;
  out.bytes = std::move(bytes);
  auto decoded = decode_draco_primitive(out.bytes);
  if (!decoded.ok())
    return Status(ErrorCode::Internal, "Draco cannot decode its own output: " + decoded.status().message());
  out.decoded = std::move(decoded).value();
  out.decoded.mesh.texture_size = mesh.texture_size;

  if (options.sequential) {
    // The reason to encode sequentially is the point order: verify it survived (same count,
    // same faces, every position within the grid's half step).
    const GltfMesh& d = out.decoded.mesh;
    bool same = d.V.rows() == mesh.V.rows() && d.F == mesh.F;
    // Half a step, plus float rounding of the dequantization (origin + q * step in float).
    double magnitude = q.position_range;
    for (const float o : q.position_origin) magnitude += std::abs(static_cast<double>(o));
    const double tol = q.position_step() / 2 + 4 * std::numeric_limits<float>::epsilon() * magnitude;
    for (Eigen::Index p = 0; same && p < d.V.rows(); ++p)
      same = (d.V.row(p) - mesh.V.row(p)).cwiseAbs().maxCoeff() <= tol;
    if (!same) return Status(ErrorCode::Internal, "Draco sequential encoding changed the point order");
  }
  return out;
}

}  // namespace spherekit::convert
