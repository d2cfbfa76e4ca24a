// Layers split near the wells for the permeability frame (docs/anisotropy.md, "Layers near the
// wells"). With kv/kh < 1 the frame stretches the reservoir's layers by (kh/kv)^1/3: next to the
// well the scaled cells are several times taller than wide, the one row of
// transition cells between the block and such a wall cannot follow the well's logarithmic field,
// and the near-well error is set there. Splitting the layers within reach of the wells (whole
// layers: a cell split only beside the cavity would meet its unsplit neighbour along a face that
// is not K-orthogonal) brings the scaled cells near the wells back to about as tall as wide.
#pragma once
#include "meshgen/case/case.hpp"

namespace hm {

/// Reservoir cells within this many times a well's cavity reach (dilation x drainage radius) of its
/// trajectory decide the split (the Gabriel repair may grow the cavity beyond the dilation).
constexpr double kLayerSplitReach = 2.0;
/// At most this many children per layer.
constexpr int kMaxLayerChildren = 16;

/// Children per layer for the case's permeability frame: a layer within reach of a well whose
/// cells there are, in the scaled frame, taller than `reservoir.near_well_layer_aspect` x the
/// narrowest of their scaled lateral widths is split into that many equal layers. All 1 for an
/// identity frame (metric: euclidean, isotropic rock), a corner-point model (split by load_case with
/// frame_layer_children, meshgen/case/corner_point_fault_steps.hpp) or no wells.
std::vector<int> near_well_layer_children(const CaseSpec& cs);

/// The case with those layers split: reservoir.z gets the children's planes, per-cell rock is
/// repeated in every child, and a well whose reach holds a split layer gets its segment_length
/// lowered so that no segment spans more than the thinnest of them vertically (its block's
/// stations then follow the layers). Notes what it did in cs.notes. Called by load_case, and by
/// whatever changes a case's permeability or grid afterwards (the accuracy study's levels).
void split_layers_near_wells(CaseSpec& cs);

}  // namespace hm
