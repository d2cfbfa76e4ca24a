// Test helper: a well block alone as a PolyMesh (its faces' patches as the caller set them).
#pragma once
#include <gtest/gtest.h>

#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/grids/well_block.hpp"

namespace hm_test {

inline hm::PolyMesh assemble_block(const hm::WellBlock& block) {
  hm::MeshBuilder b;
  hm::add_well_block(block, b);
  hm::BuildReport rep;
  hm::PolyMesh m = b.finish(&rep);
  EXPECT_TRUE(rep.ok) << (rep.problems.empty() ? "" : rep.problems[0]);
  return m;
}

}  // namespace hm_test
