// The main job (`spherekit run`), composed in memory from the other jobs: every mesh checked,
// mapped, measured and converted; a collection (the samples, or meshes with feature files)
// mapped consistently, converted and used by the applications; report.json and the results
// page. A mesh that fails is recorded and skipped; the others still run.
#pragma once

#include <string>
#include <vector>

#include "spherekit/pipeline/apps.h"
#include "spherekit/pipeline/collection.h"
#include "spherekit/pipeline/convert.h"
#include "spherekit/sphere_param.h"

namespace spherekit::pipeline {

/// The geometry-image size of the main job, per mesh and per collection member, and its PSNR
/// sample count per direction: lower than convert's default so the job stays fast.
inline constexpr int kRunImageSize = 129;
inline constexpr int kRunPsnrSamples = 100000;

struct MainJob {
  std::vector<std::string> meshes;  ///< empty: the built-in samples (written to OUT/input first)
  std::string output = "spherekit-out";
  SphereParamOptions options;
};

/// What the job did, told as it goes (in this order), for a caller that shows it; the job
/// itself prints nothing. Every method has an empty default.
class MainJobObserver {
 public:
  virtual ~MainJobObserver() = default;
  /// The progress (and cancel) callback for the next stage; `prefix` names it (a mesh).
  virtual ProgressFn progress(const std::string& prefix);
  /// Polled between files of staged folders; false cancels.
  virtual bool keep_going();
  virtual void samples_written(const std::string& dir);
  /// A mesh (or the collection) failed with `error`; the job goes on without it.
  virtual void failed(const Status& error);
  /// A stage starts ("Converting the collection (as 'spherekit convert --collection'):").
  virtual void heading(const std::string& text);
  /// Something the user should know that is not an error (the CLI prints it on stderr), e.g.
  /// that the meshes came without feature files and landmarks were proposed for them.
  virtual void note(const std::string& text);
  virtual void collection_made(const MakeCollectionResult& result, const std::string& output);
  virtual void correspondence(const Json& measured);
  virtual void assets_converted(const ConvertCollectionResult& result);
  virtual void transferred(const TransferResult& result, const TransferJob& job);
  virtual void round_trip(const std::string& a, const std::string& b, double mean_error);
  virtual void morphed(const MorphResult& result, const MorphJob& job);
  virtual void pca_done(const PcaResult& result, const PcaJob& job);
};

struct MainJobResult {
  std::string output_dir;  ///< absolute
  Json report;             ///< OUT/report.json as written
  std::vector<std::string> table_columns;
  std::vector<std::vector<std::string>> table;  ///< one row per mesh (the summary)
  int meshes = 0, failed = 0;
  bool collection_done = false;
  std::vector<Status> errors;          ///< every failure, in order (a mesh's, the collection's)
  std::vector<std::string> warnings;   ///< the results page's (no viewer installed, ...)
  double wall_seconds = 0;
};

/// Runs the main job into `job.output`. Errors (the job stops): IoError (the folder, the page,
/// the report), Cancelled (a stage's progress callback returned false); a failing mesh or
/// collection stage is in `errors` instead.
Result<MainJobResult> run_main_job(const MainJob& job, MainJobObserver& observer);

}  // namespace spherekit::pipeline
