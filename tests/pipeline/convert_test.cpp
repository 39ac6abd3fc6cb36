// The conversion pipeline as a library (spherekit/pipeline/convert.h), not through the
// program: one mesh with its sphere map, the refusals that leave nothing written, and a
// collection converted into one folder whose members share one layout.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/pipeline/convert.h"
#include "test_files.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;

namespace {

// A bumpy genus-0 mesh and its radial projection, a bijective sphere map.
struct MappedMesh {
  TriMesh mesh;
  SphereMap map;
};

MappedMesh blob(std::uint64_t seed) {
  MappedMesh m;
  m.mesh = test::random_blob(2, seed);
  m.map.S = m.mesh.V.rowwise().normalized();
  return m;
}

std::string write_pair(const std::string& dir, const std::string& name, const MappedMesh& m) {
  REQUIRE(formats::write_mesh(dir + "/" + name + ".obj", m.mesh).ok());
  REQUIRE(formats::write_sphere_map(dir + "/" + name + ".sphere.obj", m.mesh, m.map).ok());
  return dir + "/" + name;
}

pipeline::ConvertOptions small_options() {
  pipeline::ConvertOptions o;
  o.size = 17;
  o.psnr_samples = 2000;
  o.lods = 2;
  o.cage = 1;
  o.cage_tile = 3;
  return o;
}


}  // namespace

TEST_CASE("convert_mesh: image, previews, levels of detail, cage, measured and reported", "[pipeline]") {
  const std::string dir = test::temp_dir("pipeline_convert_mesh");
  const std::string base = write_pair(dir, "blob", blob(3));
  pipeline::ConvertMeshJob job{base + ".obj", base + ".sphere.obj", dir + "/out/blob.exr", dir + "/out/blob.gim.obj",
                               small_options()};
  fs::create_directories(dir + "/out");
  auto r = pipeline::convert_mesh(job);
  REQUIRE(r.ok());
  CHECK(test::files_in(dir + "/out") == std::vector<std::string>{"blob.exr", "blob.gim.obj", "blob_cage.obj", "blob_disp.exr",
                                                           "blob_lod0.glb", "blob_lod1.glb", "blob_lods.glb",
                                                           "blob_normals.png", "blob_positions.png"});
  const pipeline::GeometryAssets& g = r->assets;
  CHECK(g.image.size == 17);
  CHECK(g.remesh.F.rows() == 2 * 16 * 16);  // closed mesh: no holes to leave open
  REQUIRE(g.measured);
  CHECK(g.error.psnr > 20);
  CHECK_FALSE(g.error_all_faces.has_value());
  REQUIRE(g.lod_errors.size() == 2);
  CHECK(g.lod_errors[1].psnr < g.lod_errors[0].psnr + 1e-9);  // the coarser level is no closer
  REQUIRE(g.cage.has_value());
  CHECK(g.cage->quads == 6);
  const pipeline::Json j = pipeline::to_json(r.value());
  CHECK(j["size"] == 17);
  CHECK(j["positions"] == "fit");
  CHECK(j["lods"].size() == 2);
  // Each level's quantization is in the report (its own .glb carries none of it).
  for (std::size_t k = 0; k < 2; ++k) {
    const pipeline::Json& q = j["lods"][k]["quantization"];
    CHECK(q["position_bits"] == g.lods.levels[k].quantization.quantization.position_bits);
    CHECK(q["texcoord_bits"] == g.lods.levels[k].quantization.quantization.texcoord_bits);
    CHECK(q["position_max_error"].get<double>() > 0);
    CHECK(q.contains("decided_by"));
  }
  CHECK(j["cage"]["displacement"] == "scalar");
  CHECK(j["cage"]["bytes"].get<long long>() > 0);
  CHECK(j["psnr_db"].get<double>() == Approx(g.error.psnr));
}

TEST_CASE("convert_mesh: refused input writes nothing and names the file", "[pipeline]") {
  const std::string dir = test::temp_dir("pipeline_convert_refused");
  MappedMesh folded = blob(5);
  folded.map.S.row(0) *= -1;  // one vertex to the antipode: faces flip
  const std::string base = write_pair(dir, "folded", folded);
  fs::create_directories(dir + "/out");
  auto r = pipeline::convert_mesh({base + ".obj", base + ".sphere.obj", dir + "/out/x.exr", "", small_options()});
  REQUIRE_FALSE(r.ok());
  CHECK(r.status().code() == ErrorCode::InvalidInput);
  CHECK(r.status().message().rfind(base + ".sphere.obj: not a bijective sphere map", 0) == 0);
  CHECK(test::files_in(dir + "/out").empty());
  // An image name that is not .exr is refused before the mesh is even read (the image would be
  // OpenEXR data under a .png name).
  auto png = pipeline::convert_mesh({dir + "/absent.obj", dir + "/absent.sphere.obj", dir + "/out/x.png", "", small_options()});
  REQUIRE_FALSE(png.ok());
  CHECK(png.status().message() == dir + "/out/x.png: geometry images are written as .exr files");
  CHECK(test::files_in(dir + "/out").empty());
  pipeline::ConvertOptions bad = small_options();
  bad.size = 20;
  CHECK(pipeline::check_convert_options(bad).message().find("--size 20") != std::string::npos);
  bad = small_options();
  bad.lods = 5;
  CHECK(pipeline::check_convert_options(bad).message().find("--lods 5 does not fit") != std::string::npos);
}

