// The landmarks job: read, propose, write the feature files all-or-nothing.
#include "spherekit/pipeline/landmarks.h"

#include <chrono>
#include <filesystem>
#include <regex>

#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"

namespace spherekit::pipeline {

std::string landmark_file_for(const std::string& mesh, const std::string& output_dir) {
  const std::filesystem::path p(mesh);
  const std::filesystem::path dir = output_dir.empty() ? p.parent_path() : std::filesystem::path(output_dir);
  return (dir / (p.stem().string() + ".lm.txt")).string();
}

Result<LandmarksResult> propose_landmark_files(const LandmarksJob& job, const ProgressFn& progress) {
  if (job.meshes.empty()) return Result<LandmarksResult>(ErrorCode::InvalidArgument, "landmarks: no meshes given");
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<TriMesh> meshes;
  for (const auto& path : job.meshes) {
    auto m = formats::read_mesh(path);
    if (!m.ok()) return m.status();
    meshes.push_back(std::move(*m));
  }
  auto p = propose_landmarks(meshes, job.options, progress);
  if (!p.ok()) {
    // The library names members by index ("mesh 2: ..."); the user knows them by file.
    std::smatch sm;
    const std::string msg = p.status().message();
    if (std::regex_search(msg, sm, std::regex("^mesh ([0-9]+): ")) && std::stoul(sm[1]) < job.meshes.size())
      return Status(p.status().code(), job.meshes[std::stoul(sm[1])] + ": " + sm.suffix().str());
    return p.status();
  }
  LandmarksResult r;
  r.proposal = std::move(*p);
  for (const auto& path : job.meshes) r.files.push_back(landmark_file_for(path, job.output_dir));
  if (job.write) {
    if (!job.output_dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(job.output_dir, ec);
      if (ec) return Status(ErrorCode::IoError, job.output_dir + ": cannot create the folder (" + ec.message() + ")");
    }
    for (std::size_t i = 0; i < r.files.size(); ++i)
      if (Status s = formats::write_landmarks(r.files[i], r.proposal.landmarks[i]); !s.ok()) return s;
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

Json to_json(const LandmarksJob& job, const LandmarksResult& r) {
  const ProposeLandmarksResult& p = r.proposal;
  Json j;
  j["reference"] = job.meshes.at(static_cast<std::size_t>(p.reference));
  j["names"] = p.names;
  j["extremities"] = p.extremities;
  j["unstable_dropped"] = p.unstable_dropped;
  j["mismatch_dropped"] = p.mismatch_dropped;
  j["fine_matched"] = p.fine_matched;
  j["rim_matched"] = p.rim_matched;
  j["rim_outliers_dropped"] = p.rim_outliers_dropped;
  j["options"] = {{"agd_sources", job.options.agd_sources},
                  {"max_extremities", job.options.max_extremities},
                  {"extremity_radius", job.options.extremity_radius},
                  {"tip_drop", job.options.tip_drop},
                  {"fine_radius", job.options.fine_radius},
                  {"rim_points", job.options.rim_points},
                  {"extra_points", job.options.extra_points},
                  {"sphere_orientation", job.options.sphere_orientation},
                  {"sphere_effort", job.options.sphere_effort}};
  Json members = Json::array();
  for (std::size_t i = 0; i < job.meshes.size(); ++i) {
    const LandmarkMemberMatch& m = p.members[i];
    Json mj = {{"file", job.meshes[i]},
               {"landmarks_file", r.files[i]},
               {"extremities_found", p.extremities_found[i]},
               {"cost", m.cost},
               {"mirrored_cost", number_or_null(m.mirrored_cost < 0 ? std::nan("") : m.mirrored_cost)},
               {"orientation_agreement", m.orientation_agreement},
               {"mirror_resolved", m.mirror_resolved},
               {"mirrored", m.mirrored},
               {"mirror_ambiguous", m.mirror_ambiguous},
               {"sphere_checked", m.sphere_checked},
               {"sphere_agreement", number_or_null(m.sphere_checked ? m.sphere_agreement : std::nan(""))},
               {"sphere_runner_up", number_or_null(m.sphere_checked && m.sphere_runner_up > -2 ? m.sphere_runner_up : std::nan(""))}};
    Json lms = Json::array();
    for (std::size_t k = 0; k < p.landmarks[i].size(); ++k)
      lms.push_back({{"name", p.landmarks[i][k].name},
                     {"vertex", p.landmarks[i][k].vertex},
                     {"confidence", p.confidence[i][k]}});
    mj["landmarks"] = std::move(lms);
    members.push_back(std::move(mj));
  }
  j["members"] = std::move(members);
  j["seconds"] = r.seconds;
  return j;
}

}  // namespace spherekit::pipeline
