// The small text formats (text_formats.h).
#include "spherekit/formats/text_formats.h"

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "spherekit/formats/atomic_file.h"

namespace spherekit::formats {

Result<std::vector<int>> read_vertex_indices(const std::string& path) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, read_file(path));
  std::vector<int> out;
  std::istringstream in(text);
  std::string tok;
  int line = 1;
  for (size_t pos = 0; pos < text.size();) {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) line += text[pos++] == '\n';
    if (pos >= text.size()) break;
    size_t end = pos;
    while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end]))) ++end;
    tok = text.substr(pos, end - pos);
    char* stop = nullptr;
    const long v = std::strtol(tok.c_str(), &stop, 10);
    if (*stop != '\0' || v < -1 || v > 2000000000)
      return Status(ErrorCode::ParseError, path + ":" + std::to_string(line) + ": '" + tok + "' is not a vertex index");
    out.push_back(static_cast<int>(v));
    pos = end;
  }
  return out;
}

Result<std::vector<Eigen::Vector3d>> read_points(const std::string& path) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, read_file(path));
  std::vector<Eigen::Vector3d> out;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (auto h = line.find('#'); h != std::string::npos) line.resize(h);
    std::istringstream ls(line);
    Eigen::Vector3d p;
    std::string extra;
    if (!(ls >> std::ws).good() && ls.eof()) continue;
    if (!(ls >> p.x() >> p.y() >> p.z()) || (ls >> extra))
      return Status(ErrorCode::ParseError, path + ":" + std::to_string(n) + ": expected 'x y z'");
    if (!p.allFinite()) return Status(ErrorCode::ParseError, path + ":" + std::to_string(n) + ": not a finite point");
    out.push_back(p);
  }
  if (out.empty()) return Status(ErrorCode::InvalidInput, path + ": no points");
  return out;
}

std::string path_network_obj_text(const std::vector<std::vector<Eigen::Vector3d>>& polylines,
                                  const std::vector<std::array<int, 2>>& arcs,
                                  const std::vector<Eigen::Vector3d>& arc_targets) {
  std::string out = "# spherekit path network: mesh paths (group paths), sphere arcs (group arcs)\n";
  char text[96];
  auto vertex = [&](const Eigen::Vector3d& p) {
    std::snprintf(text, sizeof text, "v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
    out += text;
  };
  auto line = [&](int first, int count) {
    out += "l";
    for (int i = 0; i < count; ++i) {
      out += ' ';
      out += std::to_string(first + i);
    }
    out += "\n";
  };
  int next = 1;
  out += "g paths\n";
  for (const auto& path : polylines) {
    for (const auto& p : path) vertex(p);
    line(next, static_cast<int>(path.size()));
    next += static_cast<int>(path.size());
  }
  out += "g arcs\n";
  constexpr int kSamples = 16;
  for (const auto& arc : arcs) {
    const Eigen::Vector3d& a = arc_targets[static_cast<size_t>(arc[0])];
    const Eigen::Vector3d& b = arc_targets[static_cast<size_t>(arc[1])];
    for (int i = 0; i <= kSamples; ++i) vertex((a + (b - a) * (static_cast<double>(i) / kSamples)).normalized());
    line(next, kSamples + 1);
    next += kSamples + 1;
  }
  return out;
}

}  // namespace spherekit::formats
