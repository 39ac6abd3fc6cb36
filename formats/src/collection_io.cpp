// The collection folder format (collection.h): manifest parsing, validation and writing,
// the features.txt cross-check, member loading.
#include "spherekit/formats/collection.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/file_status.h"
#include "spherekit/format_text.h"

namespace fs = std::filesystem;

namespace spherekit::formats {
namespace {

using Json = OrderedJson;


Status bad(const std::string& file, const std::string& what) {
  return Status(ErrorCode::InvalidInput, file + ": " + what);
}

std::string manifest_path(const std::string& dir) { return (fs::path(dir) / kCollectionManifest).string(); }

Json vector_json(const Eigen::Vector3d& p) { return Json::array({p.x(), p.y(), p.z()}); }

std::optional<std::string> string_field(const Json& j, const char* key, Json& extra) {
  if (!j.contains(key)) return std::nullopt;
  if (j[key].is_string()) return j[key].get<std::string>();
  extra[key] = j[key];  // not what the format writes: kept as it is
  return std::nullopt;
}

std::optional<long long> integer_field(const Json& j, const char* key, Json& extra) {
  if (!j.contains(key)) return std::nullopt;
  if (j[key].is_number_integer()) return j[key].get<long long>();
  extra[key] = j[key];
  return std::nullopt;
}

// The checks every reader relies on (the same as before the manifest was typed): what the
// commands index, name files after or compare must be there and well formed.
Status validate(const Json& m, const std::string& file) {
  // (value() would throw on a "format" that is not a string: test the type first.)
  if (!m.is_object() || !m.contains("format") || !m["format"].is_string() ||
      m["format"].get<std::string>() != kCollectionFormat)
    return bad(file, std::string("not a ") + kCollectionFormat + " manifest (its \"format\" must be \"" +
                         kCollectionFormat + "\")");
  // Versions start at 1: 0, negative or non-integer versions were never written.
  if (!m.contains("format_version") || !m["format_version"].is_number_integer() ||
      m["format_version"].get<long long>() < 1 || m["format_version"].get<long long>() > kCollectionFormatVersion)
    return bad(file, "unsupported format_version " +
                         (m.contains("format_version") ? m["format_version"].dump() : std::string("(missing)")) +
                         " (this spherekit reads up to " + std::to_string(kCollectionFormatVersion) + ")");
  if (!m.contains("features") || !m["features"].is_array()) return bad(file, "missing 'features'");
  std::vector<std::string> feature_names;
  for (const Json& f : m["features"]) {
    if (!f.is_object() || !f.contains("name") || !f["name"].is_string() || f["name"].get<std::string>().empty() ||
        !f.contains("location") || !f["location"].is_array() || f["location"].size() != 3)
      return bad(file, "each feature needs a name and a location [x, y, z]");
    const std::string name = f["name"].get<std::string>();
    Eigen::Vector3d p;
    for (int a = 0; a < 3; ++a) {
      if (!f["location"][static_cast<size_t>(a)].is_number()) return bad(file, "feature location is not numeric");
      p[a] = f["location"][static_cast<size_t>(a)].get<double>();
    }
    if (!p.allFinite() || std::abs(p.norm() - 1) > 1e-9)
      return bad(file, "location of feature '" + name + "' is not a unit vector");
    // Two features of one name would be two constraints on one vertex of every member.
    if (std::find(feature_names.begin(), feature_names.end(), name) != feature_names.end())
      return bad(file, "duplicate feature name '" + name + "'");
    feature_names.push_back(name);
  }
  if (feature_names.empty()) return bad(file, "no features");
  if (!m.contains("meshes") || !m["meshes"].is_array()) return bad(file, "missing 'meshes'");
  std::vector<std::string> names, maps;
  for (const Json& e : m["meshes"]) {
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("map") ||
        !e["map"].is_string())
      return bad(file, "each mesh needs a name and a map file");
    const std::string name = e["name"].get<std::string>(), map = e["map"].get<std::string>();
    // Maps live in the folder (add writes them there): a path would read or overwrite
    // files elsewhere.
    if (map.empty() || map == "." || map == ".." || map.find('/') != std::string::npos)
      return bad(file, "map '" + map + "' of mesh '" + name + "' is not a file name in the collection folder");
    if (std::find(names.begin(), names.end(), name) != names.end()) return bad(file, "duplicate mesh name '" + name + "'");
    if (std::find(maps.begin(), maps.end(), map) != maps.end())
      return bad(file, "map '" + map + "' is listed for two meshes");
    if (e.contains("vertices") && !(e["vertices"].is_number_integer() && e["vertices"].get<long long>() >= 4))
      return bad(file, "'vertices' of mesh '" + name + "' is not a vertex count");
    names.push_back(name);
    maps.push_back(map);
  }
  return Status();
}

CollectionFeature feature_of(const Json& f) {
  CollectionFeature out;
  out.name = f["name"].get<std::string>();
  for (int a = 0; a < 3; ++a) out.location[a] = f["location"][static_cast<size_t>(a)].get<double>();
  const Json* q = f.contains("initial_location") ? &f["initial_location"] : nullptr;
  if (q && q->is_array() && q->size() == 3 && std::all_of(q->begin(), q->end(), [](const Json& x) { return x.is_number(); }))
    out.initial_location = Eigen::Vector3d((*q)[0].get<double>(), (*q)[1].get<double>(), (*q)[2].get<double>());
  // Everything else (a label, a malformed initial_location) is kept as it is.
  for (auto it = f.begin(); it != f.end(); ++it)
    if (it.key() != "name" && it.key() != "location" && (it.key() != "initial_location" || !out.initial_location))
      out.extra[it.key()] = it.value();
  return out;
}

CollectionMember member_of(const Json& e) {
  static const char* const kKnown[] = {"name",  "source",           "features_file", "map", "vertices",
                                       "faces", "feature_vertices", "added",         "result"};
  CollectionMember m;
  m.name = e["name"].get<std::string>();
  m.map = e["map"].get<std::string>();
  m.source = string_field(e, "source", m.extra);
  m.features_file = string_field(e, "features_file", m.extra);
  m.vertices = integer_field(e, "vertices", m.extra);
  m.faces = integer_field(e, "faces", m.extra);
  if (e.contains("feature_vertices")) {
    if (e["feature_vertices"].is_array()) {
      std::vector<long long> fv;
      for (const Json& v : e["feature_vertices"]) fv.push_back(v.is_number_integer() ? v.get<long long>() : -1);
      m.feature_vertices = std::move(fv);
    } else {
      m.extra["feature_vertices"] = e["feature_vertices"];
    }
  }
  if (e.contains("added")) {
    if (e["added"].is_boolean())
      m.added = e["added"].get<bool>();
    else
      m.extra["added"] = e["added"];
  }
  if (e.contains("result")) m.result = e["result"];
  for (auto it = e.begin(); it != e.end(); ++it)
    if (std::find_if(std::begin(kKnown), std::end(kKnown), [&](const char* k) { return it.key() == k; }) == std::end(kKnown))
      m.extra[it.key()] = it.value();
  return m;
}

Json member_json(const CollectionMember& m) {
  Json e;
  e["name"] = m.name;
  if (m.source) e["source"] = *m.source;
  if (m.features_file) e["features_file"] = *m.features_file;
  e["map"] = m.map;
  if (m.vertices) e["vertices"] = *m.vertices;
  if (m.faces) e["faces"] = *m.faces;
  if (m.feature_vertices) e["feature_vertices"] = *m.feature_vertices;
  if (m.added) e["added"] = *m.added;
  if (!m.result.is_null()) e["result"] = m.result;
  for (auto it = m.extra.begin(); it != m.extra.end(); ++it) e[it.key()] = it.value();
  return e;
}

// DIR/features.txt must hold the manifest's features: the same names, each at the same
// location, and nothing else. It is a copy for other tools; a copy that disagrees means the
// folder was edited or mixed with another collection's, so which F is meant is unknown.
Status check_features_file(const Collection& c) {
  const std::string path = (fs::path(c.dir) / kCollectionFeatures).string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return Status(ErrorCode::IoError, path + ": missing (every collection folder has one; rewrite it with 'spherekit consistent')");
  auto points = read_sphere_points(path, /*require_unit=*/true);
  if (!points.ok()) return with_file(points.status(), path);
  const std::string manifest = manifest_path(c.dir);
  for (const CollectionFeature& f : c.manifest.features) {
    auto it = std::find_if(points->begin(), points->end(), [&](const SpherePoint& p) { return p.name == f.name; });
    if (it == points->end()) return bad(path, "no feature '" + f.name + "' (" + manifest + " has it)");
    // Both files carry 17 significant digits: equal up to the last bit.
    if ((it->p - f.location).norm() > 1e-12)
      return bad(path, "feature '" + f.name + "' is not where " + manifest + " puts it");
  }
  if (points->size() != c.manifest.features.size())
    return bad(path, format_text("has %zu features, %s has %zu", points->size(), manifest.c_str(),
                                 c.manifest.features.size()));
  return Status();
}

}  // namespace