TEST_CASE("convert_collection: every member into one folder with one layout and a morph glTF", "[pipeline]") {
  const std::string dir = test::temp_dir("pipeline_convert_collection");
  const std::string col = dir + "/col";
  fs::create_directories(col);
  formats::CollectionManifest m;
  m.features.push_back({"north", Eigen::Vector3d(0, 0, 1), std::nullopt});
  for (int k = 0; k < 2; ++k) {
    const std::string name = "m" + std::to_string(k);
    const MappedMesh x = blob(10 + static_cast<std::uint64_t>(k));
    REQUIRE(formats::write_mesh(dir + "/" + name + ".obj", x.mesh).ok());
    REQUIRE(formats::write_sphere_map(col + "/" + name + ".sphere.obj", x.mesh, x.map).ok());
    formats::CollectionMember e;
    e.name = name;
    e.map = name + ".sphere.obj";
    e.source = dir + "/" + name + ".obj";
    e.vertices = x.mesh.V.rows();
    m.members.push_back(e);
  }
  REQUIRE(formats::write_file_atomic(col + "/features.txt", formats::sphere_points_text({"north"}, m.locations())).ok());
  REQUIRE(formats::write_file_atomic(col + "/collection.json", formats::collection_manifest_text(m)).ok());

  int events = 0;
  auto r = pipeline::convert_collection({col, dir + "/assets", small_options()}, [&](const ProgressEvent&) {
    ++events;
    return true;
  });
  REQUIRE(r.ok());
  CHECK(events > 0);
  REQUIRE(r->members.size() == 2);
  // One connectivity: the members' remeshes are the same faces.
  CHECK(r->members[0].assets.remesh.F == r->members[1].assets.remesh.F);
  const auto names = test::files_in(dir + "/assets");
  CHECK(std::count(names.begin(), names.end(), "collection_morph.glb") == 1);
  CHECK(std::count(names.begin(), names.end(), "convert_report.json") == 1);
  CHECK(formats::read_file(dir + "/assets/convert_report.json").value() == r->report.dump(2) + "\n");
  CHECK(r->report["members"][1]["cage"]["file"] == "m1_cage.obj");
  CHECK(r->report["members"][1]["lods"][1]["quantization"]["position_bits"] ==
        r->members[1].assets.lods.levels[1].quantization.quantization.position_bits);
  CHECK(r->report["feature_texels"][0]["name"] == "north");

  SECTION("cancelled between members: the folder is not replaced") {
    auto again = pipeline::convert_collection({col, dir + "/assets", small_options()}, {}, [] { return false; });
    CHECK(again.status().code() == ErrorCode::Cancelled);
    CHECK(test::files_in(dir + "/assets") == names);
  }
}

namespace {

// A collection folder of the given members (mesh + map), reference `reference`.
std::string write_collection(const std::string& dir, const std::vector<MappedMesh>& members, const std::string& reference) {
  const std::string col = dir + "/col";
  fs::create_directories(col);
  formats::CollectionManifest m;
  m.reference = reference;
  m.features.push_back({"north", Eigen::Vector3d(0, 0, 1), std::nullopt});
  for (std::size_t k = 0; k < members.size(); ++k) {
    const std::string name = "m" + std::to_string(k);
    REQUIRE(formats::write_mesh(dir + "/" + name + ".obj", members[k].mesh).ok());
    REQUIRE(formats::write_sphere_map(col + "/" + name + ".sphere.obj", members[k].mesh, members[k].map).ok());
    formats::CollectionMember e;
    e.name = name;
    e.map = name + ".sphere.obj";
    e.source = dir + "/" + name + ".obj";
    e.vertices = members[k].mesh.V.rows();
    m.members.push_back(e);
  }
  REQUIRE(formats::write_file_atomic(col + "/features.txt", formats::sphere_points_text({"north"}, m.locations())).ok());
  REQUIRE(formats::write_file_atomic(col + "/collection.json", formats::collection_manifest_text(m)).ok());
  return col;
}

}  // namespace

