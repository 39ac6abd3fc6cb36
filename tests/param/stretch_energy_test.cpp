// White-box checks of the stretch optimizer's per-vertex energy (libparam/src/stretch_optimizer.cpp):
// independence of face numbering and the size of the anti-cruft term (issue 20).
#include <catch2/catch.hpp>

#include <Eigen/SVD>
#include <cmath>

#include "detail/sphere_state.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::detail;

namespace {

// A full-resolution state: every face and vertex alive, sphere points S, surface P.
SphereState make_state(const TriMesh& m, const RowMat3d& S, const RowMatXd& P) {
  SphereState st;
  st.P = &P;
  st.models = 1;
  const int nf = static_cast<int>(m.F.rows()), nv = static_cast<int>(m.V.rows());
  for (int f = 0; f < nf; ++f) st.F.push_back({m.F(f, 0), m.F(f, 1), m.F(f, 2)});
  st.face_alive.assign(static_cast<size_t>(nf), 1);
  st.vertex_alive.assign(static_cast<size_t>(nv), 1);
  st.face_weight.assign(static_cast<size_t>(nf), 1.0);
  st.vf.assign(static_cast<size_t>(nv), {});
  for (int f = 0; f < nf; ++f)
    for (int v : st.F[static_cast<size_t>(f)]) st.vf[static_cast<size_t>(v)].push_back(f);
  st.alive_vertices = nv;
  st.S = S;
  st.update_areas();
  return st;
}

double vertex_energy(const SphereState& st, int v, double reg, double split) {
  RingScratch ring;
  REQUIRE(load_ring(st, v, ring));
  return ring_energy(st, ring, st.S.row(v).transpose(), reg, split);
}

// Smallest squared singular value of the affine map chord triangle (q) -> surface triangle (p),
// times the state's scale: computed here from an explicit 2x2 Jacobian, independently of the
// optimizer's Gram-entry formulas.
double smallest_squared_stretch(const Eigen::Vector3d q[3], const Eigen::Vector3d p[3], double scale) {
  const Eigen::Vector3d e1 = q[1] - q[0], e2 = q[2] - q[0];
  const Eigen::Vector3d u = e1.normalized(), w = (e2 - e2.dot(u) * u).normalized();
  Eigen::Matrix2d dom;
  dom << e1.dot(u), e2.dot(u), e1.dot(w), e2.dot(w);
  Eigen::Matrix<double, 3, 2> surf;
  surf.col(0) = p[1] - p[0];
  surf.col(1) = p[2] - p[0];
  const Eigen::Matrix<double, 3, 2> J = surf * dom.inverse();
  Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>> svd(J);
  const double s = svd.singularValues()(1);
  return s * s * scale;
}

}  // namespace

TEST_CASE("a vertex's stretch energy does not depend on which corner of a face comes first",
          "[param][sphere][energy]") {
  const TriMesh m = test::icosphere(1);
  RowMat3d S = m.V;
  S.rowwise().normalize();
  RowMatXd P = m.V;
  P.col(0) *= 3.0;  // an anisotropic surface: the regularizer's frames matter
  P.col(2) *= 0.5;
  SphereState a = make_state(m, S, P);
  SphereState b = a;
  for (auto& c : b.F) c = {c[1], c[2], c[0]};
  for (int v = 0; v < static_cast<int>(S.rows()); ++v)
    for (double split : {0.0, 0.99}) {  // chord triangles, and the accordion split of large faces
      const double ea = vertex_energy(a, v, 1e-4, split), eb = vertex_energy(b, v, 1e-4, split);
      REQUIRE(std::isfinite(ea));
      CHECK(eb == Approx(ea).epsilon(1e-12));
    }
}

TEST_CASE("the anti-cruft term: exact on conformal faces, never above the smallest-singular-value form",
          "[param][sphere][energy]") {
  const TriMesh m = test::icosphere(1);
  RowMat3d S = m.V;
  S.rowwise().normalize();
  const double reg = 1e-3;

  SECTION("conformal: surface = 2 x the sphere's chord triangles, so a = c = T/2 in every frame") {
    RowMatXd P = 2.0 * S;
    SphereState st = make_state(m, S, P);
    const double k = st.model_scale[0] * 4.0;  // squared stretch along every direction
    for (int v = 0; v < static_cast<int>(S.rows()); ++v) {
      double expected = 0;
      for (int f : st.vf[static_cast<size_t>(v)]) {
        const auto& c = st.F[static_cast<size_t>(f)];
        const Eigen::Vector3d p0 = P.row(c[0]).transpose(), p1 = P.row(c[1]).transpose(), p2 = P.row(c[2]).transpose();
        const double area = 0.5 * (p1 - p0).cross(p2 - p0).norm();
        expected += (area + st.area_floor[0]) / st.model_area[0] * reg / (k * k * k);
      }
      const double term = vertex_energy(st, v, reg, 0.0) - vertex_energy(st, v, 0.0, 0.0);
      CHECK(term == Approx(expected).epsilon(1e-9));
    }
  }

  SECTION("anisotropic: at most w / sigma_min^6 per face, and strictly less somewhere") {
    RowMatXd P = S;
    P.col(0) *= 4.0;
    P.col(1) *= 1.5;
    SphereState st = make_state(m, S, P);
    bool strictly_less = false;
    for (int v = 0; v < static_cast<int>(S.rows()); ++v) {
      double bound = 0;
      for (int f : st.vf[static_cast<size_t>(v)]) {
        const auto& c = st.F[static_cast<size_t>(f)];
        Eigen::Vector3d q[3], p[3];
        for (int i = 0; i < 3; ++i) {
          q[i] = S.row(c[i]).transpose();
          p[i] = P.row(c[i]).transpose();
        }
        const double g = smallest_squared_stretch(q, p, st.model_scale[0]);
        const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
        bound += (area + st.area_floor[0]) / st.model_area[0] * reg / (g * g * g);
      }
      const double term = vertex_energy(st, v, reg, 0.0) - vertex_energy(st, v, 0.0, 0.0);
      CHECK(term > 0);
      CHECK(term <= bound * (1 + 1e-9));
      if (term < 0.9 * bound) strictly_less = true;
    }
    CHECK(strictly_less);
  }
}
