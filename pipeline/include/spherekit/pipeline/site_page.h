// The results page of the main job: OUT/index.html showing the glTF levels of detail in a
// three.js viewer, the morph glTF files with a slider, the PNG images and plots, and tables.
//
// The page must work opened from disk (file://) as well as served on localhost. Chromium
// refuses fetch/XHR and ES modules on file:// pages, so the page uses classic <script>s only
// and fetches nothing: every .glb is written base64-encoded into a small script of its own
// (OUT/site/glb/*.js, loaded when its model is shown), the site description into
// OUT/site/data.js, and the Draco primitives are decoded on the page's thread by Google's
// JavaScript Draco decoder instead of three.js's DRACOLoader (which fetches its decoder and
// runs it in a worker). Images, plots and tables are plain HTML, visible without JavaScript.
// The landmark editor's meshes are scripts too (OUT/site/mesh/*.js), and its downloads are
// made in the page (Blob URLs), so they also work from disk.
//
// three.js and the decoder come from npm (scripts/setup_viewer.sh builds them into
// ~/.cache/spherekit/viewer/dist); they are copied into OUT/site/lib. When they are not
// installed the page is written without the 3-D views and says why, and so does a warning.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::pipeline {

// Reports keep their key order.
using Json = nlohmann::ordered_json;

/// Writes `out_dir`/index.html and the files it uses (`out_dir`/site/...), each atomically.
///
/// `site` describes what to show. Every key is optional; every path is relative to `out_dir`
/// (files outside it, absolute paths and missing files are skipped with a warning):
///
///     {
///       "title": "SphereKit results",
///       "description": "one paragraph of plain text under the title",
///       "models": [{"name": "sample_a",
///                   "lods": ["assets/a_lod0.glb", "assets/a_lod1.glb"],   // LOD0 = finest
///                   "images": [{"label": "geometry image normals", "png": "assets/a_gim.png"}]}],
///       "morph": {"glb": "apps/morph.glb", "label": "a to b", "mode": "sequence"},
///       "plots": [{"label": "PCA error", "png": "apps/pca_error.png"}],
///       "tables": [{"label": "maps", "columns": ["mesh", "efficiency"], "rows": [["a", 0.71]]}],
///       "landmarks": {"members": [{"name": "a", "mesh": "/in/a.obj", "features": "/in/a.lm.txt",
///                                  "source": "given: /in/a.lm.txt"}]},
///       "viewer_dir": "/abs/folder"     // where scripts/setup_viewer.sh installed the viewer
///     }
///
/// - "morph" is one object or an array of them. "mode" "sequence" (default: the targets are
///   successive frames, one slider runs through them) or "weights" (independent targets such
///   as principal components: one slider per target, weight -3..3).
/// - Table cells are strings, numbers (6 significant digits), booleans or null (empty).
/// - "landmarks" (issue 25): the landmark editor. Its "mesh" and "features" are input files
///   (any path, not only inside `out_dir`): each mesh is read as formats::read_mesh reads it
///   and written for the page into `out_dir`/site/mesh/*.js (positions as float32, the
///   original vertex numbering), so that a vertex picked on the page is the index every
///   `.lm.txt` reader expects. "features" empty or absent: no landmarks yet. A mesh that
///   cannot be read is skipped with a warning; a feature file that does not read against its
///   mesh shows the member without landmarks and says why.
///   Optional per member: "confidence" {name: 0..1} and "note" (a proposal's measures and
///   left/right flag, shown beside the landmarks).
/// - "viewer_dir" is normally absent: then $SPHEREKIT_VIEWER_DIR, else
///   $HOME/.cache/spherekit/viewer; the viewer files are its dist/ folder.
///
/// @param warnings when not null, receives one line per problem the page shows instead of
///        content: no viewer installed (no 3-D view), a missing or unusable file. The library
///        prints nothing; the caller may print these.
/// @return IoError when a file cannot be written or a listed glTF file cannot be read;
///         InvalidArgument when `site` is not a JSON object.
Status write_site_page(const std::string& out_dir, const Json& site, std::vector<std::string>* warnings = nullptr);

}  // namespace spherekit::pipeline
