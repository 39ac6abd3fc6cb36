// The landmark editor's data for the results page (site_landmarks.h).
#include "site_landmarks.h"

#include <cstdint>
#include <cstring>
#include <filesystem>

#include "spherekit/file_status.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"

namespace spherekit::pipeline::detail {
namespace {

std::string text(const Json& j, const char* key) {
  auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

// Little-endian, whatever the machine: the page reads the bytes as typed arrays, and every
// browser platform is little-endian.
void put_u32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out += static_cast<char>((v >> (8 * k)) & 255u);
}
void put_f32(std::string& out, float f) {
  std::uint32_t v;
  std::memcpy(&v, &f, sizeof v);
  put_u32(out, v);
}

}  // namespace

Result<LandmarkMemberData> landmark_member_data(const Json& member) {
  if (!member.is_object()) return Status(ErrorCode::InvalidArgument, "a landmarks entry is not a JSON object");
  const std::string mesh_path = text(member, "mesh");
  if (mesh_path.empty()) return Status(ErrorCode::InvalidArgument, "a landmarks entry names no mesh");
  // The reader every `.lm.txt` consumer uses (check --landmarks, consistent, landmarks): the
  // same vertex numbering, including STL's welded vertices and polygon triangulation.
  auto mesh = formats::read_mesh(mesh_path);
  if (!mesh.ok()) return with_file(mesh.status(), mesh_path);
  const TriMesh& m = mesh.value();
  const auto nv = static_cast<std::uint32_t>(m.V.rows()), nf = static_cast<std::uint32_t>(m.F.rows());

  LandmarkMemberData out;
  const Eigen::RowVector3d offset = nv ? Eigen::RowVector3d(0.5 * (m.V.colwise().minCoeff() + m.V.colwise().maxCoeff()))
                                       : Eigen::RowVector3d::Zero();
  out.payload.reserve(8 + 12 * static_cast<std::size_t>(nv) + 12 * static_cast<std::size_t>(nf));
  put_u32(out.payload, nv);
  put_u32(out.payload, nf);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    for (int c = 0; c < 3; ++c) put_f32(out.payload, static_cast<float>(m.V(v, c) - offset(c)));
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) put_u32(out.payload, static_cast<std::uint32_t>(m.F(f, c)));

  const std::string name = text(member, "name").empty() ? std::filesystem::path(mesh_path).stem().string()
                                                        : text(member, "name");
  Json& e = out.entry;
  e["name"] = name;
  // Downloaded as the name `consistent` and `run` look for beside the mesh.
  e["file"] = std::filesystem::path(mesh_path).stem().string() + ".lm.txt";
  e["source"] = text(member, "source");
  e["offset"] = {offset(0), offset(1), offset(2)};
  e["vertices"] = nv;
  e["triangles"] = nf;
  e["landmarks"] = Json::array();
  if (const std::string note = text(member, "note"); !note.empty()) e["note"] = note;
  // How sure a proposal is of each name (0..1), shown beside it: what to check first.
  if (auto c = member.find("confidence"); c != member.end() && c->is_object()) {
    Json confidence = Json::object();
    for (const auto& [name, value] : c->items())
      if (value.is_number()) confidence[name] = value;
    e["confidence"] = std::move(confidence);
  }
  if (const std::string features = text(member, "features"); !features.empty()) {
    auto lms = formats::read_landmarks(features, static_cast<int>(nv));
    if (!lms.ok()) {
      e["error"] = with_file(lms.status(), features).message();
    } else {
      for (const Landmark& l : lms.value()) e["landmarks"].push_back({{"name", l.name}, {"vertex", l.vertex}});
    }
  }
  return out;
}

}  // namespace spherekit::pipeline::detail
