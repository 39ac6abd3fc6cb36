// A small consistently parameterized collection for the application tests (attribute
// transfer, morphing, PCA): the built-in samples, 3 members of ~1200 vertices (a and c closed,
// b with a hole), mapped with the consistent stage at low effort. Built once per process.
#pragma once

#include <vector>

#include "sample_collection.h"
#include "spherekit/mesh.h"

namespace spherekit::test {

struct MappedCollection {
  std::vector<samples::SampleMesh> members;
  std::vector<RowMat3d> maps;   ///< consistent sphere maps, one per member
  std::vector<RowMat3d> features;  ///< per member: landmark positions on the mesh (#landmarks by 3)
};

/// The collection (REQUIREs success; ~2-4 s on first use).
const MappedCollection& mapped_sample_collection();

}  // namespace spherekit::test
