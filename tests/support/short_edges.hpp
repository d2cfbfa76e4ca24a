// Test helper shared by several suites: the edges of transition cells shorter than a fraction of
// their cell's reference length (h_ref of Q_S), counted once per cell and face.
#pragma once

#include "meshgen/core/geometry.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace hm::test {

inline int transition_edges_shorter_than(const HybridMesh& h, double fraction_of_h) {
  int count = 0;
  for (int c = 0; c < h.mesh.n_cells(); ++c) {
    if (h.mesh.cell_region[c] != kTransition) continue;
    for (const int32_t* f = h.mesh.cell_begin(c); f != h.mesh.cell_end(c); ++f) {
      const int k = h.mesh.face_size(*f);
      const int32_t* v = h.mesh.face_begin(*f);
      for (int i = 0; i < k; ++i)
        count += norm(h.mesh.nodes[v[i]] - h.mesh.nodes[v[(i + 1) % k]]) < fraction_of_h * h.cell_h_ref[c];
    }
  }
  return count;
}

}  // namespace hm::test
