// The results page's landmark editor data (issue 25): per member the mesh exactly as
// formats::read_mesh reads it (the vertex numbering every `.lm.txt` reader uses, so that a
// vertex picked on the page is the index `spherekit check --landmarks` and the collection
// jobs expect) and the landmarks of its feature file. Internal to site_page.cpp.
#pragma once

#include <string>

#include "spherekit/pipeline/site_page.h"

namespace spherekit::pipeline::detail {

struct LandmarkMemberData {
  /// For data.js: name, file (the download's name), source, offset, vertices, triangles,
  /// landmarks [{name, vertex}], "confidence" and "note" when given, and "error" when the
  /// feature file could not be read.
  Json entry;
  /// The mesh for the page: little-endian u32 #V, u32 #F, then #V x 3 float32 positions
  /// minus `offset` (float32 keeps its precision near the origin, whatever the mesh's
  /// placement), then #F x 3 u32 vertex indices.
  std::string payload;
};

/// One entry of the description's "landmarks" list: {"name", "mesh" (a mesh file, any path),
/// "features" (its `.lm.txt`, any path; empty or absent: none yet), "source" (plain text: where
/// the landmarks came from), optional "confidence" {name: 0..1} and "note" (a proposal's
/// measures and flag, shown beside the landmarks)}. Errors: the mesh cannot be read (the page skips the member).
/// A feature file that does not read against the mesh is not an error: the member is shown
/// without landmarks and the entry's "error" says why.
Result<LandmarkMemberData> landmark_member_data(const Json& member);

}  // namespace spherekit::pipeline::detail
