// `spherekit param` as a job: a mesh mapped bijectively onto the unit sphere, minimizing
// stretch (Praun & Hoppe 2003), or with features on given sphere points (the constrained
// stage of Asirvatham, Praun & Hoppe 2005). Only a bijection is ever written.
#pragma once

#include <optional>
#include <string>

#include "spherekit/constrained_param.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/pipeline/mesh_input.h"
#include "spherekit/progress.h"
#include "spherekit/sphere_param.h"

namespace spherekit::pipeline {

struct ParamJob {
  std::string mesh;          ///< genus 0, holes allowed
  std::string output;        ///< the sphere map (.obj)
  std::string features;      ///< constrained: feature vertices (`name vertex` lines) ...
  std::string targets;       ///< ... and their sphere points (`name x y z`); both or neither
  std::string dump_network;  ///< constrained: also write the path network here (.obj)
  SphereParamOptions options;
  ConstrainedParamOptions constrained;  ///< its `sphere` is replaced by `options`
};

struct ParamResult {
  ParamJob job;
  LoadedMesh input;
  std::optional<SphereParamResult> unconstrained;
  std::optional<ConstrainedParamResult> constrained;
  int features = 0;
  double write_seconds = 0, wall_seconds = 0;
};

/// Reads the mesh (refused unless param accepts it), maps it and writes the map. Errors name
/// the file: InvalidArgument (--features without --targets, --dump-network without them),
/// InvalidInput (a feature without a target or the reverse), SolverFailed (a map with flipped
/// faces: nothing written), Cancelled.
Result<ParamResult> map_mesh(const ParamJob& job, const ProgressFn& progress = {});

/// The report of `param --report`.
Json to_json(const ParamResult& result);

}  // namespace spherekit::pipeline
