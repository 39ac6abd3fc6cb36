// Landmark files (`name vertex_index`), sphere-point files (`name x y z`) and landmark
// targets (`name vertex_index x y z`): one record per line, '#' comments, blank lines
// ignored. Every problem is reported as "file:line: ...".
#include "spherekit/formats/feature_io.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string_view>
#include <vector>

#include "feature_codecs.h"
#include "number_text.h"
#include "spherekit/formats/atomic_file.h"
#include "text_scan.h"
#include "unit_vector.h"

namespace spherekit::formats {
namespace {

using detail::quote_token;

/// Splits a content line into at most `kMaxFields` tokens and counts all of them.
struct Fields {
  static constexpr int kMaxFields = 5;
  std::string_view token[kMaxFields];
  int count = 0;
};

Fields split_fields(std::string_view content) {
  Fields f;
  std::string_view token;
  while (detail::next_token(content, token)) {
    if (f.count < Fields::kMaxFields) f.token[f.count] = token;
    ++f.count;
  }
  return f;
}

/// Names are single tokens; anything else could not be read back.
bool writable_name(const std::string& name) {
  if (name.empty() || name.front() == '#') return false;
  for (char c : name) {
    if (static_cast<unsigned char>(c) <= 0x20 || c == 0x7f || c == '#') return false;
  }
  return true;
}

/// A vector length for a message: "2", "0.5", "1e+303" (to_string would print 300 digits).
std::string length_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

Status bad_name(const std::string& path, const std::string& name) {
  return Status(ErrorCode::InvalidInput, path + ": cannot write name " + quote_token(name) +
                                             " (names must be non-empty, without spaces or '#')");
}

}  // namespace

namespace detail {

Result<std::vector<Landmark>> parse_landmarks(const std::string& path, std::string_view bytes, int num_vertices) {
  detail::LineReader lines(bytes);
  std::vector<Landmark> landmarks;
  std::map<std::string, std::uint64_t, std::less<>> name_line;    // name -> line of first use
  std::map<int, std::size_t> vertex_owner;                         // vertex -> landmark index
  std::vector<std::uint64_t> landmark_line;
  std::string_view line;
  while (lines.next(line)) {
    const std::string at = path + ":" + std::to_string(lines.number()) + ": ";
    const Fields f = split_fields(detail::strip_comment(line));
    if (f.count == 0) continue;
    if (f.count != 2) {
      return Status(ErrorCode::ParseError,
                    at + "expected 'name vertex_index', got " + std::to_string(f.count) + " fields");
    }
    std::int64_t index = 0;
    if (!detail::parse_int(f.token[1], index)) {
      return Status(ErrorCode::ParseError, at + "vertex index " + quote_token(f.token[1]) + " is not an integer");
    }
    if (index < 0) return Status(ErrorCode::InvalidInput, at + "negative vertex index " + std::to_string(index));
    if ((num_vertices >= 0 && index >= num_vertices) || index > std::numeric_limits<int>::max()) {
      return Status(ErrorCode::InvalidInput, at + "vertex index " + std::to_string(index) + " out of range (" +
                                                 (num_vertices >= 0 ? std::to_string(num_vertices) : "int") +
                                                 (num_vertices >= 0 ? " vertices)" : " range)"));
    }
    const std::string name(f.token[0]);
    if (auto it = name_line.find(name); it != name_line.end()) {
      return Status(ErrorCode::InvalidInput, at + "duplicate landmark name " + quote_token(name) + " (first on line " +
                                                 std::to_string(it->second) + ")");
    }
    const int vertex = static_cast<int>(index);
    if (auto it = vertex_owner.find(vertex); it != vertex_owner.end()) {
      return Status(ErrorCode::InvalidInput, at + "landmark " + quote_token(name) + " uses vertex " +
                                                 std::to_string(vertex) + ", already used by " +
                                                 quote_token(landmarks[it->second].name) + " (line " +
                                                 std::to_string(landmark_line[it->second]) + ")");
    }
    name_line.emplace(name, lines.number());
    vertex_owner.emplace(vertex, landmarks.size());
    landmark_line.push_back(lines.number());
    landmarks.push_back({name, vertex});
  }
  return landmarks;
}

}  // namespace detail

Result<std::vector<Landmark>> read_landmarks(const std::string& path, int num_vertices) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  return detail::parse_landmarks(path, bytes, num_vertices);
}

Status write_landmarks(const std::string& path, const std::vector<Landmark>& landmarks) {
  std::string out = "# landmarks: name vertex_index (0-based)\n";
  for (const Landmark& l : landmarks) {
    if (!writable_name(l.name)) return bad_name(path, l.name);
    if (l.vertex < 0) {
      return Status(ErrorCode::InvalidInput, path + ": landmark " + quote_token(l.name) + " has negative vertex " +
                                                 std::to_string(l.vertex));
    }
    out += l.name;
    out += ' ';
    detail::append_int(out, l.vertex);
    out += '\n';
  }
  return write_file_atomic(path, out);
}

