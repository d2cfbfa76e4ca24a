#include "mesh_builder.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace hm {

namespace {
void note(BuildReport& r, const std::string& what) {
  r.ok = false;
  if (r.problems.size() < 20) r.problems.push_back(what);
}
}  // namespace

void canonical_cycle_into(const std::vector<int32_t>& cycle, std::vector<int32_t>* out, bool* reversed) {
  const size_t n = cycle.size();
  const size_t k = static_cast<size_t>(std::min_element(cycle.begin(), cycle.end()) - cycle.begin());
  const int32_t next = cycle[(k + 1) % n], prev = cycle[(k + n - 1) % n];
  out->resize(n);
  const bool rev = prev < next;
  for (size_t i = 0; i < n; ++i) (*out)[i] = rev ? cycle[(k + n - i) % n] : cycle[(k + i) % n];
  if (reversed) *reversed = rev;
}

std::vector<int32_t> canonical_cycle(const std::vector<int32_t>& cycle, bool* reversed) {
  std::vector<int32_t> out;
  canonical_cycle_into(cycle, &out, reversed);
  return out;
}

int32_t MeshBuilder::add_node(Vec3 p) {
  nodes_.push_back(p);
  return static_cast<int32_t>(nodes_.size() - 1);
}

namespace {

// FNV-1a over the ids of a canonical cycle.
uint64_t cycle_hash(const std::vector<int32_t>& key) {
  uint64_t h = 1469598103934665603ull;
  for (int32_t v : key) {
    h ^= static_cast<uint32_t>(v);
    h *= 1099511628211ull;
  }
  return h ^ (h >> 29);
}

// Whether the cycle at [c, c + n) has the canonical form `key` (the same cycle up to
// rotation and orientation): start at key[0], which is the cycle's smallest id.
bool same_cycle(const std::vector<int32_t>& key, const int32_t* c, size_t n) {
  if (n != key.size()) return false;
  const size_t k = static_cast<size_t>(std::find(c, c + n, key[0]) - c);
  if (k == n) return false;
  bool fwd = true, bwd = true;
  for (size_t i = 1; i < n && (fwd || bwd); ++i) {
    fwd = fwd && c[(k + i) % n] == key[i];
    bwd = bwd && c[(k + n - i) % n] == key[i];
  }
  return fwd || bwd;
}

}  // namespace

int32_t MeshBuilder::find_face(const std::vector<int32_t>& key, uint64_t hash) const {
  if (table_.empty()) return -1;
  const size_t mask = table_.size() - 1;
  for (size_t i = hash & mask;; i = (i + 1) & mask) {
    const int32_t f = table_[i];
    if (f < 0) return -1;
    if (face_hash_[f] == hash && same_cycle(key, face_nodes_.data() + face_ptr_[f], face_ptr_[f + 1] - face_ptr_[f]))
      return f;
  }
}

void MeshBuilder::reserve(size_t more_cells, size_t more_faces, size_t more_face_nodes) {
  const size_t cells = cells_.size() + more_cells, faces = faces_.size() + more_faces;
  cells_.reserve(cells);
  cell_ptr_.reserve(cells + 1);
  cell_faces_.reserve(cell_faces_.size() + 2 * more_faces);
  faces_.reserve(faces);
  face_hash_.reserve(faces);
  face_ptr_.reserve(faces + 1);
  face_nodes_.reserve(face_nodes_.size() + more_face_nodes);
  grow_table(faces);
}

void MeshBuilder::grow_table(size_t faces) {
  if (2 * faces <= table_.size()) return;  // load factor <= 1/2
  size_t size = std::max<size_t>(1024, table_.size());
  while (2 * faces > size) size *= 2;
  std::vector<int32_t> bigger(size, -1);
  const size_t mask = bigger.size() - 1;
  for (int32_t g : table_) {
    if (g < 0) continue;
    size_t i = face_hash_[g] & mask;
    while (bigger[i] >= 0) i = (i + 1) & mask;
    bigger[i] = g;
  }
  table_.swap(bigger);
}

void MeshBuilder::insert_face(int32_t f, uint64_t hash) {
  grow_table(faces_.size() + 1);
  const size_t mask = table_.size() - 1;
  size_t i = hash & mask;
  while (table_[i] >= 0) i = (i + 1) & mask;
  table_[i] = f;
}

