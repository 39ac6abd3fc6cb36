// The long help paragraphs and examples of the commands whose help is longer than their
// code (`spherekit CMD --help` prints them through add_command): kept here so each cmd_*.cpp
// reads as flags -> options -> one call -> print (issue 21).
#pragma once

namespace spherekit::cli::help {

// `spherekit convert` (single mesh and --collection).
inline constexpr const char* kConvert =
    "Resample a mesh through its sphere map (as written by `spherekit param`) into an N x N\n"
    "octahedral geometry image (N = 2^k+1): each texel's sphere point is located in the sphere\n"
    "map and the surface position and normal are interpolated there. Writes a float EXR\n"
    "(R,G,B = position, N.X,N.Y,N.Z = normal, face_id; ZIP; provenance in the header), and\n"
    "with --remesh the triangle mesh the image defines (holes of the mesh left open), and two\n"
    "PNG previews of the image,\n"
    "OUT_normals.png (normals as colours) and OUT_positions.png (positions in the bounding\n"
    "box as colours; texels in holes of the mesh at half brightness). Prints the remesh PSNR against the\n"
    "original (peak = bounding-box diagonal, symmetric RMS surface distance; for a mesh with\n"
    "holes without the remesh faces that have two or three texels in a hole); --report writes\n"
    "it with the timings as JSON. With --lods L it also writes L levels of detail (image sizes\n"
    "N, (N-1)/2+1, ..., each resampled and fitted at its own size; faces spanning holes of the\n"
    "mesh left out) as Draco-compressed glTF (POSITION, NORMAL, TEXCOORD_0 = texel centres\n"
    "of the image): OUT_lod0.glb ... one per level, and OUT_lods.glb with all of them (MSFT_lod,\n"
    "level 0 shown by viewers without it), OUT being -o without its extension. Position bits:\n"
    "the fewest >= --min-position-bits whose quantization error is at most a tenth of the\n"
    "measured remesh error (recorded in OUT_lods.glb's extras and in the report, with each\n"
    "level's size and the PSNR of its decoded geometry; a level's own file carries only its\n"
    "level and texture size). The mesh must be one `param` accepts and the\n"
    "map a bijection (no face flipped by the exact predicate).\n"
    "With --cage N it also fits a Catmull-Clark base cage defined on the sphere domain (the\n"
    "cube, N x N quads per face, 6N^2 quads, the same for every mesh: in a consistent\n"
    "collection cage vertex k is the same place on every member) whose limit surface\n"
    "(OpenSubdiv) best fits the mesh, writes it as OUT_cage.obj with texture coordinates, and\n"
    "samples the displacement from the limit surface to the mesh on a T x T grid per quad\n"
    "(--cage-tile T) into one float EXR texture over the cage's UVs, OUT_disp.exr, that DCC\n"
    "tools apply as is (Blender: blender -b -P scripts/blender_setup_cage.py -- OUT_cage.obj\n"
    "OUT_disp.exr OUT.blend; T = 2^L+1 for L subdivision levels; see README). It reports the PSNR of the\n"
    "bare limit surface and of the displaced one.\n"
    "With --collection DIR (instead of MESH SPHERE) every member of a consistent collection is\n"
    "converted with the same options into the folder -o: NAME.exr, NAME_normals.png,\n"
    "NAME_positions.png, NAME_lod*.glb, NAME_cage.obj,\n"
    "NAME_disp.exr per member, collection_morph.glb (one glTF, the members as morph targets),\n"
    "and convert_report.json (per member sizes and PSNRs, and per feature the texel that holds\n"
    "it in every image). All members share one layout: the same texel, cage vertex, glTF\n"
    "vertex is the same place on every member. Each LOD level has one connectivity on every\n"
    "member (collection_morph_lodK.glb per level): the reference member's own mesh laid on\n"
    "every member through the consistent maps, unless it folds over on more than 1% of its\n"
    "faces on some member, then the common remesh simplified (report: lod_connectivity).\n"
    "The folder appears only when complete.\n"
    "Exit codes: 2 bad flags (e.g.\n"
    "--size not 2^k+1), 3 bad input (including a folded map), 4 I/O error.";
inline constexpr const char* kConvertExamples =
    "  spherekit convert bunny.obj bunny.sphere.obj -o bunny.exr\n"
    "  spherekit convert bunny.obj bunny.sphere.obj -o bunny.exr --size 129 --remesh bunny.gim.obj\n"
    "  spherekit convert igea.ply igea.sphere.obj -o igea.exr --report igea.convert.json\n"
    "  spherekit convert bunny.obj bunny.sphere.obj -o out/bunny.exr --size 257 --lods 4\n"
    "  spherekit convert bunny.obj bunny.sphere.obj -o out/bunny.exr --cage 8 --cage-tile 33\n"
    "  spherekit convert --collection heads/ -o heads_assets/ --size 129 --lods 3 --cage 8";

// `spherekit consistent` (paper §3).
inline constexpr const char* kConsistent =
    "Consistent spherical parameterization (Asirvatham, Praun, Hoppe 2005): every mesh is mapped\n"
    "bijectively onto the unit sphere so that corresponding features (same names in the meshes'\n"
    "feature files, `name vertex` lines) land on the same sphere points. Then two surface points\n"
    "correspond when their sphere points are equal ('spherekit correspond').\n"
    "Steps: 1 unconstrained map of the reference (its features give F'); 2 constrained maps of\n"
    "the others to F'; 3 remesh all as octahedral geometry images, features snapped; 4 one mesh\n"
    "in R^3n; 5 its unconstrained map (n-D quadric, summed stretch) gives the final locations F;\n"
    "6 constrained maps of all meshes to F. --no-refine-locations stops after step 2.\n"
    "Then the correspondence is refined: each other mesh's map is fitted to the reference's so\n"
    "that the maps agree between the features (the reference's surface carried onto each mesh\n"
    "as rigidly as possible, the map flowed onto it, then a few stretch passes; bijective,\n"
    "features exact, a round that would cost over 20% of a map's stretch efficiency is not\n"
    "taken; collection.json records what it did per member). --no-refine-correspondence keeps\n"
    "the step-6 maps.\n"
    "Writes the folder -o DIR: collection.json (manifest), features.txt (`name x y z`: F) and\n"
    "<stem>.sphere.obj per mesh; DIR is replaced only when everything succeeded. Feature files\n"
    "default to NAME.lm.txt beside each mesh. Without meshes, the built-in sample collection.";
inline constexpr const char* kConsistentExamples =
    "  spherekit consistent -o cats cat0.obj cat2.obj cat5.obj cat9.obj\n"
    "  spherekit consistent -o pair bunny.obj gargoyle.obj --features bunny.lm.txt gargoyle.lm.txt\n"
    "  spherekit consistent -o samples-collection          # the built-in samples";

// `spherekit add` (paper §5).
inline constexpr const char* kAdd =
    "Constrained spherical parameterization of MESH with its features exactly on the collection's\n"
    "feature locations F (the paper's way to grow a database without recomputing it, §5). The\n"
    "feature file (default NAME.lm.txt beside the mesh) must name every feature of the\n"
    "collection. Writes DIR/<stem>.sphere.obj and updates collection.json under the folder's lock\n"
    "(DIR/.collection.lock, held only around the manifest update), so that concurrent adds, e.g. the\n"
    "tasks of a job array, all land. Reads the manifest and F, and, when the collection was made\n"
    "with the correspondence refinement, the reference member's mesh and map: the new map is\n"
    "refined against it as `consistent` refined the others (--no-refine-correspondence: not).\n"
    "Members are kept sorted by name.";
inline constexpr const char* kAddExamples =
    "  spherekit add cats cat10.obj\n"
    "  spherekit add cats scan.ply --features scan.lm.txt --name cat_scan\n"
    "  spherekit add cats cat11.obj --map cat11.sphere.obj   # computed elsewhere, verified";

// `spherekit submit` (issue 23).
inline constexpr const char* kSubmit =
    "A collection too large for one 'consistent' run: the feature locations F come from a subset of\n"
    "k members (steps 1-5, 'consistent'), then every other member is mapped to F as its own task\n"
    "('add', the paper's §5; concurrent tasks update the manifest under the folder's lock), then\n"
    "optionally 'convert --collection', then a final check (every member listed, every map a\n"
    "bijection). The result equals 'consistent' on the subset followed by 'add' of the rest.\n"
    "k: the joint step keeps one quadric of d(d+1)/2 doubles (d = 3k) per remesh vertex, about\n"
    "8 N^2 (3k)(3k+1)/2 bytes for an N x N remesh: 60 MB at k = 20, 1.5 GB at k = 100 (N = 65).\n"
    "Default k = min(n, 12, what fits --joint-memory-mb); the subset is spread over the shapes\n"
    "(farthest points of the feature-layout descriptor) or --subset-by first or --subset-members.\n"
    "--scheduler local (default) runs the tasks here, one after another; --scheduler slurm submits\n"
    "one job array per stage (sbatch --array, --dependency=afterok --kill-on-invalid-dep=yes,\n"
    "--cpus-per-task, --threads and OMP_NUM_THREADS in each task), waits, and exits non-zero when\n"
    "any task failed (job states from scontrol AND every task's output files). Scripts, per-task\n"
    "logs (logs/STAGE_I.out/.err), per-task reports and the plan go to --work (default DIR.jobs).";
inline constexpr const char* kSubmitExamples =
    "  spherekit submit -o lib meshes/*.obj --subset 16 --effort 1\n"
    "  spherekit submit -o lib meshes/*.obj --scheduler slurm --cpus-per-task 2 --threads 2 \\\n"
    "      --partition batch --time 1:00:00 --convert lib-assets --convert-args '--gi 129 --lods 3'\n"
    "  spherekit submit --verify lib.jobs/plan.json        # the final task: check the result";

}  // namespace spherekit::cli::help
