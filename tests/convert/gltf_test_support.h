// Test helpers for the glTF writers: inputs (a blob's geometry image), an independent reader of
// .glb files (nlohmann::json + Google's Draco decoder called directly, not the library's decode),
// and the npm validators (Khronos gltf-validator + draco3d), installed on first use by
// scripts/setup_npm_tools.sh.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/geometry_image.h"

namespace spherekit::test {

/// A star-shaped random blob (random_blob(level, seed)) resampled through its radial sphere map
/// into a size x size geometry image.
GeometryImage blob_geometry_image(int size, int level = 3, std::uint64_t seed = 7);

// Fixtures shared by the glTF tests, so that the validator test checks the very files the
// other tests write.

/// The image the level-of-detail tests use: blob_geometry_image(65).
GeometryImage lod_test_image();
/// Their options: 3 levels (65, 33, 17), an error budget of 1e-4 RMS (the blob is ~2 across).
convert::GltfLodOptions lod_test_options();

/// A mesh with holes (sphere_with_holes(2, 3): holes a vertex's ring of a level-2 icosphere
/// wide, several texels even at 17 x 17), its radial sphere map, and the fitted images of
/// `levels` levels of detail from `size` down (lod_geometry_images; levels[0] the finest).
struct HoledLodImages {
  TriMesh mesh;
  RowMat3d S;
  std::vector<GeometryImage> levels;
};
HoledLodImages holed_lod_images(int size, int levels);
/// A collection of `members` blobs (seeds 7, 8, ...) as geometry-image primitives of one
/// connectivity.
std::vector<convert::GltfMesh> collection_test_meshes(int size, int members = 3);

/// Writes a star-shaped blob (random_blob(3, 21)) and its radial sphere map as dir/blob.obj and
/// dir/blob.sphere.obj (the inputs of the command-line tests).
void write_blob_inputs(const std::string& dir);

/// A parsed .glb: the JSON chunk and the BIN chunk.
struct GlbFile {
  nlohmann::json json;
  std::string bin;
};

/// Parses a .glb (header, JSON chunk, optional BIN chunk), REQUIRE-ing a well-formed layout.
GlbFile parse_glb(const std::string& bytes);
/// The bytes of bufferView `view`.
std::string buffer_view_bytes(const GlbFile& glb, int view);

/// One Draco primitive decoded with draco::Decoder, by the unique ids in its extension.
struct DecodedPrimitive {
  int mesh = 0, primitive = 0;
  Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> V, N;
  Eigen::Matrix<float, Eigen::Dynamic, 2, Eigen::RowMajor> UV;
  Eigen::Matrix<std::uint32_t, Eigen::Dynamic, 3, Eigen::RowMajor> F;
};

/// Decodes every KHR_draco_mesh_compression primitive of `glb` and CHECKs it against its
/// accessors: every primitive attribute is in the extension and vice versa, the unique ids exist,
/// accessor counts = decoded points (indices: 3 x decoded faces), FLOAT / VEC3 / VEC2 types, no
/// bufferView on compressed accessors, index type UNSIGNED_SHORT iff points <= 65535, and
/// POSITION min/max equal to the decoded bounds exactly.
std::vector<DecodedPrimitive> decode_and_check_draco(const GlbFile& glb);

/// The npm validators: where they are, or why they are not.
struct NpmTools {
  bool available = false;
  std::string node_dir;  ///< folder holding node_modules/{gltf-validator,draco3d}
  std::string why;       ///< when not available: the set-up script's message
};
/// Runs scripts/setup_npm_tools.sh (idempotent; once per process) into $SPHEREKIT_NPM_DIR, else
/// ~/.cache/spherekit/npm-tools, else <build>/npm-tools.
const NpmTools& npm_tools();

/// Runs tests/convert/validate_gltf.mjs on `files`: for each, the validator's counts and
/// messages and the draco3d decode check, as JSON ({"files": [{file, errors, warnings, infos,
/// hints, messages[], draco_primitives, draco_problems[]}]}). REQUIREs that node ran.
nlohmann::json run_npm_validators(const NpmTools& tools, const std::vector<std::string>& files);

}  // namespace spherekit::test