bool MeshBuilder::clean_cycle(const CellFace& cf, int32_t cell) {
  // Drop repeated consecutive nodes (a conformity snap can merge two vertices).
  std::vector<int32_t>& cyc = cyc_;
  cyc.clear();
  for (int32_t v : cf.nodes)
    if (cyc.empty() || cyc.back() != v) cyc.push_back(v);
  while (cyc.size() > 1 && cyc.front() == cyc.back()) cyc.pop_back();
  sorted_.assign(cyc.begin(), cyc.end());
  std::sort(sorted_.begin(), sorted_.end());
  if (cyc.size() >= 3 && std::adjacent_find(sorted_.begin(), sorted_.end()) == sorted_.end()) return true;
  ++report_.degenerate_faces;
  std::ostringstream os;
  os << "cell " << cell << ": degenerate face with " << cyc.size() << " nodes";
  note(report_, os.str());
  return false;
}

int32_t MeshBuilder::new_face(int32_t cell, int32_t patch, const uint64_t* hash) {
  const int32_t f = static_cast<int32_t>(faces_.size());
  if (hash) insert_face(f, *hash);
  face_hash_.push_back(hash ? *hash : 0);
  face_nodes_.insert(face_nodes_.end(), cyc_.begin(), cyc_.end());
  face_ptr_.push_back(static_cast<int32_t>(face_nodes_.size()));
  FaceRecord rec;
  rec.owner = cell;
  rec.patch = patch;
  rec.uses = 1;
  faces_.push_back(rec);
  return f;
}

bool MeshBuilder::second_use(int32_t f, int32_t cell, bool reversed) {
  FaceRecord& rec = faces_[f];
  ++rec.uses;
  if (rec.uses > 2) {
    ++report_.overused_faces;
    std::ostringstream os;
    os << "face " << f << " named by a third cell " << cell;
    note(report_, os.str());
    return false;
  }
  // The stored cycle is the owner's orientation: the neighbour must name it reversed.
  bool stored_reversed = false;
  stored_.assign(face_nodes_.begin() + face_ptr_[f], face_nodes_.begin() + face_ptr_[f + 1]);
  canonical_cycle_into(stored_, &sorted_, &stored_reversed);
  if (sorted_ != key_) {
    ++report_.unmatched_faces;
    std::ostringstream os;
    os << "cell " << cell << " names face " << f << " by its id with other nodes";
    note(report_, os.str());
    --rec.uses;
    return false;
  }
  if (stored_reversed == reversed) {
    ++report_.misoriented_faces;
    std::ostringstream os;
    os << "face " << f << " named with the same orientation by cells " << rec.owner << " and " << cell;
    note(report_, os.str());
  }
  rec.neighbour = cell;
  return true;
}

int32_t MeshBuilder::add_cell(const std::vector<CellFace>& faces, const CellAttributes& attrs,
                              std::vector<int32_t>* face_ids) {
  const int32_t cell = static_cast<int32_t>(cells_.size());
  if (face_ids) face_ids->assign(faces.size(), -1);
  for (size_t i = 0; i < faces.size(); ++i) {
    const CellFace& cf = faces[i];
    if (!clean_cycle(cf, cell)) continue;
    bool reversed = false;
    canonical_cycle_into(cyc_, &key_, &reversed);
    int32_t f = -1;
    if (cf.known_face >= 0) {
      if (cf.known_face >= static_cast<int32_t>(faces_.size()) || !second_use(cf.known_face, cell, reversed)) continue;
      f = cf.known_face;
    } else if (cf.by_id_only) {
      f = new_face(cell, cf.patch, nullptr);
    } else {
      const uint64_t hash = cycle_hash(key_);
      f = find_face(key_, hash);
      if (f < 0) f = new_face(cell, cf.patch, &hash);
      else if (!second_use(f, cell, reversed)) continue;
    }
    cell_faces_.push_back(f);
    if (face_ids) (*face_ids)[i] = f;
  }
  cell_ptr_.push_back(static_cast<int32_t>(cell_faces_.size()));
  cells_.push_back(attrs);
  return cell;
}

