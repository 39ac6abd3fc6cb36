// The kernel point of a vertex's ring on the sphere (detail/kernel_point.h): whenever the
// kernel has room (a point found by brute force makes every ring face clearly positive) one is
// found, checked with the exact predicate; rings whose kernel is empty fail at the ascent's
// full cost in the callers' work budget (the untangling's bound counts it).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

#include "detail/kernel_point.h"
#include "spherekit/predicates.h"

using namespace spherekit;

namespace {

struct Ring {
  RowMat3d S;  // row 0: the vertex (unused by kernel_point), rows 1..k: the ring
  std::vector<std::array<int, 2>> faces;
};

// k points around a random pole, at random polar angles, in counter-clockwise order except
// where `shuffle` swaps two neighbours (a folded ring).
Ring random_ring(std::mt19937& rng, int k, bool shuffle) {
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Vector3d pole = Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized();
  const Eigen::Vector3d e1 = pole.unitOrthogonal(), e2 = pole.cross(e1);
  std::vector<double> phi(static_cast<size_t>(k));
  for (int i = 0; i < k; ++i) phi[static_cast<size_t>(i)] = 2 * std::numbers::pi * (i + 0.8 * (u(rng) - 0.5)) / k;
  if (shuffle) {
    const int i = static_cast<int>(u(rng) * k) % k;
    std::swap(phi[static_cast<size_t>(i)], phi[static_cast<size_t>((i + 1) % k)]);
  }
  Ring r;
  r.S.resize(k + 1, 3);
  r.S.row(0) = pole.transpose();
  for (int i = 0; i < k; ++i) {
    const double theta = 0.05 + 1.3 * u(rng);
    const Eigen::Vector3d p = std::cos(theta) * pole +
                              std::sin(theta) * (std::cos(phi[static_cast<size_t>(i)]) * e1 + std::sin(phi[static_cast<size_t>(i)]) * e2);
    r.S.row(i + 1) = p.transpose();
  }
  for (int i = 0; i < k; ++i) r.faces.push_back({i + 1, (i + 1) % k + 1});
  return r;
}

bool in_kernel(const Ring& r, const Eigen::Vector3d& x) {
  for (const auto& f : r.faces)
    if (orient3d_origin(x.data(), r.S.row(f[0]).data(), r.S.row(f[1]).data()) <= 0) return false;
  return true;
}

// The largest min over ring faces of n_f . x on a dense Fibonacci lattice (points about
// 0.018 rad apart: within about 0.01 of the true max-min).
double lattice_max_min(const Ring& r) {
  constexpr int kPoints = 40000;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  double best = -2;
  for (int i = 0; i < kPoints; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / kPoints, s = std::sqrt(1 - z * z);
    const Eigen::Vector3d x(s * std::cos(golden * i), s * std::sin(golden * i), z);
    double m = 2;
    for (const auto& f : r.faces) {
      const Eigen::Vector3d n = r.S.row(f[0]).transpose().cross(r.S.row(f[1]).transpose()).normalized();
      m = std::min(m, n.dot(x));
    }
    best = std::max(best, m);
  }
  return best;
}

}  // namespace

TEST_CASE("kernel_point: a ring with room in its kernel always gets a point in it, an empty one costs the full ascent",
          "[kernel_point]") {
  std::mt19937 rng(5);
  int roomy = 0, empty = 0;
  for (int t = 0; t < 300; ++t) {
    const int k = 3 + t % 10;
    // (A whole triangle reversed has its kernel on the far side of the sphere, out of the
    // ascent's reach from the ring's mean: not a ring the untangling meets.)
    const Ring r = random_ring(rng, k, t % 3 == 0 && k > 3);
    const double room = lattice_max_min(r);
    Eigen::Vector3d start = Eigen::Vector3d::Zero();
    for (int i = 1; i <= k; ++i) start += r.S.row(i).transpose();
    if (!(start.norm() > 0)) continue;
    Eigen::Vector3d x;
    long work = 0;
    const bool found = detail::kernel_point(r.S, r.faces, start, &x, nullptr, &work);
    INFO("ring " << t << ", " << k << " faces, lattice max-min " << room);
    if (found) CHECK(in_kernel(r, x));
    if (room > 0.02) {
      ++roomy;
      CHECK(found);
    }
    if (room < -0.02) {
      ++empty;
      CHECK_FALSE(found);
      CHECK(work == 2000);
    }
  }
  // Both kinds occurred, so both checks above were exercised.
  CHECK(roomy > 50);
  CHECK(empty > 20);
}
