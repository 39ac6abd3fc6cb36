// spherekit::param in Python: check, param (unconstrained and constrained), eval, consistent
// maps of a collection, correspondence, geometry images and their remesh error.
#include "py_common.h"
#include "spherekit/check_mesh.h"
#include "spherekit/consistent_param.h"
#include "spherekit/constrained_param.h"
#include "spherekit/correspondence.h"
#include "spherekit/geometry_image.h"
#include "spherekit/metrics.h"
#include "spherekit/sphere_param.h"

namespace spherekit::py {
namespace {

using Callback = std::optional<pyb::function>;

pyb::dict check_dict(const MeshCheck& c) {
  pyb::dict d;
#define SK_FIELD(name) d[#name] = c.name
  SK_FIELD(vertices); SK_FIELD(faces); SK_FIELD(edges); SK_FIELD(unreferenced_vertices); SK_FIELD(nonfinite_vertices);
  SK_FIELD(invalid_indices); SK_FIELD(degenerate_faces); SK_FIELD(zero_area_faces); SK_FIELD(duplicate_faces);
  SK_FIELD(boundary_edges); SK_FIELD(nonmanifold_edges); SK_FIELD(orientation_conflicts); SK_FIELD(nonmanifold_vertices);
  SK_FIELD(boundary_loops); SK_FIELD(components); SK_FIELD(euler); SK_FIELD(genus); SK_FIELD(orientable); SK_FIELD(bbox_diag);
#undef SK_FIELD
  const Status accepted = require_genus0(c, /*allow_boundary=*/true);
  d["accepted"] = accepted.ok();
  d["problem"] = accepted.ok() ? std::string() : accepted.message();
  return d;
}

pyb::dict provenance_dict(const Provenance& p) {
  pyb::dict d;
  d["library_version"] = p.library_version;
  d["method"] = p.method;
  d["options_digest"] = p.options_digest;
  d["seed"] = p.seed;
  return d;
}

SphereParamOptions sphere_options(int effort, std::uint64_t seed, int threads, double regularizer_weight) {
  SphereParamOptions o;
  o.effort = effort;
  o.seed = seed;
  o.threads = threads;
  o.regularizer_weight = regularizer_weight;
  return o;
}

std::vector<Eigen::Vector3d> to_points(const pyb::array& a, const char* what) {
  const RowMat3d m = to_rowmat3d(a, what);
  std::vector<Eigen::Vector3d> out;
  for (Eigen::Index i = 0; i < m.rows(); ++i) out.emplace_back(m.row(i).transpose());
  return out;
}

RowMat3d from_points(const std::vector<Eigen::Vector3d>& p) {
  RowMat3d m(static_cast<Eigen::Index>(p.size()), 3);
  for (std::size_t i = 0; i < p.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = p[i].transpose();
  return m;
}

// The measures every map result has (SphereParamResult, ConstrainedParamResult); S is a view.
template <class Result>
void bind_map_measures(pyb::class_<Result>& c) {
  c.def_readonly("map", &Result::map)
      .def_property_readonly("S", [](Result& r) -> RowMat3d& { return r.map.S; }, pyb::return_value_policy::reference_internal)
      .def_readonly("flipped_faces", &Result::flipped_faces)
      .def_readonly("efficiency", &Result::efficiency)
      .def_readonly("l2_stretch", &Result::l2_stretch)
      .def_readonly("linf_stretch", &Result::linf_stretch)
      .def_readonly("winding", &Result::winding)
      .def_readonly("holes_filled", &Result::holes_filled);
}

}  // namespace

void bind_param(pyb::module_& m) {
  m.def("check", [](const Mesh& mesh) { return check_dict(check_mesh(mesh.mesh)); }, pyb::arg("mesh"),
        "Structural report of a mesh as a dict (the fields of `spherekit check --json`, plus 'accepted' and\n"
        "'problem': whether param accepts it and, if not, the command line's message).");
  m.def(
      "repair_pinched_vertices",
      [](const Mesh& mesh) {
        Mesh out = mesh;
        std::vector<int> new_to_old;
        const int split = repair_pinched_vertices(out.mesh, &new_to_old);
        return pyb::make_tuple(out, split, new_to_old);
      },
      pyb::arg("mesh"), "Splits pinched vertices (as check --repair): returns (mesh, vertices split, new_to_old).");

  pyb::class_<SphereMap>(m, "SphereMap", "A sphere map: S (#V x 3 unit vectors, view) and its provenance.")
      .def(pyb::init([](const pyb::array& S) {
             SphereMap map;
             map.S = to_rowmat3d(S, "S");
             return map;
           }),
           pyb::arg("S"))
      .def_readonly("S", &SphereMap::S, "#V x 3 unit vectors, in the mesh's vertex order")
      .def_property_readonly("provenance", [](const SphereMap& s) { return provenance_dict(s.provenance); });

  auto sphere_result = pyb::class_<SphereParamResult>(m, "SphereParamResult");
  bind_map_measures(sphere_result);
  sphere_result.def_readonly("base_vertices", &SphereParamResult::base_vertices)
      .def_readonly("optimization_passes", &SphereParamResult::optimization_passes)
      .def_property_readonly("times", [](const SphereParamResult& r) {
        return pyb::dict(pyb::arg("check") = r.times.check, pyb::arg("simplify") = r.times.simplify,
                         pyb::arg("refine") = r.times.refine, pyb::arg("total") = r.times.total);
      });

  m.def(
      "param",
      [](const Mesh& mesh, int effort, std::uint64_t seed, int threads, double regularizer_weight, Callback progress) {
        const SphereParamOptions o = sphere_options(effort, seed, threads, regularizer_weight);
        return run_stage(std::move(progress), mesh.source,
                         [&](const ProgressFn& fn) { return parameterize_sphere(mesh.mesh, o, fn); });
      },
      pyb::arg("mesh"), pyb::kw_only(), pyb::arg("effort") = 2, pyb::arg("seed") = 1, pyb::arg("threads") = 0,
      pyb::arg("regularizer_weight") = SphereParamOptions{}.regularizer_weight, pyb::arg("progress") = pyb::none(),
      "Maps a genus-0 mesh bijectively onto the unit sphere (parameterize_sphere; as `spherekit param`).\n"
      "The result's flipped_faces is 0 for a bijection (the command line refuses to write any other map).\n"
      "Raises InvalidInput (not genus 0, ...), Cancelled, SolverFailed.");

  pyb::class_<FeatureNetworkReport>(m, "FeatureNetworkReport")
      .def_readonly("paths", &FeatureNetworkReport::paths)
      .def_readonly("total_length", &FeatureNetworkReport::total_length)
      .def_readonly("max_ratio", &FeatureNetworkReport::max_ratio)
      .def_readonly("swirls_fixed", &FeatureNetworkReport::swirls_fixed)
      .def_readonly("edge_flips", &FeatureNetworkReport::edge_flips)
      .def_readonly("steiner_vertices", &FeatureNetworkReport::steiner_vertices)
      .def_readonly("auxiliary_features", &FeatureNetworkReport::auxiliary_features);

  auto constrained_result = pyb::class_<ConstrainedParamResult>(m, "ConstrainedParamResult");
  bind_map_measures(constrained_result);
  constrained_result.def_readonly("max_feature_angle", &ConstrainedParamResult::max_feature_angle)
      .def_readonly("network", &ConstrainedParamResult::network)
      .def_readonly("efficiency_retried", &ConstrainedParamResult::efficiency_retried,
                    "made twice: the first kept too little of the unconstrained efficiency (collections)")
      .def_readonly("first_efficiency", &ConstrainedParamResult::first_efficiency)
      .def_readonly("as_unconstrained", &ConstrainedParamResult::as_unconstrained);

  m.def(
      "param_constrained",
      [](const Mesh& mesh, std::vector<int> feature_vertices, const pyb::array& targets, int effort, std::uint64_t seed,
         int threads, Callback progress) {
        ConstrainedParamOptions o;
        o.sphere = collection_options(effort, seed, threads);
        const std::vector<Eigen::Vector3d> t = to_points(targets, "targets");
        return run_stage(std::move(progress), mesh.source, [&](const ProgressFn& fn) {
          return parameterize_sphere_constrained(mesh.mesh, feature_vertices, t, o, fn);
        });
      },
      pyb::arg("mesh"), pyb::arg("feature_vertices"), pyb::arg("targets"), pyb::kw_only(), pyb::arg("effort") = 2,
      pyb::arg("seed") = 1, pyb::arg("threads") = 0, pyb::arg("progress") = pyb::none(),
      "Constrained map (Asirvatham, Praun, Hoppe 2005 §4; as `param --features --targets` and `add`): every\n"
      "feature vertex lands exactly on its target (k x 3 unit vectors).");

  pyb::class_<ConsistentParamResult>(m, "ConsistentParamResult")
      .def_readonly("maps", &ConsistentParamResult::maps, "one ConstrainedParamResult per mesh")
      .def_property_readonly("initial_locations", [](const ConsistentParamResult& r) { return from_points(r.initial_locations); },
                             "F' (step 1), k x 3")
      .def_property_readonly("final_locations", [](const ConsistentParamResult& r) { return from_points(r.final_locations); },
                             "F (step 5), k x 3; features.txt of the collection folder")
      .def_readonly("reference_efficiency", &ConsistentParamResult::reference_efficiency)
      .def_readonly("unconstrained_efficiency", &ConsistentParamResult::unconstrained_efficiency,
                    "per mesh: its unconstrained map's efficiency (0 with efficiency_retry=0)")
      .def_readonly("joint_efficiency", &ConsistentParamResult::joint_efficiency)
      .def_readonly("joint_flips", &ConsistentParamResult::joint_flips)
      .def_readonly("remesh_vertices", &ConsistentParamResult::remesh_vertices)
      .def_readonly("refinement_failure", &ConsistentParamResult::refinement_failure)
      .def_property_readonly("times", [](const ConsistentParamResult& r) {
        const auto& t = r.times;
        return pyb::dict(pyb::arg("step1_reference") = t.reference, pyb::arg("step2_initial_maps") = t.initial,
                         pyb::arg("step3_remesh") = t.remesh, pyb::arg("step4_concatenate") = t.concatenate,
                         pyb::arg("step5_joint_map") = t.joint, pyb::arg("step6_final_maps") = t.final_maps,
                         pyb::arg("refine_correspondence") = t.refinement, pyb::arg("total") = t.total);
      })
      .def_property_readonly("refinement", [](const ConsistentParamResult& r) {
        // What the correspondence refinement did, per mesh (empty when it did not run).
        pyb::list out;
        for (const RefinedMember& m : r.refinement.members)
          out.append(pyb::dict(pyb::arg("refined") = m.refined, pyb::arg("note") = m.note, pyb::arg("rounds") = m.rounds,
                               pyb::arg("samples") = m.samples, pyb::arg("energy_before") = m.energy_before,
                               pyb::arg("energy_after") = m.energy_after, pyb::arg("crushed_faces") = m.crushed_faces,
                               pyb::arg("folded_samples_left_out") = m.folded_samples_left_out,
                               pyb::arg("flow_relaxations") = m.flow_relaxations, pyb::arg("snap_moves") = m.snap_moves,
                               pyb::arg("efficiency_before") = m.efficiency_before,
                               pyb::arg("efficiency_after") = m.efficiency_after, pyb::arg("seconds") = m.seconds));
        return out;
      });

  m.def(
      "consistent",
      [](const std::vector<Mesh>& meshes, const std::vector<std::vector<int>>& features, int reference, int remesh_size,
         bool refine_locations, bool refine_correspondence, double efficiency_retry, int effort, std::uint64_t seed,
         int threads, Callback progress) {
        ConsistentParamOptions o;
        o.constrained.sphere = collection_options(effort, seed, threads);
        o.reference = reference;
        o.remesh_size = remesh_size;
        o.refine_locations = refine_locations;
        o.refine_correspondence = refine_correspondence;
        o.efficiency_retry = efficiency_retry;
        o.threads = threads;
        std::vector<TriMesh> tri;
        for (const Mesh& mesh : meshes) tri.push_back(mesh.mesh);
        Progress p(std::move(progress));
        const ProgressFn fn = p.fn();
        auto result = [&] {
          pyb::gil_scoped_release release;
          return parameterize_consistent(tri, features, o, fn);
        }();
        // "mesh 2: ..." -> the file, as the command line says it.
        Status s = result.status();
        for (std::size_t i = 0; i < meshes.size() && !s.ok(); ++i) {
          const std::string tag = "mesh " + std::to_string(i) + ": ";
          if (!meshes[i].source.empty() && s.message().rfind(tag, 0) == 0)
            s = Status(s.code(), meshes[i].source + ": " + s.message().substr(tag.size()));
        }
        p.finish(s);
        return std::move(result).value();
      },
      pyb::arg("meshes"), pyb::arg("features"), pyb::kw_only(), pyb::arg("reference") = 0, pyb::arg("remesh_size") = 65,
      pyb::arg("refine_locations") = true, pyb::arg("refine_correspondence") = true,
      pyb::arg("efficiency_retry") = ConsistentParamOptions{}.efficiency_retry, pyb::arg("effort") = 2,
      pyb::arg("seed") = 1, pyb::arg("threads") = 0, pyb::arg("progress") = pyb::none(),
      "Consistent maps of a collection (the paper's six steps, then the correspondence refinement; as\n"
      "`spherekit consistent`): features[i] lists\n"
      "mesh i's feature vertices, in the same order (same names) for every mesh.");

  pyb::class_<SphereMapMetrics>(m, "SphereMapMetrics")
      .def_readonly("vertices", &SphereMapMetrics::vertices)
      .def_readonly("faces", &SphereMapMetrics::faces)
      .def_readonly("radius_dev", &SphereMapMetrics::radius_dev)
      .def_readonly("flipped", &SphereMapMetrics::flipped)
      .def_readonly("flipped_majority", &SphereMapMetrics::flipped_majority)
      .def_readonly("degenerate", &SphereMapMetrics::degenerate)
      .def_readonly("closed", &SphereMapMetrics::closed)
      .def_readonly("winding", &SphereMapMetrics::winding)
      .def_readonly("fold_excess", &SphereMapMetrics::fold_excess)
      .def_readonly("efficiency", &SphereMapMetrics::efficiency)
      .def_readonly("l2_stretch", &SphereMapMetrics::l2_stretch)
      .def_readonly("linf", &SphereMapMetrics::linf)
      .def_readonly("conformal_mean", &SphereMapMetrics::conformal_mean)
      .def_readonly("conformal_p95", &SphereMapMetrics::conformal_p95)
      .def_readonly("area_log_mean", &SphereMapMetrics::area_log_mean)
      .def_readonly("feature_err_deg", &SphereMapMetrics::feature_err_deg);

  m.def(
      "eval",
      [](const Mesh& mesh, const pyb::array& S) {
        const RowMat3d s = to_rowmat3d(S, "S");
        auto r = [&] {
          pyb::gil_scoped_release release;
          return evaluate_sphere_map(mesh.mesh, s);
        }();
        return unwrap(std::move(r), mesh.source);
      },
      pyb::arg("mesh"), pyb::arg("S"), "Measures a sphere map exactly as `spherekit eval` (evalsphere.py's definitions).");
  m.def(
      "count_flipped_faces", [](const Mesh& mesh, const pyb::array& S) { return count_flipped_faces(mesh.mesh.F, to_rowmat3d(S, "S")); },
      pyb::arg("mesh"), pyb::arg("S"), "Faces with det[S(a), S(b), S(c)] <= 0 by the exact predicate (0 for a bijection).");

  m.def(
      "correspond",
      [](const Mesh& from, const pyb::array& S_from, const Mesh& to, const pyb::array& S_to, const pyb::array& points) {
        const RowMat3d sf = to_rowmat3d(S_from, "S_from"), st = to_rowmat3d(S_to, "S_to"), q = to_rowmat3d(points, "points");
        std::vector<SurfacePoint> snapped;
        auto moved = [&] {
          pyb::gil_scoped_release release;
          // Points are snapped to `from`'s surface first, as `spherekit correspond --points` does.
          const ClosestPointLocator locator(from.mesh);
          for (Eigen::Index i = 0; i < q.rows(); ++i) snapped.push_back(locator.closest(q.row(i).transpose()));
          return transfer_points(from.mesh, sf, snapped, to.mesh, st);
        }();
        const std::vector<TransferredPoint> out = unwrap(std::move(moved), from.source);
        RowMat3d positions(static_cast<Eigen::Index>(out.size()), 3);
        Eigen::VectorXi faces(static_cast<Eigen::Index>(out.size()));
        std::vector<bool> in_hole(out.size());
        for (std::size_t i = 0; i < out.size(); ++i) {
          positions.row(static_cast<Eigen::Index>(i)) = surface_position(to.mesh, out[i].point).transpose();
          faces(static_cast<Eigen::Index>(i)) = out[i].point.face;
          in_hole[i] = out[i].in_hole;
        }
        return pyb::make_tuple(positions, faces, in_hole);
      },
      pyb::arg("from_mesh"), pyb::arg("S_from"), pyb::arg("to_mesh"), pyb::arg("S_to"), pyb::arg("points"),
      "Sends surface points (n x 3, snapped to from_mesh) to to_mesh through the common sphere (as `spherekit\n"
      "correspond`): returns (positions n x 3, faces of to_mesh, in_hole flags).");

  pyb::class_<GeometryImage>(m, "GeometryImage", "An N x N octahedral geometry image; arrays are views.")
      .def_readonly("size", &GeometryImage::size)
      .def_readonly("texels_in_holes", &GeometryImage::texels_in_holes)
      .def_property_readonly("positions", [](pyb::object self) {
        auto& g = self.cast<GeometryImage&>();
        return pyb::array_t<float>({g.size, g.size, 3}, g.positions.data(), self);
      })
      .def_property_readonly("normals", [](pyb::object self) {
        auto& g = self.cast<GeometryImage&>();
        return pyb::array_t<float>({g.size, g.size, 3}, g.normals.data(), self);
      })
      .def_property_readonly("face_ids", [](pyb::object self) {
        auto& g = self.cast<GeometryImage&>();
        return pyb::array_t<std::int32_t>({g.size, g.size}, g.face_ids.data(), self);
      })
      .def_property_readonly("in_hole", [](pyb::object self) {
        auto& g = self.cast<GeometryImage&>();
        return pyb::array_t<std::uint8_t>({g.size, g.size}, g.in_hole.data(), self);
      });

  m.def(
      "geometry_image",
      [](const Mesh& mesh, const pyb::array& S, int size, bool fit, int threads) {
        const RowMat3d s = to_rowmat3d(S, "S");
        GeometryImageOptions o;
        o.fit_positions = fit;
        o.threads = threads;
        auto r = [&] {
          pyb::gil_scoped_release release;
          return sample_geometry_image(mesh.mesh, s, size, o);
        }();
        return unwrap(std::move(r), mesh.source);
      },
      pyb::arg("mesh"), pyb::arg("S"), pyb::arg("size") = 257, pyb::kw_only(), pyb::arg("fit") = true,
      pyb::arg("threads") = 0,
      "Resamples the mesh through its sphere map into a size x size octahedral geometry image (size = 2^k+1);\n"
      "fit=True stores the least-squares fit of the surface (as `convert --positions fit`, the default).");
  m.def(
      "geometry_image_mesh", [](const GeometryImage& g, bool keep_holes) {
        Mesh out;
        out.mesh = keep_holes ? geometry_image_mesh(g) : geometry_image_open_mesh(g);
        return out;
      },
      pyb::arg("image"), pyb::kw_only(), pyb::arg("keep_holes") = false,
      "The remesh of a geometry image (as `convert --remesh`: a mesh's holes stay open unless keep_holes).");
  m.def(
      "remesh_psnr",
      [](const Mesh& original, const Mesh& remesh, int samples, std::uint64_t seed, int threads) {
        RemeshErrorOptions o;
        o.samples = samples;
        o.seed = seed;
        o.threads = threads;
        pyb::gil_scoped_release release;
        return remesh_psnr(original.mesh, remesh.mesh, o);
      },
      pyb::arg("original"), pyb::arg("remesh"), pyb::kw_only(), pyb::arg("samples") = RemeshErrorOptions{}.samples,
      pyb::arg("seed") = 1, pyb::arg("threads") = 0,
      "PSNR (dB) of a remesh against the original: peak = bounding-box diagonal, symmetric RMS distance.");
}

}  // namespace spherekit::py