int CollectionManifest::member_index(const std::string& name) const {
  for (std::size_t i = 0; i < members.size(); ++i)
    if (members[i].name == name) return static_cast<int>(i);
  return -1;
}

std::vector<std::string> CollectionManifest::feature_names() const {
  std::vector<std::string> out;
  for (const CollectionFeature& f : features) out.push_back(f.name);
  return out;
}

std::vector<Eigen::Vector3d> CollectionManifest::locations() const {
  std::vector<Eigen::Vector3d> out;
  for (const CollectionFeature& f : features) out.push_back(f.location);
  return out;
}

Result<CollectionManifest> parse_collection_manifest(const std::string& text, const std::string& file) {
  if (text.empty()) return Status(ErrorCode::ParseError, file + ": file is empty");
  Json m;
  try {
    m = Json::parse(text);
  } catch (const Json::parse_error& e) {
    // Where it broke tells a cut-off file (a copy interrupted mid-way) from an edit gone wrong.
    if (e.byte >= text.size())
      return Status(ErrorCode::ParseError,
                    format_text("%s: not valid JSON: ends early after %zu bytes (truncated?)", file.c_str(), text.size()));
    return Status(ErrorCode::ParseError, format_text("%s: not valid JSON (syntax error at byte %zu)", file.c_str(), e.byte));
  } catch (const Json::exception& e) {
    // The parser's other refusals, e.g. "number overflow parsing '1e400'" (out_of_range).
    std::string why = e.what();
    if (const size_t at = why.find("] "); at != std::string::npos) why = why.substr(at + 2);
    return Status(ErrorCode::ParseError, file + ": not valid JSON (" + why + ")");
  }
  SPHEREKIT_RETURN_IF_ERROR(validate(m, file));
  CollectionManifest out;
  out.format_version = m["format_version"].get<int>();
  out.library_version = string_field(m, "library_version", out.extra);
  out.method = string_field(m, "method", out.extra);
  out.reference = string_field(m, "reference", out.extra);
  for (const Json& f : m["features"]) out.features.push_back(feature_of(f));
  for (const Json& e : m["meshes"]) out.members.push_back(member_of(e));
  if (m.contains("options")) out.options = m["options"];
  static const char* const kKnown[] = {"format",    "format_version", "library_version", "method",
                                       "reference", "features",       "meshes",          "options"};
  for (auto it = m.begin(); it != m.end(); ++it)
    if (std::find_if(std::begin(kKnown), std::end(kKnown), [&](const char* k) { return it.key() == k; }) == std::end(kKnown))
      out.extra[it.key()] = it.value();
  return out;
}

