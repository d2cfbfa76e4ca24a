// Assembles a PolyMesh from cells given as lists of oriented faces.
// Faces are deduplicated by node identity (the cyclic node sequence, not coordinates):
// the second cell that names a face must name it with the reversed cycle, which is
// exactly the conformity condition. Several grids (reservoir, wells, transition) add
// into one builder and so share nodes and faces.
#pragma once
#include <cstdint>
#include <map>  // not used here any more; kept for the files that took it from this header
#include <string>
#include <vector>

#include "polymesh.hpp"

namespace hm {

/// One face of a cell as handed to the builder: node ids ordered so that the
/// right-hand normal points OUT of the cell, and the patch it belongs to if it
/// turns out to be a boundary face (kInteriorFace = "must be shared").
struct CellFace {
  std::vector<int32_t> nodes;
  int32_t patch = kInteriorFace;
  /// A face added earlier by another cell, by its id (add_cell's face_ids): this cell is its
  /// second cell and names it reversed; no lookup by nodes. -1: looked up by its nodes.
  int32_t known_face = -1;
  /// A new face that no later cell looks up by its nodes (a boundary face, or one a later
  /// cell names by id): kept out of the lookup table.
  bool by_id_only = false;
};

/// Room to reserve in a MeshBuilder: cells, distinct faces, and nodes over those faces' cycles.
struct BuilderCapacity {
  size_t cells = 0, faces = 0, face_nodes = 0;
};

struct BuildReport {
  bool ok = true;
  int unmatched_faces = 0;      ///< faces declared interior that no second cell named
  int overused_faces = 0;       ///< faces named by a third cell
  int misoriented_faces = 0;    ///< second use with the same (not reversed) orientation
  int degenerate_faces = 0;     ///< fewer than 3 distinct nodes
  int removed_unused_nodes = 0; ///< nodes no face referenced (compacted away)
  std::vector<std::string> problems;  ///< first problems, human readable
};

class MeshBuilder {
 public:
  int32_t add_node(Vec3 p);
  Vec3 node(int32_t id) const { return nodes_[id]; }
  int32_t n_nodes() const { return static_cast<int32_t>(nodes_.size()); }
  /// Capacity for this many more cells, distinct faces and nodes over those faces' cycles: a
  /// large grid added in one go is then stored without regrowing its arrays.
  void reserve(size_t more_cells, size_t more_faces, size_t more_face_nodes);
  /// Adds a cell; returns its id. Faces must be closed and outward oriented. face_ids (if
  /// given): the id of each face, -1 where the face was refused (degenerate, overused).
  int32_t add_cell(const std::vector<CellFace>& faces, const CellAttributes& attrs,
                   std::vector<int32_t>* face_ids = nullptr);
  /// Finishes: compacts unused nodes, fixes patches, returns the mesh. The report says
  /// whether every face was used consistently; the mesh is returned either way so
  /// that a caller can inspect it. The builder's arrays move into the mesh: the builder
  /// is left empty (no second copy of a large mesh stays alive).
  PolyMesh finish(BuildReport* report);

 private:
  struct FaceRecord {
    int32_t owner = -1, neighbour = -1;
    int32_t patch = kInteriorFace;
    int uses = 0;
  };

  std::vector<Vec3> nodes_;
  std::vector<int32_t> face_ptr_{0};
  std::vector<int32_t> face_nodes_;
  std::vector<FaceRecord> faces_;
  // Face lookup by canonical cycle: an open-addressing hash table of face ids (-1: empty
  // slot), probed linearly; the key of face f is the canonical form of its stored cycle,
  // compared in place. face_hash_[f] keeps each face's hash for growing the table.
  int32_t find_face(const std::vector<int32_t>& key, uint64_t hash) const;
  void insert_face(int32_t f, uint64_t hash);
  void grow_table(size_t faces);  // the table for this many faces at load factor <= 1/2
  bool clean_cycle(const CellFace& cf, int32_t cell);  // the face's cycle into cyc_; false if degenerate
  int32_t new_face(int32_t cell, int32_t patch, const uint64_t* hash);  // cyc_ as a new face; hashed if hash
  bool second_use(int32_t f, int32_t cell, bool reversed);  // cell as f's neighbour (key_: its canonical cycle)
  std::vector<int32_t> table_;
  std::vector<uint64_t> face_hash_;
  std::vector<int32_t> cyc_, sorted_, key_, stored_;  // scratch of add_cell
  std::vector<int32_t> cell_ptr_{0};
  std::vector<int32_t> cell_faces_;
  std::vector<CellAttributes> cells_;
  BuildReport report_;
};

/// The cells with keep[c] as a mesh of their own: faces toward the other cells become boundary
/// faces (kOuterBoundary), the other attributes and metric_scale are kept; (*cell_of)[k] is the
/// whole mesh's cell of cell k. `mesh` must pass check_csr_invariants.
PolyMesh cells_as_mesh(const PolyMesh& mesh, const std::vector<char>& keep, std::vector<int32_t>* cell_of);

/// The canonical key of a face cycle: rotated to start at its smallest id, oriented so
/// that the second entry is the smaller neighbour. `reversed` tells whether the
/// orientation was flipped to get there.
std::vector<int32_t> canonical_cycle(const std::vector<int32_t>& cycle, bool* reversed);
/// The same into *out (no allocation once *out has the capacity).
void canonical_cycle_into(const std::vector<int32_t>& cycle, std::vector<int32_t>* out, bool* reversed);

/// Checks the CSR/ownership invariants listed in docs/mesh-layout.md.
CsrReport check_csr_invariants(const PolyMesh& mesh);

}  // namespace hm