namespace detail {

Result<std::vector<SpherePoint>> parse_sphere_points(const std::string& path, std::string_view bytes,
                                                     bool require_unit) {
  // Points are unit to within writing precision; only |p| further than this from 1 is
  // worth dividing out, so points written exactly come back bit-identical.
  constexpr double kUnitRoundoff = 4 * std::numeric_limits<double>::epsilon();
  constexpr double kRequireUnitTolerance = 1e-6;  // the documented contract of require_unit
  detail::LineReader lines(bytes);
  std::vector<SpherePoint> points;
  std::map<std::string, std::uint64_t, std::less<>> name_line;
  std::string_view line;
  while (lines.next(line)) {
    const std::string at = path + ":" + std::to_string(lines.number()) + ": ";
    const Fields f = split_fields(detail::strip_comment(line));
    if (f.count == 0) continue;
    if (f.count != 4) {
      return Status(ErrorCode::ParseError, at + "expected 'name x y z', got " + std::to_string(f.count) + " fields");
    }
    SpherePoint sp;
    sp.name = std::string(f.token[0]);
    for (int k = 0; k < 3; ++k) {
      if (!detail::parse_double(f.token[k + 1], sp.p[k])) {
        return Status(ErrorCode::ParseError, at + "bad number " + quote_token(f.token[k + 1]));
      }
    }
    if (!sp.p.allFinite()) {
      return Status(ErrorCode::InvalidInput, at + "point " + quote_token(sp.name) + " is not finite");
    }
    const double norm = sp.p.stableNorm();  // finite for every finite point
    if (norm == 0) return Status(ErrorCode::InvalidInput, at + "point " + quote_token(sp.name) + " has zero length");
    if (require_unit && std::abs(norm - 1) > kRequireUnitTolerance) {
      return Status(ErrorCode::InvalidInput, at + "point " + quote_token(sp.name) + " has length " +
                                                 length_text(norm) + ", not 1");
    }
    if (std::abs(norm - 1) > kUnitRoundoff) sp.p = detail::unit_vector(sp.p);
    if (auto it = name_line.find(sp.name); it != name_line.end()) {
      return Status(ErrorCode::InvalidInput, at + "duplicate point name " + quote_token(sp.name) + " (first on line " +
                                                 std::to_string(it->second) + ")");
    }
    name_line.emplace(sp.name, lines.number());
    points.push_back(std::move(sp));
  }
  return points;
}

}  // namespace detail

Result<std::vector<SpherePoint>> read_sphere_points(const std::string& path, bool require_unit) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  return detail::parse_sphere_points(path, bytes, require_unit);
}

namespace detail {

Result<std::vector<LandmarkTarget>> parse_landmark_targets(const std::string& path, std::string_view bytes,
                                                           int num_vertices) {
  detail::LineReader lines(bytes);
  std::vector<LandmarkTarget> targets;
  std::map<std::string, std::uint64_t, std::less<>> name_line;  // name -> line of first use
  std::map<int, std::uint64_t> vertex_line;                     // vertex -> line of first use
  std::string_view line;
  while (lines.next(line)) {
    const std::string at = path + ":" + std::to_string(lines.number()) + ": ";
    const Fields f = split_fields(detail::strip_comment(line));
    if (f.count == 0) continue;
    if (f.count != 5) {
      return Status(ErrorCode::ParseError,
                    at + "expected 'name vertex_index x y z', got " + std::to_string(f.count) + " fields");
    }
    LandmarkTarget t;
    t.name = std::string(f.token[0]);
    std::int64_t index = 0;
    if (!detail::parse_int(f.token[1], index)) {
      return Status(ErrorCode::ParseError, at + "vertex index " + quote_token(f.token[1]) + " is not an integer");
    }
    for (int k = 0; k < 3; ++k) {
      if (!detail::parse_double(f.token[k + 2], t.p[k])) {
        return Status(ErrorCode::ParseError, at + "bad number " + quote_token(f.token[k + 2]));
      }
    }
    if (index < 0) return Status(ErrorCode::InvalidInput, at + "negative vertex index " + std::to_string(index));
    if ((num_vertices >= 0 && index >= num_vertices) || index > std::numeric_limits<int>::max()) {
      return Status(ErrorCode::InvalidInput, at + "vertex index " + std::to_string(index) + " out of range (" +
                                                 (num_vertices >= 0 ? std::to_string(num_vertices) : "int") +
                                                 (num_vertices >= 0 ? " vertices)" : " range)"));
    }
    t.vertex = static_cast<int>(index);
    if (!t.p.allFinite()) {
      return Status(ErrorCode::InvalidInput, at + "target " + quote_token(t.name) + " is not finite");
    }
    const double norm = t.p.stableNorm();  // finite for every finite point
    if (std::abs(norm - 1) > kTargetUnitTolerance) {
      return Status(ErrorCode::InvalidInput, at + "target " + quote_token(t.name) + " has length " +
                                                 length_text(norm) + ", not 1 (targets are points on the unit sphere)");
    }
    t.p /= norm;  // in [1 - 1e-3, 1 + 1e-3]: no overflow or underflow
    if (auto it = name_line.find(t.name); it != name_line.end()) {
      return Status(ErrorCode::InvalidInput, at + "duplicate target name " + quote_token(t.name) + " (first on line " +
                                                 std::to_string(it->second) + ")");
    }
    if (auto it = vertex_line.find(t.vertex); it != vertex_line.end()) {
      return Status(ErrorCode::InvalidInput, at + "target " + quote_token(t.name) + " uses vertex " +
                                                 std::to_string(t.vertex) + ", already targeted on line " +
                                                 std::to_string(it->second));
    }
    name_line.emplace(t.name, lines.number());
    vertex_line.emplace(t.vertex, lines.number());
    targets.push_back(std::move(t));
  }
  return targets;
}

}  // namespace detail

Result<std::vector<LandmarkTarget>> read_landmark_targets(const std::string& path, int num_vertices) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  return detail::parse_landmark_targets(path, bytes, num_vertices);
}

Status write_sphere_points(const std::string& path, const std::vector<SpherePoint>& points) {
  std::string out = "# sphere points: name x y z\n";
  for (const SpherePoint& sp : points) {
    if (!writable_name(sp.name)) return bad_name(path, sp.name);
    out += sp.name;
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      detail::append_double(out, sp.p[k]);  // shortest exact form (17 significant digits at most)
    }
    out += '\n';
  }
  return write_file_atomic(path, out);
}

}  // namespace spherekit::formats