PolyMesh MeshBuilder::finish(BuildReport* report) {
  PolyMesh m;
  // Compact nodes: keep only those referenced by a face, in their original order.
  std::vector<int32_t> new_id(nodes_.size(), -1);
  for (int32_t v : face_nodes_) new_id[v] = 0;
  m.nodes.reserve(nodes_.size());
  for (size_t i = 0; i < nodes_.size(); ++i) {
    if (new_id[i] == 0) {
      new_id[i] = static_cast<int32_t>(m.nodes.size());
      m.nodes.push_back(nodes_[i]);
    } else {
      ++report_.removed_unused_nodes;
    }
  }
  nodes_ = {};
  table_ = {};
  face_hash_ = {};
  m.face_node_ptr = std::move(face_ptr_);
  m.face_nodes = std::move(face_nodes_);
  for (int32_t& v : m.face_nodes) v = new_id[v];
  const size_t nf = faces_.size();
  m.face_owner.resize(nf);
  m.face_neighbour.resize(nf);
  m.face_patch.resize(nf);
  for (size_t f = 0; f < nf; ++f) {
    const FaceRecord& r = faces_[f];
    m.face_owner[f] = r.owner;
    m.face_neighbour[f] = r.neighbour;
    if (r.neighbour >= 0) {
      m.face_patch[f] = kInteriorFace;
    } else if (r.patch == kInteriorFace) {
      m.face_patch[f] = kUnmatchedFace;
      ++report_.unmatched_faces;
      std::ostringstream os;
      os << "face " << f << " of cell " << r.owner << " has no neighbour but is not a boundary face";
      note(report_, os.str());
    } else {
      m.face_patch[f] = r.patch;
    }
  }
  faces_ = {};
  m.cell_face_ptr = std::move(cell_ptr_);
  m.cell_faces = std::move(cell_faces_);
  const size_t nc = cells_.size();
  m.cell_region.resize(nc);
  m.cell_fv_center.resize(nc);
  m.cell_ijk.resize(nc);
  m.cell_perm.resize(nc);
  m.cell_porosity.resize(nc);
  m.cell_radial.resize(nc);
  for (size_t c = 0; c < nc; ++c) {
    m.cell_region[c] = cells_[c].region;
    m.cell_fv_center[c] = cells_[c].fv_center;
    m.cell_ijk[c] = cells_[c].ijk;
    m.cell_perm[c] = cells_[c].perm;
    m.cell_porosity[c] = cells_[c].porosity;
    m.cell_radial[c] = cells_[c].radial;
  }
  if (std::any_of(cells_.begin(), cells_.end(), [](const CellAttributes& a) { return a.pore_volume_mult != 1.0; })) {
    m.cell_pore_volume_mult.resize(nc);
    for (size_t c = 0; c < nc; ++c) m.cell_pore_volume_mult[c] = cells_[c].pore_volume_mult;
  }
  if (report) *report = report_;
  *this = MeshBuilder{};
  return m;
}