TEST_CASE("convert_collection: levels on the reference member's own mesh, or the remesh where it folds", "[pipeline]") {
  const std::string dir = test::temp_dir("pipeline_convert_template_levels");
  pipeline::ConvertOptions o = small_options();
  o.cage = 0;
  o.lods = 3;
  MappedMesh a{test::random_blob(2, 21), {}}, b{test::random_blob(3, 22), {}};
  a.map.S = a.mesh.V.rowwise().normalized();
  b.map.S = b.mesh.V.rowwise().normalized();

  SECTION("the reference's mesh fits every member: its levels") {
    const std::string col = write_collection(dir, {a, b}, "m1");
    auto r = pipeline::convert_collection({col, dir + "/assets", o});
    REQUIRE(r.ok());
    CHECK(r->lod_connectivity == "template");
    CHECK(r->lod_template == "m1");
    CHECK(r->lod_connectivity_reason.empty());
    CHECK(r->report["lod_connectivity"]["kind"] == "template");
    CHECK(r->report["lod_connectivity"]["template_folds"]["m0"]["folded_faces"] == 0);
    const pipeline::Json& choice = r->report["lod_connectivity"]["choice"];
    REQUIRE(choice["template_worst_member_psnr_db"].size() == 3);
    REQUIRE(choice["remesh_worst_member_psnr_db"].size() == 3);
    double laid = 0, remesh = 0;
    for (int k = 0; k < 3; ++k) laid += choice["template_worst_member_psnr_db"][k].get<double>(), remesh += choice["remesh_worst_member_psnr_db"][k].get<double>();
    CHECK(laid >= remesh);
    // Level 0 has the reference's vertex count (m1: a finer blob than m0) on both members, and
    // every level one connectivity.
    const auto& l0 = r->members[0].assets.lods.levels;
    const auto& l1 = r->members[1].assets.lods.levels;
    REQUIRE(l0.size() == 3);
    for (std::size_t k = 0; k < 3; ++k) CHECK(l0[k].mesh.F == l1[k].mesh.F);
    CHECK(*std::max_element(l0[0].mesh.position_index.begin(), l0[0].mesh.position_index.end()) + 1 == b.mesh.V.rows());
    const auto names = test::files_in(dir + "/assets");
    CHECK(std::count(names.begin(), names.end(), "collection_morph_lod2.glb") == 1);
  }
  // m1's map turns the cap round the north pole by half a turn (and, if `both`, the south
  // pole's cap too), each latitude circle rigidly: still one-to-one on m1's fine mesh, but the
  // coarse m0 laid on it folds over.
  auto twisted = [](bool both) {
    MappedMesh c{test::random_blob(5, 23), {}};
    c.map.S = c.mesh.V.rowwise().normalized();
    for (Eigen::Index v = 0; v < c.map.S.rows(); ++v) {
      const Eigen::Vector3d d = c.map.S.row(v).transpose();
      const double polar = std::acos(std::clamp(std::abs(d.z()), 0.0, 1.0));
      const double t = (d.z() < 0 && !both ? 0.0 : 3.141592653589793) * std::clamp((1.0 - polar) / 0.8, 0.0, 1.0);
      c.map.S.row(v) =
          Eigen::Vector3d(std::cos(t) * d.x() - std::sin(t) * d.y(), std::sin(t) * d.x() + std::cos(t) * d.y(), d.z()).transpose();
    }
    return c;
  };
  SECTION("the reference's mesh laid on a member is the worse surface: the common remesh's levels") {
    const std::string col = write_collection(dir, {a, twisted(false)}, "m0");
    auto r = pipeline::convert_collection({col, dir + "/assets", o});
    REQUIRE(r.ok());
    CHECK(r->lod_connectivity == "remesh");
    const pipeline::Json& c = r->report["lod_connectivity"];
    CHECK(c["template_folds"]["m1"]["folded_faces"].get<int>() > 0);
    REQUIRE(c.contains("choice"));
    double laid = 0, remesh = 0;
    for (int k = 0; k < 3; ++k)
      laid += c["choice"]["template_worst_member_psnr_db"][k].get<double>(), remesh += c["choice"]["remesh_worst_member_psnr_db"][k].get<double>();
    CHECK(laid < remesh);
    CHECK(r->lod_connectivity_reason.find("the template m0 laid on every member has a worst member of") == 0);
    const auto& l0 = r->members[0].assets.lods.levels;
    const auto& l1 = r->members[1].assets.lods.levels;
    for (std::size_t k = 0; k < l0.size(); ++k) CHECK(l0[k].mesh.F == l1[k].mesh.F);
  }
  SECTION("the reference's mesh folds over on many faces of a member: not even tried") {
    const std::string col = write_collection(dir, {a, twisted(true)}, "m0");
    auto r = pipeline::convert_collection({col, dir + "/assets", o});
    REQUIRE(r.ok());
    CHECK(r->lod_connectivity == "remesh");
    CHECK(r->lod_connectivity_reason.find("the template m0 laid on m1 folds over on") == 0);
    CHECK_FALSE(r->report["lod_connectivity"].contains("choice"));
  }
}
