// `spherekit correspond`: surface points of one collection member mapped to another through
// the common sphere, and the measured error of that map against ground truth (the Princeton
// protocol of shared/tools/evalcorr.py).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <unordered_map>
#include <string>
#include <vector>

#include "cli_common.h"
#include "collection.h"
#include "commands.h"
#include "spherekit/correspondence.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/sphere_map_io.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

struct CorrespondArgs {
  std::string dir, a, b;
  std::string points;
  std::string output;
  std::vector<std::string> corr, gt;
  int samples = 0;
  bool json = false;
};

struct Mapped {
  LoadedMesh mesh;
  SphereMap map;
};

Result<Mapped> load_mapped_member(const CollectionInfo& c, const std::string& path) {
  const int i = find_member(c, path);
  if (i < 0)
    return Status(ErrorCode::InvalidInput, path + ": not a member of the collection " + c.dir +
                                               " (add it with 'spherekit add')");
  SPHEREKIT_ASSIGN_OR_RETURN(LoadedMesh m, load_mesh(path));
  const Json& e = c.manifest["meshes"][static_cast<size_t>(i)];
  // The mesh must be the one that was mapped: say so when its vertex count shows it is not
  // (the map reader below could only report that two counts differ).
  if (e.contains("vertices") && e["vertices"].get<long long>() != static_cast<long long>(m.mesh.V.rows()))
    return Status(ErrorCode::InvalidInput,
                  strprintf("%s: has %lld vertices, but member '%s' of %s was mapped with %lld (not the mesh of "
                            "the collection?)",
                            path.c_str(), static_cast<long long>(m.mesh.V.rows()), e["name"].get<std::string>().c_str(),
                            (fs::path(c.dir) / kCollectionManifest).string().c_str(), e["vertices"].get<long long>()));
  const std::string map_path = (fs::path(c.dir) / e["map"].get<std::string>()).string();
  std::error_code ec;
  if (!fs::is_regular_file(map_path, ec))
    return Status(ErrorCode::IoError, map_path + ": missing (the map of member '" + e["name"].get<std::string>() +
                                          "' in " + (fs::path(c.dir) / kCollectionManifest).string() + ")");
  auto map = formats::read_sphere_map(map_path, m.mesh);
  if (!map.ok()) return map.status();
  Mapped out;
  out.mesh = std::move(m);
  out.map = std::move(map).value();
  return out;
}

// Whitespace-separated integers of a file (a .corr.txt or .gt.txt file).
Result<std::vector<int>> read_integers(const std::string& path) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, formats::read_file(path));
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

// `x y z` lines ('#' comments, blank lines allowed).
Result<std::vector<Eigen::Vector3d>> read_points(const std::string& path) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, formats::read_file(path));
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

