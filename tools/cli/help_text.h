// The long help paragraphs and examples of the commands whose help is longer than their
// code (`spherekit CMD --help` prints them through add_command): kept here so each cmd_*.cpp
// reads as flags -> options -> one call -> print (issue 21).
#pragma once

namespace spherekit::cli::help {

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
    "tasks of a job array, all land. Reads only the manifest and F, not the other members' maps.\n"
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