OrderedJson collection_manifest_json(const CollectionManifest& c) {
  Json m;
  m["format"] = kCollectionFormat;
  m["format_version"] = c.format_version;
  if (c.library_version) m["library_version"] = *c.library_version;
  if (c.method) m["method"] = *c.method;
  if (c.reference) m["reference"] = *c.reference;
  m["features"] = Json::array();
  for (const CollectionFeature& f : c.features) {
    Json j{{"name", f.name}, {"location", vector_json(f.location)}};
    if (f.initial_location) j["initial_location"] = vector_json(*f.initial_location);
    for (auto it = f.extra.begin(); it != f.extra.end(); ++it) j[it.key()] = it.value();
    m["features"].push_back(std::move(j));
  }
  m["meshes"] = Json::array();
  for (const CollectionMember& e : c.members) m["meshes"].push_back(member_json(e));
  if (!c.options.is_null()) m["options"] = c.options;
  for (auto it = c.extra.begin(); it != c.extra.end(); ++it) m[it.key()] = it.value();
  return m;
}

std::string collection_manifest_text(const CollectionManifest& c) {
  const Json m = collection_manifest_json(c);
  // Non-finite doubles become null (nlohmann's choice), which every JSON reader accepts.
  return m.dump(2) + "\n";
}

Result<Collection> read_collection(const std::string& dir) {
  const std::string file = manifest_path(dir);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status(ErrorCode::IoError, dir + ": no such collection folder");
  if (!fs::is_regular_file(file, ec))
    return Status(ErrorCode::IoError, file + ": missing (not a collection folder; make one with 'spherekit consistent')");
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, read_file(file));
  Collection c;
  c.dir = dir;
  SPHEREKIT_ASSIGN_OR_RETURN(c.manifest, parse_collection_manifest(text, file));
  SPHEREKIT_RETURN_IF_ERROR(check_features_file(c));
  return c;
}

