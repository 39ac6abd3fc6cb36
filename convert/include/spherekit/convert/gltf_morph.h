// A collection of meshes with one connectivity as ONE glTF mesh with morph targets (glTF 2.0
// "Morph Targets"): the first member is the base primitive, every other member a target whose
// POSITION (and NORMAL) are displacements from the base, so a weight vector blends the
// members (weight 1 on target k-1 and 0 elsewhere shows member k). Consistent sphere maps give
// every member's geometry image the same texels and hence the same points and faces
// (gltf_mesh_from_geometry_image); this is what makes the members morphable.
//
// The encoding, and why uncompressed is the default. Morph targets are indexed by vertex: the
// i-th value of every target applies to the base's i-th vertex. Draco's edgebreaker reorders and
// may split vertices (ALGORITHM.md §7, gotcha 9), and KHR_draco_mesh_compression says nothing
// about targets, so
//  * Uncompressed (default): base and targets are plain float accessors in the members' own
//    point order; exact, and every glTF loader supports it.
//  * DracoSequential: the base primitive is Draco-compressed with *sequential* encoding, which
//    keeps the point and face order (verified after decoding: the encoder returns Internal if
//    not), and the targets stay uncompressed float accessors in that order. The displacements
//    are taken from the decoded (quantized) base, so base + target reproduces each member to
//    float precision; only the base carries quantization error. Smaller, but it relies on a
//    loader applying uncompressed targets to a decompressed base in point order.
#pragma once

#include <string>
#include <vector>

#include "spherekit/convert/gltf_draco.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert {

enum class MorphEncoding {
  Uncompressed,     ///< float accessors for base and targets (default)
  DracoSequential,  ///< base in a sequential Draco bitstream, targets float accessors
};

struct GltfMorphOptions {
  MorphEncoding encoding = MorphEncoding::Uncompressed;
  /// One name per member, recorded as mesh.extras.targetNames (the names of members 1..) and
  /// mesh.extras.spherekit.members; empty: "member0", "member1", ...
  std::vector<std::string> names;
  std::string name = "collection";  ///< mesh and node name
  GltfProvenance provenance;        ///< asset.extras.spherekit (sphere_map: the collection)
  /// > 0: adds an animation "morph" of this many seconds that shows the members in turn,
  /// member k (target k-1 at weight 1) at time k * seconds / (members - 1), the weights
  /// linearly interpolated in between (for members that are the frames of a morph sequence,
  /// morph.h). 0: no animation. Needs >= 2 members.
  double animation_seconds = 0;
  // DracoSequential only
  QuantizationBudget budget;        ///< quantization of the base (gltf_draco.h)
  double reference_rms_error = 0;   ///< error budget of the base's positions (<= 0: minimum bits)
  int compression_level = 7;        ///< Draco compression level 0..10
};

/// What was built.
struct GltfMorph {
  std::string glb;         ///< the .glb
  GltfMesh base;           ///< the base as stored (the decoded base for DracoSequential)
  int targets = 0;         ///< members - 1
  QuantizationChoice quantization;  ///< DracoSequential only
};

/// Builds one glTF with `members[0]` as the base and a morph target per further member.
/// Requirements: >= 1 member; every member passes check_gltf_mesh and has the base's point
/// count, faces, position_index, and the base's texture coordinates (targets cannot move them);
/// normals on all members or none. Errors: InvalidInput (naming the first offending member),
/// InvalidArgument (names not empty and not one per member), Internal (Draco or tinygltf
/// failed, or sequential encoding reordered points).
[[nodiscard]] Result<GltfMorph> build_gltf_morph_targets(const std::vector<GltfMesh>& members,
                                                         const GltfMorphOptions& options = {});

/// The same for plain triangle meshes (gltf_mesh_from_trimesh: per-vertex normals, no texture
/// coordinates). Every member needs the first's faces.
[[nodiscard]] Result<GltfMorph> build_gltf_morph_targets(const std::vector<TriMesh>& members,
                                                         const GltfMorphOptions& options = {});

}  // namespace spherekit::convert
