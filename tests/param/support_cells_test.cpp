// The feature warp's support grid (detail/feature_warp.h, SupportCells): the flow's field at a
// vertex sums, in feature order, the kernels of the features within the support, and the grid
// lets a vertex visit only the features its cell lists. The field is the same to the bit only
// if every contributing feature is listed, in ascending order; these tests check exactly that
// (the predicate the warp itself uses, |x - c| / support < 1) on points that stress the grid:
// cell boundaries, the cube's faces at +-1 and coordinates rounded past them.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "detail/feature_warp.h"

using spherekit::detail::SupportCells;

namespace {

Eigen::Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Vector3d v(n(rng), n(rng), n(rng));
  return v.normalized();
}

// Every centre the warp would sum for x (r < 1 as the warp computes r) must be listed.
void require_lists_contributors(SupportCells& cells, const std::vector<Eigen::Vector3d>& centres, double support,
                                const Eigen::Vector3d& x, long* listed_total) {
  const double inv_h = 1 / support;
  const auto list = cells.near(x);
  REQUIRE(std::is_sorted(list.begin(), list.end()));
  REQUIRE(std::adjacent_find(list.begin(), list.end()) == list.end());
  for (size_t j = 0; j < centres.size(); ++j) {
    const double r = (x - centres[j]).norm() * inv_h;
    if (r < 1) REQUIRE(std::binary_search(list.begin(), list.end(), static_cast<int>(j)));
  }
  *listed_total += static_cast<long>(list.size());
}

}  // namespace

TEST_CASE("the support grid lists every feature whose kernel reaches a point, in ascending order", "[param][warp]") {
  std::mt19937_64 rng(7);
  for (double support : {0.02, 0.13, 0.4, 1.1, 3.0}) {
    for (int count : {1, 17, 300}) {
      std::vector<Eigen::Vector3d> centres;
      for (int j = 0; j < count; ++j) centres.push_back(random_unit(rng));
      // Centres on the cube's axes and on cell boundaries too (they touch many cells).
      centres.push_back(Eigen::Vector3d(1, 0, 0));
      centres.push_back(Eigen::Vector3d(0, -1, 0));
      SupportCells cells(centres, support);
      const double cell = 2.0 / cells.cells_per_axis();
      long listed = 0;
      int points = 0;
      for (int p = 0; p < 2000; ++p, ++points)
        require_lists_contributors(cells, centres, support, random_unit(rng), &listed);
      // Near every centre, at the distance where the kernel ends.
      for (const auto& c : centres)
        for (int p = 0; p < 4; ++p, ++points) {
          const Eigen::Vector3d x = (c + support * (1 - 1e-12) * random_unit(rng)).normalized();
          require_lists_contributors(cells, centres, support, x, &listed);
        }
      // The point of a cell nearest a centre: where a centre's support just reaches a cell.
      std::uniform_int_distribution<int> pick(0, cells.cells_per_axis() - 1);
      for (const auto& c : centres)
        for (int p = 0; p < 20; ++p, ++points) {
          Eigen::Vector3d x;
          for (int a = 0; a < 3; ++a) {
            const int i = std::clamp(static_cast<int>(std::floor((c[a] + 1) / cell)) + pick(rng) % 3 - 1, 0,
                                     cells.cells_per_axis() - 1);
            x[a] = std::clamp(c[a], -1 + i * cell, -1 + (i + 1) * cell);
          }
          require_lists_contributors(cells, centres, support, x, &listed);
        }
      // Points on cell boundaries, on the cube's faces, and rounded just past them.
      for (int p = 0; p < 200; ++p, ++points) {
        Eigen::Vector3d x = random_unit(rng);
        const int a = p % 3;
        x[a] = -1 + cell * std::round((x[a] + 1) / cell);
        require_lists_contributors(cells, centres, support, x, &listed);
      }
      for (const Eigen::Vector3d& x : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 0, 1),
                                       Eigen::Vector3d(std::nextafter(1.0, 2.0), 0, 0),
                                       Eigen::Vector3d(0, std::nextafter(-1.0, -2.0), 0),
                                       Eigen::Vector3d(1.5, 0.2, 0.1)}) {
        require_lists_contributors(cells, centres, support, x, &listed);
        ++points;
      }
      // A point off the sphere beyond rounding gets every centre.
      REQUIRE(cells.near(Eigen::Vector3d(1.5, 0.2, 0.1)).size() == centres.size());
      // The grid is worth it: with small supports a point visits a small share of the centres.
      if (support <= 0.4 && count == 300)
        CHECK(static_cast<double>(listed) / points < 0.35 * static_cast<double>(centres.size()));
    }
  }
}