Status check_member_maps(const Collection& c, int skip) {
  const std::string manifest = manifest_path(c.dir);
  for (std::size_t i = 0; i < c.manifest.members.size(); ++i) {
    if (static_cast<int>(i) == skip) continue;
    const CollectionMember& e = c.manifest.members[i];
    const std::string path = (fs::path(c.dir) / e.map).string();
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
      return Status(ErrorCode::IoError, path + ": missing (the map of member '" + e.name + "' in " + manifest + ")");
    auto map = read_mesh(path);
    if (!map.ok()) return with_file(map.status(), path);
    if (e.vertices && map->V.rows() != *e.vertices)
      return bad(path, format_text("has %lld vertices, %s records %lld for member '%s'",
                                   static_cast<long long>(map->V.rows()), manifest.c_str(), *e.vertices, e.name.c_str()));
  }
  return Status();
}

int find_member(const Collection& c, const std::string& mesh_path) {
  const std::string stem = fs::path(mesh_path).stem().string();
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(mesh_path, ec), ec);
  int by_stem = -1;
  for (std::size_t i = 0; i < c.manifest.members.size(); ++i) {
    const CollectionMember& e = c.manifest.members[i];
    if (e.source && fs::path(*e.source) == abs) return static_cast<int>(i);
    if (by_stem < 0 && e.name == stem) by_stem = static_cast<int>(i);
  }
  return by_stem;
}

Result<LoadedMember> load_collection_member(const Collection& c, int i, const std::string& fallback_path) {
  const CollectionMember& e = c.manifest.members.at(static_cast<std::size_t>(i));
  LoadedMember m;
  m.index = i;
  m.name = e.name;
  m.source = e.source.value_or(std::string());
  std::error_code ec;
  if ((m.source.empty() || !fs::is_regular_file(m.source, ec)) && !fallback_path.empty() &&
      fs::is_regular_file(fallback_path, ec))
    m.source = fallback_path;
  if (m.source.empty())
    return Status(ErrorCode::InvalidInput, c.dir + ": member " + m.name + " has no source mesh in the manifest");
  SPHEREKIT_ASSIGN_OR_RETURN(m.mesh, read_mesh(m.source));
  SPHEREKIT_ASSIGN_OR_RETURN(m.map, read_sphere_map((fs::path(c.dir) / e.map).string(), m.mesh));
  if (e.feature_vertices) {
    const std::vector<long long>& fv = *e.feature_vertices;
    m.features.resize(static_cast<Eigen::Index>(fv.size()), 3);
    for (std::size_t k = 0; k < fv.size(); ++k) {
      if (fv[k] < 0 || fv[k] >= m.mesh.V.rows())
        return Status(ErrorCode::InvalidInput, manifest_path(c.dir) + ": member " + m.name + ": feature vertex out of range");
      m.features.row(static_cast<Eigen::Index>(k)) = m.mesh.V.row(static_cast<Eigen::Index>(fv[k]));
    }
  }
  return m;
}

Result<LoadedMember> load_collection_member(const Collection& c, const std::string& name_or_path) {
  const int i = find_member(c, name_or_path);
  if (i < 0) {
    std::string names;
    for (const CollectionMember& e : c.manifest.members) names += (names.empty() ? "" : ", ") + e.name;
    return Status(ErrorCode::InvalidInput, name_or_path + ": not a member of the collection " + c.dir + " (members: " +
                                               names + ")");
  }
  return load_collection_member(c, i, name_or_path);
}

Result<std::vector<LoadedMember>> load_collection_members(const Collection& c) {
  std::vector<LoadedMember> out;
  for (std::size_t i = 0; i < c.manifest.members.size(); ++i) {
    SPHEREKIT_ASSIGN_OR_RETURN(LoadedMember m, load_collection_member(c, static_cast<int>(i)));
    out.push_back(std::move(m));
  }
  return out;
}

std::string sphere_points_text(const std::vector<std::string>& names, const std::vector<Eigen::Vector3d>& points) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i)
    out += format_text("%s %.17g %.17g %.17g\n", names[i].c_str(), points[i].x(), points[i].y(), points[i].z());
  return out;
}

}  // namespace spherekit::formats
