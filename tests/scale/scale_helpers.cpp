// Helpers of the scale tests (scale_helpers.h).
#include "scale_helpers.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/metrics.h"

extern char** environ;
namespace fs = std::filesystem;

namespace spherekit::test {

std::map<std::string, std::string> collection_files(const std::string& dir) {
  std::map<std::string, std::string> out;
  const std::string text = slurp(dir + "/collection.json");
  const nlohmann::json m = nlohmann::json::parse(text, nullptr, false);
  if (m.is_discarded() || !m.is_object() || !m.contains("meshes")) return out;
  out["collection.json"] = text;
  out["features.txt"] = slurp(dir + "/features.txt");
  for (const auto& e : m["meshes"]) {
    const std::string map = e.value("map", "");
    out[map] = fs::exists(dir + "/" + map) ? slurp(dir + "/" + map) : std::string("<missing>");
  }
  return out;
}

std::map<std::string, std::string> visible_files(const std::string& dir) {
  std::map<std::string, std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (!n.empty() && n[0] != '.' && e.is_regular_file()) out[n] = slurp(e.path().string());
  }
  return out;
}

int spawn_quiet(const std::vector<std::string>& argv) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

int wait_for(int pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
}

int collection_map_problems(const std::string& dir, std::string* first) {
  int problems = 0;
  auto note = [&](const std::string& what) {
    if (problems++ == 0 && first) *first = what;
  };
  const nlohmann::json m = nlohmann::json::parse(slurp(dir + "/collection.json"), nullptr, false);
  if (m.is_discarded() || !m.contains("meshes") || !m.contains("features")) {
    note(dir + "/collection.json: unreadable");
    return problems;
  }
  std::vector<Eigen::Vector3d> F;
  for (const auto& f : m["features"])
    F.emplace_back(f["location"][0].get<double>(), f["location"][1].get<double>(), f["location"][2].get<double>());
  for (const auto& e : m["meshes"]) {
    const std::string name = e["name"].get<std::string>();
    auto mesh = formats::read_mesh(e["source"].get<std::string>());
    if (!mesh.ok()) {
      note(name + ": " + mesh.status().message());
      continue;
    }
    auto map = formats::read_sphere_map(dir + "/" + e["map"].get<std::string>(), mesh.value());
    if (!map.ok()) {
      note(name + ": " + map.status().message());
      continue;
    }
    if (const int f = count_flipped_faces(mesh->F, map->S); f != 0) note(name + ": " + std::to_string(f) + " flipped faces");
    const auto& fv = e["feature_vertices"];
    for (size_t k = 0; k < fv.size() && k < F.size(); ++k) {
      const Eigen::Vector3d s = map->S.row(fv[k].get<int>()).transpose();
      if (std::atan2(s.cross(F[k]).norm(), s.dot(F[k])) > 1e-12) note(name + ": feature " + std::to_string(k) + " off F");
    }
  }
  return problems;
}

std::vector<std::string> hidden_siblings(const std::string& dir) {
  const fs::path d = fs::absolute(dir).lexically_normal();
  const std::string prefix = "." + d.filename().string() + ".";
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(d.parent_path(), ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(prefix, 0) == 0) out.push_back(n);
  }
  return out;
}

}  // namespace spherekit::test
