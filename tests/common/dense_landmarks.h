// Dense corresponding landmark sets for tests (issue 19: "works well with either sparse or
// dense sets", paper §1): farthest-point samples of member 0, carried to the other members
// through a ground truth. tools/dev/dense_landmarks.py makes the same sets for the command
// line (from a family's .corr.txt / .gt.txt files) and measures them.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "spherekit/mesh.h"

namespace spherekit::test {

/// Vertex of another member that a vertex of member 0 corresponds to, or -1 (not covered).
using CarryFn = std::function<int(int)>;

/// `k` farthest-point samples of `m0` (geodesic along the edges, first sample vertex 0),
/// among the vertices every `carry` covers; a sample whose partner on some member is
/// already a landmark there is skipped, so every member's landmarks are distinct. Returns
/// one vertex list per member (member 0 first, then one per `carry`); fewer than k entries
/// when the covered vertices run out.
std::vector<std::vector<int>> farthest_point_landmarks(const TriMesh& m0, const std::vector<CarryFn>& carry, int k);

/// Carrying through two members' .corr.txt sample lists (line s of both is the same surface
/// point): vertex v of the first goes to corr1[s] for the first s with corr0[s] == v.
CarryFn carry_through_samples(const std::vector<int>& corr0, const std::vector<int>& corr1);

/// Whitespace-separated integers of a file (empty when it cannot be read).
std::vector<int> read_int_list(const std::string& path);

/// Fewest edges between two of the given vertices of `m` (breadth-first; 0 if fewer than two).
int min_hops_between(const TriMesh& m, const std::vector<int>& verts);

}  // namespace spherekit::test