int run_correspond(const CorrespondArgs& a) {
  if (a.points.empty() && a.corr.empty() && a.gt.empty())
    return print_error(Status(ErrorCode::InvalidArgument, "nothing to do: give --points, --corr or --gt"));
  if (Status s = require_output_folders({a.output}); !s.ok()) return print_error(s);
  auto col = read_collection(a.dir);
  if (!col.ok()) return print_error(col.status());
  auto A = load_mapped_member(col.value(), a.a);
  if (!A.ok()) return print_error(A.status());
  auto B = load_mapped_member(col.value(), a.b);
  if (!B.ok()) return print_error(B.status());
  const TriMesh& ma = A->mesh.mesh;
  const TriMesh& mb = B->mesh.mesh;

  if (!a.points.empty()) {
    auto pts = read_points(a.points);
    if (!pts.ok()) return print_error(pts.status());
    const ClosestPointLocator closest(ma);
    std::vector<SurfacePoint> on_a;
    for (const auto& p : pts.value()) on_a.push_back(closest.closest(p));
    auto moved = transfer_points(ma, A->map.S, on_a, mb, B->map.S);
    if (!moved.ok()) return print_error(moved.status());
    std::string text;
    int holes = 0;
    for (const TransferredPoint& t : moved.value()) {
      const Eigen::Vector3d x = surface_position(mb, t.point);
      text += strprintf("%.9g %.9g %.9g\n", x.x(), x.y(), x.z());
      holes += t.in_hole;
    }
    if (a.output.empty()) {
      std::fputs(text.c_str(), stdout);
    } else if (Status s = formats::write_file_atomic(a.output, text); !s.ok()) {
      return print_error(s);
    }
    if (holes) std::fprintf(stderr, "note: %d points fell into holes of %s (nearest surface point given)\n", holes, a.b.c_str());
  }

  if (!a.corr.empty() || !a.gt.empty()) {
    const bool corr = !a.corr.empty();
    const auto& files = corr ? a.corr : a.gt;
    auto la = read_integers(files[0]);
    if (!la.ok()) return print_error(la.status());
    auto lb = read_integers(files[1]);
    if (!lb.ok()) return print_error(lb.status());
    std::vector<std::pair<int, int>> pairs;
    if (corr) {
      if (la->size() != lb->size())
        return print_error(Status(ErrorCode::InvalidInput, files[0] + " and " + files[1] + " differ in length"));
      for (size_t i = 0; i < la->size(); ++i) pairs.push_back({(*la)[i], (*lb)[i]});
    } else {
      // Template ids: vertex i of A pairs with the first vertex of B with the same id.
      std::unordered_map<int, int> first;
      for (size_t j = 0; j < lb->size(); ++j) first.emplace((*lb)[j], static_cast<int>(j));
      for (size_t i = 0; i < la->size(); ++i)
        if (auto it = first.find((*la)[i]); (*la)[i] >= 0 && it != first.end()) pairs.push_back({static_cast<int>(i), it->second});
    }
    for (const auto& [x, y] : pairs)
      if (x < 0 || x >= ma.V.rows() || y < 0 || y >= mb.V.rows())
        return print_error(Status(ErrorCode::InvalidInput, strprintf("%s: vertex pair (%d, %d) out of range", files[0].c_str(), x, y)));
    if (a.samples > 0 && static_cast<int>(pairs.size()) > a.samples) {
      // Evenly spaced subset: deterministic.
      std::vector<std::pair<int, int>> sub;
      for (int i = 0; i < a.samples; ++i) sub.push_back(pairs[static_cast<size_t>(i) * pairs.size() / a.samples]);
      pairs.swap(sub);
    }
    std::vector<SurfacePoint> on_a;
    std::vector<int> truth;
    for (const auto& [x, y] : pairs) {
      on_a.push_back(vertex_surface_point(ma, x));
      truth.push_back(y);
    }
    auto moved = transfer_points(ma, A->map.S, on_a, mb, B->map.S);
    if (!moved.ok()) return print_error(moved.status());
    std::vector<SurfacePoint> predicted;
    for (const auto& t : moved.value()) predicted.push_back(t.point);
    auto err = correspondence_error(mb, predicted, truth);
    if (!err.ok()) return print_error(err.status());
    const CorrespondenceError& e = err.value();
    Json j{{"pairs", e.pairs},          {"mean", e.mean},
           {"median", e.median},        {"p90", e.p90},
           {"max", e.max},              {"under_0.025", e.under_0025},
           {"under_0.05", e.under_005}, {"under_0.1", e.under_01}};
    if (a.json)
      std::printf("%s\n", j.dump().c_str());
    else
      std::printf("%s -> %s: %d pairs, mean error %.4f, median %.4f, p90 %.4f, max %.4f; under 0.05: %.1f%%, under 0.1: %.1f%%\n",
                  a.a.c_str(), a.b.c_str(), e.pairs, e.mean, e.median, e.p90, e.max, 100 * e.under_005, 100 * e.under_01);
  }
  return 0;
}

}  // namespace

void register_correspond(CLI::App& app) {
  auto args = std::make_shared<CorrespondArgs>();
  CLI::App* cmd = add_command(
      app, "correspond", "Map surface points of one collection member to another through the sphere",
      "A and B are member meshes of the collection DIR ('spherekit consistent'). Each point of\n"
      "--points (`x y z` lines, snapped to the closest point of A's surface) goes through A's\n"
      "sphere map to the sphere and back through B's map onto B; the points on B are printed\n"
      "(`x y z` lines) or written to -o. With --corr A.corr.txt B.corr.txt (line k of both files:\n"
      "corresponding vertices) or --gt A.gt.txt B.gt.txt (template id per vertex), the map's\n"
      "error is measured like shared/tools/evalcorr.py: geodesic distance on B to the true\n"
      "partner / sqrt(area B), Dijkstra on B's edges plus the straight step into the triangle.",
      "  spherekit correspond cats cat0.obj cat2.obj --points picks.txt -o picks_on_cat2.txt\n"
      "  spherekit correspond cats cat0.obj cat2.obj --corr cat0.corr.txt cat2.corr.txt --json");
  cmd->add_option("DIR", args->dir, "collection folder")->required();
  cmd->add_option("A", args->a, "source mesh (a member)")->required();
  cmd->add_option("B", args->b, "target mesh (a member)")->required();
  cmd->add_option("--points", args->points, "points on A (`x y z` lines)");
  cmd->add_option("-o,--output", args->output, "write the points on B here (default: stdout)");
  cmd->add_option("--corr", args->corr, "ground truth: A.corr.txt B.corr.txt")->expected(2);
  cmd->add_option("--gt", args->gt, "ground truth: A.gt.txt B.gt.txt")->expected(2);
  cmd->add_option("--samples", args->samples, "measure at most N evenly spaced pairs (default: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", args->json, "print the error measures as one JSON line (evalcorr.py's keys)");
  cmd->callback([args] { set_exit_code(run_correspond(*args)); });
}

}  // namespace spherekit::cli
