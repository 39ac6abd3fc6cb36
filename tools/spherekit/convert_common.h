// What `spherekit convert` shares between its single-mesh form (cmd_convert.cpp) and its
// collection form (convert_collection.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cli_common.h"
#include "spherekit/convert/gltf_draco.h"
#include "spherekit/geometry_image.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"

namespace spherekit::cli {

struct ConvertArgs {
  std::string mesh;
  std::string sphere;
  std::string collection;  // --collection DIR: convert every member into the folder -o
  std::string output;
  std::string remesh;
  std::string report;
  int size = 257;
  std::string positions = "fit";  // texel positions: fit (least squares) or sampled
  int psnr_samples = RemeshErrorOptions{}.samples;
  int lods = 0;  // glTF levels of detail (0: none)
  int cage = 0;  // Catmull-Clark cage: quads per cube-face edge (0: none)
  int cage_tile = 17;
  std::string displacement = "scalar";
  convert::QuantizationBudget budget;
  bool quiet = false;
};

/// The sampling options --positions asks for.
GeometryImageOptions geometry_image_options(const ConvertArgs& a);

/// Flags that are wrong whatever the input: checked before anything is read or written.
Status check_convert_flags(const ConvertArgs& a);

/// OUT.exr -> OUT (the glTF files are OUT_lod0.glb ... and OUT_lods.glb).
std::string gltf_prefix(const std::string& output);
std::uintmax_t file_bytes(const std::string& path);
Json number_or_null(double x);
/// PNG previews of a geometry image (convert/geometry_image_png.h), written atomically:
/// PREFIX_normals.png and PREFIX_positions.png. Returns the paths written.
Result<std::vector<std::string>> write_geometry_image_previews(const GeometryImage& image, const std::string& prefix);

/// What --cage produced, for the report and the summary.
struct CageOutput {
  std::string cage_path, displacement_path;
  int n = 0, tile = 0, control_points = 0, quads = 0, samples_in_holes = 0;
  std::string kind;
  double fit_rms = 0, max_displacement = 0, ray_residual = 0;
  long long stored_floats = 0;
  RemeshError limit_error, displaced_error;
  bool measured = false;
  double seconds = 0, psnr_seconds = 0;
};

/// Fits the cage, samples the displacement, writes PREFIX_cage.obj and PREFIX_disp.exr, and
/// measures the bare limit surface and the displaced surface against the mesh (hole spans
/// left out, as for the image).
Result<CageOutput> build_cage(const TriMesh& mesh, const RowMat3d& S, const ConvertArgs& a, const std::string& prefix,
                              const ProgressFn& progress);
/// The report's "cage" object (file names as given, or relative to `relative_to` if set).
Json cage_json(const CageOutput& c);

/// `convert --collection DIR -o OUTDIR`.
int run_convert_collection(const ConvertArgs& a);

}  // namespace spherekit::cli
