// Deck layout and deck connections (docs/export-eclipse.md, "Layout").
#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <sstream>
#include <utility>

#include "eclipse_deck.hpp"
#include "meshgen/case/grdecl.hpp"

namespace hm {

namespace {

std::string cell_text(int c) { return "cell " + std::to_string(c); }

}  // namespace

bool make_eclipse_layout(const ReservoirSpec& res, const PolyMesh& mesh, const EclipseDeckOptions& opt,
                         EclipseLayout* out, std::string* error) {
  EclipseLayout L;
  L.nx = static_cast<int>(res.x.size()) - 1;
  L.ny = static_cast<int>(res.y.size()) - 1;
  L.nz = static_cast<int>(res.z.size()) - 1;
  if (L.nx < 1 || L.ny < 1 || L.nz < 1) {
    *error = "reservoir lattice needs at least 2 nodes per axis";
    return false;
  }
  const int nc = mesh.n_cells();
  if (static_cast<int>(mesh.cell_fv_center.size()) != nc || static_cast<int>(mesh.cell_ijk.size()) != nc) {
    *error = "mesh per-cell arrays have the wrong size";
    return false;
  }
  if (!(opt.thin_cell_thickness > 0) || !(opt.extra_column_width > 0)) {
    *error = "thin_cell_thickness and extra_column_width must be > 0";
    return false;
  }
  const double h = opt.thin_cell_thickness;

  // Reservoir cells keep (i,j,k); everything else goes to the extra columns.
  std::vector<int32_t> res_cell(static_cast<size_t>(L.nx) * L.ny * L.nz, -1);
  std::vector<int32_t> extra;
  for (int c = 0; c < nc; ++c) {
    const auto& ijk = mesh.cell_ijk[c];
    if (mesh.cell_region[c] != kReservoir || ijk[0] < 0) {
      extra.push_back(c);
      continue;
    }
    if (ijk[0] >= L.nx || ijk[1] < 0 || ijk[1] >= L.ny || ijk[2] < 0 || ijk[2] >= L.nz) {
      *error = cell_text(c) + ": (i,j,k) = (" + std::to_string(ijk[0]) + "," + std::to_string(ijk[1]) + "," +
               std::to_string(ijk[2]) + ") is outside the " + std::to_string(L.nx) + "x" + std::to_string(L.ny) +
               "x" + std::to_string(L.nz) + " reservoir lattice";
      return false;
    }
    const size_t r = ijk[0] + static_cast<size_t>(L.nx) * (ijk[1] + static_cast<size_t>(L.ny) * ijk[2]);
    if (res_cell[r] >= 0) {
      *error = cell_text(c) + " and " + cell_text(res_cell[r]) + " have the same (i,j,k)";
      return false;
    }
    // Flow takes a reservoir cell's depth from its corner points: the FV centre must be there
    // (a corner-point model's cell: the mean of its 8 ZCORN depths, as OPM's cell depth).
    double zc = 0.5 * (res.z[ijk[2]] + res.z[ijk[2] + 1]);
    if (res.corner_point) {
      zc = 0;
      for (int q = 0; q < 8; ++q) zc += corner_depth(*res.corner_point, ijk[0] + L.nx * (ijk[1] + L.ny * ijk[2]), q);
      zc /= 8;
    }
    if (std::abs(mesh.cell_fv_center[c].z - zc) > 1e-9 * (std::abs(zc) + 1.0)) {
      std::ostringstream s;
      s.precision(17);
      s << cell_text(c) << ": FV centre depth " << mesh.cell_fv_center[c].z << " is not the lattice cell centre depth "
        << zc;
      *error = s.str();
      return false;
    }
    res_cell[r] = c;
  }

  // A corner-point model: its columns are the model's (COORD/ZCORN as OPM read them); the near-well
  // cells go to extra columns beyond its +x side as in a rectilinear grid (docs/export-eclipse.md,
  // "A corner-point model").
  L.corner_point = static_cast<bool>(res.corner_point);
  // Pack the extra cells by depth: a min-heap of open columns keyed by their current bottom. Cells
  // come in increasing depth, so if the column with the shallowest bottom cannot take a cell, no
  // open column can, and a new one is opened (greedy interval colouring: the fewest columns).
  std::vector<std::pair<double, int32_t>> by_depth;
  by_depth.reserve(extra.size());
  for (int32_t c : extra) {
    const double z = mesh.cell_fv_center[c].z;
    if (!std::isfinite(z)) {
      *error = cell_text(c) + ": FV centre is not finite";
      return false;
    }
    by_depth.push_back({z, c});
  }
  std::sort(by_depth.begin(), by_depth.end());
  struct Column {
    std::vector<int32_t> cells;
    double bottom = 0;
  };
  std::vector<Column> columns;
  using Key = std::pair<double, int>;  // (bottom, column)
  std::priority_queue<Key, std::vector<Key>, std::greater<Key>> open;
  for (const auto& [z, c] : by_depth) {
    const double top = z - 0.5 * h;
    int col = -1;
    // A gap of one thickness between boxes keeps them from touching (no geometric face).
    if (!open.empty() && open.top().first + h <= top) {
      col = open.top().second;
      open.pop();
    } else {
      col = static_cast<int>(columns.size());
      columns.push_back({});
    }
    columns[col].cells.push_back(c);
    columns[col].bottom = z + 0.5 * h;
    if (static_cast<int>(columns[col].cells.size()) < L.nz) open.push({columns[col].bottom, col});
  }
  // Extra columns sit on every other i and every other j: two thin boxes of neighbouring columns
  // that overlap in depth would get a geometric (fault-like) connection from flow that no EDIT
  // keyword removes; columns with an inactive column between them never touch.
  const int rows = (L.ny + 1) / 2;
  const int slabs = columns.empty() ? 0 : static_cast<int>((columns.size() + rows - 1) / rows);
  L.extra_columns = slabs == 0 ? 0 : 2 * slabs - 1;
  L.deck_nx = L.extra_columns == 0 ? L.nx : L.nx + 1 + L.extra_columns;
  const size_t nd = static_cast<size_t>(L.deck_nx) * L.ny * L.nz;
  L.deck_cell.assign(nd, -1);
  L.top.assign(nd, 0.0);
  L.bottom.assign(nd, 0.0);
  L.cell_deck_index.assign(nc, -1);
  auto deck_index = [&](int i, int j, int k) { return i + static_cast<size_t>(L.deck_nx) * (j + static_cast<size_t>(L.ny) * k); };
  // Reservoir and separator columns follow the lattice.
  const int lattice_columns = L.extra_columns == 0 ? L.nx : L.nx + 1;
  for (int k = 0; k < L.nz; ++k)
    for (int j = 0; j < L.ny; ++j)
      for (int i = 0; i < lattice_columns; ++i) {
        const size_t g = deck_index(i, j, k);
        L.top[g] = res.z[k];
        L.bottom[g] = res.z[k + 1];
        if (res.corner_point && i < L.nx) {  // the model cell's depth range (information only)
          const int mc = i + L.nx * (j + L.ny * k);
          L.top[g] = L.bottom[g] = corner_depth(*res.corner_point, mc, 0);
          for (int q = 0; q < 8; ++q) {
            L.top[g] = std::min(L.top[g], corner_depth(*res.corner_point, mc, q));
            L.bottom[g] = std::max(L.bottom[g], corner_depth(*res.corner_point, mc, q));
          }
        }
        if (i < L.nx) {
          const int32_t c = res_cell[i + static_cast<size_t>(L.nx) * (j + static_cast<size_t>(L.ny) * k)];
          L.deck_cell[g] = c;
          if (c >= 0) L.cell_deck_index[c] = static_cast<int32_t>(g);
        }
      }
  // Extra columns: column m is (i, j) = (nx + 1 + 2 (m / rows), 2 (m % rows)), its cells in k order;
  // unused slots (and the inactive columns in between) are zero-thickness boxes at the last bottom
  // (or at the reservoir top).
  for (int i = L.nx + 1; i < L.deck_nx; ++i)
    for (int j = 0; j < L.ny; ++j) {
      const int m = (i - L.nx - 1) % 2 == 0 && j % 2 == 0 ? (i - L.nx - 1) / 2 * rows + j / 2 : -1;
      double last = res.z.front();
      for (int k = 0; k < L.nz; ++k) {
        const size_t g = deck_index(i, j, k);
        if (m >= 0 && m < static_cast<int>(columns.size()) && k < static_cast<int>(columns[m].cells.size())) {
          const int32_t c = columns[m].cells[k];
          const double z = mesh.cell_fv_center[c].z;
          L.top[g] = z - 0.5 * h;
          L.bottom[g] = z + 0.5 * h;
          last = L.bottom[g];
          L.deck_cell[g] = c;
          L.cell_deck_index[c] = static_cast<int32_t>(g);
        } else {
          L.top[g] = last;
          L.bottom[g] = last;
        }
      }
    }

  L.pillar_x.assign(res.x.begin(), res.x.end());
  // The extra pillars are vertical, beyond the model's last x (a corner-point model's pillars may
  // lean out further than its cells' corners).
  double x_end = res.x.back();
  if (res.corner_point)
    for (size_t p = 0; p + 5 < res.corner_point->coord.size(); p += 6)
      x_end = std::max({x_end, res.corner_point->coord[p], res.corner_point->coord[p + 3]});
  if (L.extra_columns > 0)
    for (int m = 1; m <= 1 + L.extra_columns; ++m) L.pillar_x.push_back(x_end + m * opt.extra_column_width);
  L.pillar_y.assign(res.y.begin(), res.y.end());
  double zmin = res.z.front(), zmax = res.z.back();
  for (size_t g = 0; g < nd; ++g) {
    zmin = std::min(zmin, L.top[g]);
    zmax = std::max(zmax, L.bottom[g]);
  }
  L.pillar_top = zmin - 1.0;
  L.pillar_bottom = zmax + 1.0;
  *out = std::move(L);
  return true;
}

EclipseConnections make_eclipse_connections(const PolyMesh& mesh, const EclipseLayout& L,
                                            const Transmissibilities& trans) {
  EclipseConnections out;
  const size_t nd = static_cast<size_t>(L.n_deck_cells());
  out.tranx.assign(nd, 0.0);
  out.trany.assign(nd, 0.0);
  out.tranz.assign(nd, 0.0);
  std::vector<EclipseConnections::Nnc> raw;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int32_t o = mesh.face_owner[f], n = mesh.face_neighbour[f];
    if (n < 0) continue;
    const double t = trans.face[f];
    if (t == 0) {
      ++out.zero_faces;
      continue;
    }
    if (!(t > 0)) ++out.negative_faces;
    out.total += t;
    int32_t a = L.cell_deck_index[o], b = L.cell_deck_index[n];
    if (a > b) std::swap(a, b);
    const bool both_reservoir = mesh.cell_region[o] == kReservoir && mesh.cell_region[n] == kReservoir &&
                                mesh.cell_ijk[o][0] >= 0 && mesh.cell_ijk[n][0] >= 0;
    if (both_reservoir) {
      const auto ia = L.deck_ijk(a), ib = L.deck_ijk(b);
      const int d0 = ib[0] - ia[0], d1 = ib[1] - ia[1], d2 = ib[2] - ia[2];
      if (d0 == 1 && d1 == 0 && d2 == 0) { out.tranx[a] += t; continue; }
      if (d0 == 0 && d1 == 1 && d2 == 0) { out.trany[a] += t; continue; }
      if (d0 == 0 && d1 == 0 && d2 == 1) { out.tranz[a] += t; continue; }
    }
    raw.push_back({a, b, t});
  }
  // Connections without a face (a model's NNC) are NNC records too; a pair that also shares faces
  // gets one record, their sum, as flow adds a deck NNC to its own connection of the pair.
  for (int k = 0; k < mesh.n_nncs(); ++k) {
    const double t = trans.nnc[k];
    if (t == 0) continue;
    out.total += t;
    int32_t a = L.cell_deck_index[mesh.nnc_cells[k][0]], b = L.cell_deck_index[mesh.nnc_cells[k][1]];
    if (a > b) std::swap(a, b);
    raw.push_back({a, b, t});
  }
  std::sort(raw.begin(), raw.end(), [](const auto& x, const auto& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  for (const auto& r : raw) {
    if (!out.nnc.empty() && out.nnc.back().a == r.a && out.nnc.back().b == r.b)
      out.nnc.back().t += r.t;
    else
      out.nnc.push_back(r);
  }
  for (const auto& r : out.nnc) {
    if (flow_logical_neighbours(L, r.a, r.b)) continue;
    if (std::abs(r.t) < kFlowNncThreshold) {
      ++out.below_flow_threshold;
      out.below_flow_threshold_sum += std::abs(r.t);
    } else if (!(r.t > 0)) {
      if (out.negative_nnc++ == 0) out.first_negative_nnc = r;
    }
  }
  return out;
}

bool flow_logical_neighbours(const EclipseLayout& L, int32_t a, int32_t b) {
  const int32_t d = std::abs(b - a);
  return d == 1 || d == L.deck_nx || d == L.deck_nx * L.ny;
}

FlowDroppedConnections drop_connections_flow_ignores(const PolyMesh& mesh, const EclipseLayout& L,
                                                     Transmissibilities* trans) {
  // Every face and NNC joining deck cells that are not logical neighbours, by deck pair: its T is
  // face[index] (index >= 0) or nnc[-1 - index].
  struct Link {
    int32_t a, b, index;
  };
  std::vector<Link> links;
  auto add = [&](int32_t c0, int32_t c1, int32_t index) {
    const int32_t a = L.cell_deck_index[c0], b = L.cell_deck_index[c1];
    if (!flow_logical_neighbours(L, a, b)) links.push_back({std::min(a, b), std::max(a, b), index});
  };
  for (int32_t f = 0; f < mesh.n_faces(); ++f)
    if (mesh.face_neighbour[f] >= 0 && trans->face[f] != 0) add(mesh.face_owner[f], mesh.face_neighbour[f], f);
  for (int32_t i = 0; i < mesh.n_nncs(); ++i)
    if (trans->nnc[i] != 0) add(mesh.nnc_cells[i][0], mesh.nnc_cells[i][1], -1 - i);
  std::sort(links.begin(), links.end(), [](const Link& x, const Link& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  auto t_of = [&](const Link& l) -> double& { return l.index >= 0 ? trans->face[l.index] : trans->nnc[-1 - l.index]; };
  FlowDroppedConnections out;
  for (size_t begin = 0, end = 0; begin < links.size(); begin = end) {
    double t = 0;
    for (end = begin; end < links.size() && links[end].a == links[begin].a && links[end].b == links[begin].b; ++end)
      t += t_of(links[end]);
    // Flow's test is signed: a negative pair is dropped too (write_eclipse_deck refuses those first).
    if (!(t < kFlowNncThreshold)) continue;
    ++out.pairs;
    out.sum += std::abs(t);
    const int32_t c0 = L.deck_cell[links[begin].a], c1 = L.deck_cell[links[begin].b];
    if (mesh.cell_region[c0] == kReservoir && mesh.cell_region[c1] == kReservoir) ++out.model_pairs;
    for (size_t k = begin; k < end; ++k) t_of(links[k]) = 0;
  }
  return out;
}

std::string describe(const FlowDroppedConnections& d) {
  std::ostringstream s;
  s << d.pairs << " connections between cells that are not logical neighbours have T < " << kFlowNncThreshold
    << " cP.rm3/day/bar (" << d.model_pairs << " of them between model cells, sum " << d.sum
    << "): not connected, as OPM Flow does";
  return s.str();
}

bool drop_connections_flow_ignores(const ReservoirSpec& reservoir, const PolyMesh& mesh,
                                   const EclipseDeckOptions& options, Transmissibilities* trans,
                                   FlowDroppedConnections* dropped, std::string* error) {
  EclipseLayout layout;
  if (!make_eclipse_layout(reservoir, mesh, options, &layout, error)) return false;
  const FlowDroppedConnections d = drop_connections_flow_ignores(mesh, layout, trans);
  if (dropped) *dropped = d;
  return true;
}

}  // namespace hm