CsrReport check_csr_invariants(const PolyMesh& m) {
  CsrReport r;
  auto bad = [&](const std::string& s) {
    r.ok = false;
    if (r.problems.size() < 20) r.problems.push_back(s);
  };
  const int nf = m.n_faces(), nc = m.n_cells(), nn = m.n_nodes();
  if (m.face_node_ptr.size() != static_cast<size_t>(nf) + 1 || m.face_node_ptr.front() != 0)
    bad("face_node_ptr must have n_faces + 1 entries starting at 0");
  if (m.cell_face_ptr.size() != static_cast<size_t>(nc) + 1 || m.cell_face_ptr.front() != 0)
    bad("cell_face_ptr must have n_cells + 1 entries starting at 0");
  if (m.face_neighbour.size() != static_cast<size_t>(nf) || m.face_patch.size() != static_cast<size_t>(nf))
    bad("face_neighbour/face_patch sizes differ from n_faces");
  if (!m.face_trans_mult.empty() && m.face_trans_mult.size() != static_cast<size_t>(nf))
    bad("face_trans_mult is neither empty nor of size n_faces");
  for (size_t f = 0; f < m.face_trans_mult.size(); ++f)
    if (!(std::isfinite(m.face_trans_mult[f]) && m.face_trans_mult[f] >= 0)) {
      bad("face_trans_mult[" + std::to_string(f) + "] is not a finite value >= 0");
      break;
    }
  if (!m.cell_pore_volume_mult.empty() && m.cell_pore_volume_mult.size() != static_cast<size_t>(nc))
    bad("cell_pore_volume_mult is neither empty nor of size n_cells");
  for (size_t c = 0; c < m.cell_pore_volume_mult.size(); ++c)
    if (!(std::isfinite(m.cell_pore_volume_mult[c]) && m.cell_pore_volume_mult[c] > 0)) {
      bad("cell_pore_volume_mult[" + std::to_string(c) + "] is not a finite value > 0");
      break;
    }
  if (m.nnc_trans.size() != m.nnc_cells.size()) bad("nnc_trans and nnc_cells differ in size");
  for (size_t k = 0; k < m.nnc_cells.size(); ++k) {
    const auto [a, b] = m.nnc_cells[k];
    if (a < 0 || a >= nc || b < 0 || b >= nc || a == b) {
      bad("nnc_cells[" + std::to_string(k) + "] is not a pair of two distinct valid cells");
      break;
    }
    if (k < m.nnc_trans.size() && !(std::isfinite(m.nnc_trans[k]) && m.nnc_trans[k] >= 0)) {
      bad("nnc_trans[" + std::to_string(k) + "] is not a finite value >= 0");
      break;
    }
  }
  if (m.cell_fv_center.size() != static_cast<size_t>(nc) || m.cell_ijk.size() != static_cast<size_t>(nc) ||
      m.cell_perm.size() != static_cast<size_t>(nc) || m.cell_porosity.size() != static_cast<size_t>(nc) ||
      m.cell_radial.size() != static_cast<size_t>(nc))
    bad("per-cell arrays differ in size from n_cells");
  if (!r.ok) return r;
  if (m.face_node_ptr.back() != static_cast<int32_t>(m.face_nodes.size())) bad("face_node_ptr.back() != face_nodes.size()");
  if (m.cell_face_ptr.back() != static_cast<int32_t>(m.cell_faces.size())) bad("cell_face_ptr.back() != cell_faces.size()");
  if (!r.ok) return r;
  for (int f = 0; f < nf; ++f) {
    if (m.face_size(f) < 3) bad("face " + std::to_string(f) + " has fewer than 3 nodes");
    for (const int32_t* v = m.face_begin(f); v != m.face_end(f); ++v)
      if (*v < 0 || *v >= nn) bad("face " + std::to_string(f) + " has an out-of-range node id");
    if (m.face_owner[f] < 0 || m.face_owner[f] >= nc) bad("face " + std::to_string(f) + " has an invalid owner");
    if (m.face_neighbour[f] >= nc || m.face_neighbour[f] == m.face_owner[f])
      bad("face " + std::to_string(f) + " has an invalid neighbour");
    if ((m.face_neighbour[f] >= 0) != (m.face_patch[f] == kInteriorFace))
      bad("face " + std::to_string(f) + ": patch must be kInteriorFace exactly when it has a neighbour");
  }
  std::vector<int> seen(nf, 0);
  for (int c = 0; c < nc; ++c) {
    if (m.cell_face_ptr[c + 1] - m.cell_face_ptr[c] < 4) bad("cell " + std::to_string(c) + " has fewer than 4 faces");
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) {
      if (*f < 0 || *f >= nf) { bad("cell " + std::to_string(c) + " has an out-of-range face id"); continue; }
      if (m.face_owner[*f] != c && m.face_neighbour[*f] != c)
        bad("cell " + std::to_string(c) + " lists face " + std::to_string(*f) + " that is not its own");
      ++seen[*f];
    }
  }
  for (int f = 0; f < nf; ++f) {
    const int want = m.face_neighbour[f] >= 0 ? 2 : 1;
    if (seen[f] != want) bad("face " + std::to_string(f) + " listed by " + std::to_string(seen[f]) + " cells, expected " + std::to_string(want));
  }
  return r;
}


PolyMesh cells_as_mesh(const PolyMesh& mesh, const std::vector<char>& keep, std::vector<int32_t>* cell_of) {
  MeshBuilder b;
  std::vector<int32_t> node(mesh.n_nodes(), -1);
  std::vector<CellFace> faces;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    if (!keep[c]) continue;
    faces.clear();
    for (const int32_t* fp = mesh.cell_begin(c); fp != mesh.cell_end(c); ++fp) {
      CellFace f;
      for (const int32_t* v = mesh.face_begin(*fp); v != mesh.face_end(*fp); ++v) {
        if (node[*v] < 0) node[*v] = b.add_node(mesh.nodes[*v]);
        f.nodes.push_back(node[*v]);
      }
      if (mesh.face_owner[*fp] != c) std::reverse(f.nodes.begin(), f.nodes.end());
      const int32_t other = mesh.face_owner[*fp] == c ? mesh.face_neighbour[*fp] : mesh.face_owner[*fp];
      f.patch = other < 0 ? mesh.face_patch[*fp] : (keep[other] ? kInteriorFace : kOuterBoundary);
      faces.push_back(std::move(f));
    }
    CellAttributes at;
    at.region = mesh.cell_region[c];
    at.fv_center = mesh.cell_fv_center[c];
    at.ijk = mesh.cell_ijk[c];
    at.perm = mesh.cell_perm[c];
    at.porosity = mesh.cell_porosity[c];
    at.pore_volume_mult = mesh.cell_pore_volume_mult.empty() ? 1.0 : mesh.cell_pore_volume_mult[c];
    at.radial = mesh.cell_radial[c];
    b.add_cell(faces, at);
    cell_of->push_back(c);
  }
  BuildReport report;
  PolyMesh sub = b.finish(&report);
  sub.metric_scale = mesh.metric_scale;
  return sub;
}

}  // namespace hm
