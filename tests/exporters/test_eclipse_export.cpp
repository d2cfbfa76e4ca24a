// Eclipse deck export: layout, connections, the numbers written, GRDECL, error statuses.
// (Running flow on the deck: test_flow_deck.cpp.)
#include <gtest/gtest.h>

#include <map>
#include <numeric>

#include "exporter_test_support.hpp"
#include "exporters/eclipse/eclipse_deck.hpp"

namespace {

using namespace hmtest;

hm::CaseSpec two_well_box() {
  hm::CaseSpec cs = box_case({0, 30, 50, 60, 70, 90, 120}, {0, 25, 45, 55, 65, 90}, {1000, 1005, 1012, 1020, 1030});
  cs.name = "deck_test";
  add_vertical_well(cs, "INJ", hm::WellType::Injector, 2, 2, 260, 0.1);
  add_vertical_well(cs, "PROD", hm::WellType::Producer, 4, 3, 150, 0.1);
  return cs;
}

struct Fixture {
  hm::CaseSpec cs = two_well_box();
  hm::PolyMesh mesh;
  hm::MeshGeometry geo;
  hm::Transmissibilities trans;
  Fixture() {
    hm::BuildReport rep;
    mesh = build_box_with_vertical_wells(cs, &rep);
    EXPECT_TRUE(rep.ok);
    geo = hm::compute_geometry(mesh);
    trans = hm::compute_transmissibilities(mesh, geo);
  }
};

// Values of an Eclipse array keyword in `text` (N*v expanded), empty if absent.
std::vector<double> eclipse_array(const std::string& text, const std::string& keyword) {
  std::istringstream in(text);
  std::string line;
  std::vector<double> out;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside) {
      inside = line == keyword;
      continue;
    }
    if (line.rfind("--", 0) == 0) continue;
    std::istringstream words(line);
    std::string w;
    while (words >> w) {
      if (w == "/") return out;
      const size_t star = w.find('*');
      if (star == std::string::npos) {
        out.push_back(std::stod(w));
      } else {
        const long n = std::stol(w.substr(0, star));
        out.insert(out.end(), n, std::stod(w.substr(star + 1)));
      }
    }
  }
  return out;
}

// Records of a record keyword (each record's words, up to its '/'), empty if absent.
std::vector<std::vector<std::string>> eclipse_records(const std::string& text, const std::string& keyword) {
  std::istringstream in(text);
  std::string line;
  std::vector<std::vector<std::string>> out;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside) {
      inside = line == keyword;
      continue;
    }
    if (line.rfind("--", 0) == 0) continue;
    if (line == "/") break;
    std::istringstream words(line);
    std::vector<std::string> rec;
    std::string w;
    while (words >> w && w != "/") rec.push_back(w);
    out.push_back(rec);
  }
  return out;
}

TEST(EclipseLayout, ReservoirCellsKeepIjkOthersAreThinBoxesInExtraColumns) {
  Fixture fx;
  hm::EclipseLayout L;
  std::string error;
  hm::EclipseDeckOptions opt;
  ASSERT_TRUE(hm::make_eclipse_layout(fx.cs.reservoir, fx.mesh, opt, &L, &error)) << error;
  EXPECT_EQ(L.nx, 6);
  EXPECT_EQ(L.ny, 5);
  EXPECT_EQ(L.nz, 4);
  ASSERT_GT(L.extra_columns, 0);
  EXPECT_EQ(L.deck_nx, L.nx + 1 + L.extra_columns);
  ASSERT_EQ(L.deck_cell.size(), static_cast<size_t>(L.n_deck_cells()));
  std::vector<int> used(L.n_deck_cells(), 0);
  for (int c = 0; c < fx.mesh.n_cells(); ++c) {
    const int32_t g = L.cell_deck_index[c];
    ASSERT_GE(g, 0);
    ++used[g];
    EXPECT_EQ(L.deck_cell[g], c);
    const auto ijk = L.deck_ijk(g);
    // Flow's depth is the mean of the corner depths: the FV centre's.
    EXPECT_NEAR(0.5 * (L.top[g] + L.bottom[g]), fx.mesh.cell_fv_center[c].z, 1e-12);
    if (fx.mesh.cell_region[c] == hm::kReservoir) {
      EXPECT_EQ(ijk[0], fx.mesh.cell_ijk[c][0]);
      EXPECT_EQ(ijk[1], fx.mesh.cell_ijk[c][1]);
      EXPECT_EQ(ijk[2], fx.mesh.cell_ijk[c][2]);
    } else {
      EXPECT_GE(ijk[0], L.nx + 1) << "cell " << c;  // beyond the separator column
      EXPECT_NEAR(L.bottom[g] - L.top[g], opt.thin_cell_thickness, 1e-12);
    }
  }
  for (int g = 0; g < L.n_deck_cells(); ++g) {
    EXPECT_LE(used[g], 1);
    if (L.deck_ijk(g)[0] == L.nx) {
      EXPECT_EQ(L.deck_cell[g], -1) << "separator column must be inactive";
    }
  }
  // Every column: depths non-decreasing (ZCORN), active boxes separated by a gap.
  for (int j = 0; j < L.ny; ++j)
    for (int i = 0; i < L.deck_nx; ++i) {
      double last_bottom = -1e300;
      for (int k = 0; k < L.nz; ++k) {
        const int g = i + L.deck_nx * (j + L.ny * k);
        ASSERT_LE(L.top[g], L.bottom[g]);
        ASSERT_LE(last_bottom, L.top[g]) << "column (" << i << "," << j << ") overlaps at k=" << k;
        if (L.deck_cell[g] >= 0 && i > L.nx && last_bottom > -1e300) {
          ASSERT_GE(L.top[g] - last_bottom, opt.thin_cell_thickness * (1 - 1e-9));
        }
        last_bottom = L.bottom[g];
      }
    }
  // No box of an extra column has an active lateral neighbour (it would touch it geometrically).
  for (int g = 0; g < L.n_deck_cells(); ++g) {
    const auto ijk = L.deck_ijk(g);
    if (L.deck_cell[g] < 0 || ijk[0] <= L.nx) continue;
    EXPECT_EQ(L.deck_cell[g - 1], -1);
    if (ijk[0] + 1 < L.deck_nx) {
      EXPECT_EQ(L.deck_cell[g + 1], -1);
    }
    if (ijk[1] + 1 < L.ny) {
      EXPECT_EQ(L.deck_cell[g + L.deck_nx], -1);
    }
    if (ijk[1] > 0) {
      EXPECT_EQ(L.deck_cell[g - L.deck_nx], -1);
    }
  }
  // 8 well cells per layer share one depth: at least 8 columns.
  int columns_used = 0;
  for (int j = 0; j < L.ny; ++j)
    for (int i = L.nx + 1; i < L.deck_nx; ++i) columns_used += L.deck_cell[i + L.deck_nx * j] >= 0;
  EXPECT_GE(columns_used, 8);
}

TEST(EclipseLayout, FewLayersForceMoreColumns) {
  // One layer: every extra column holds a single box.
  hm::CaseSpec cs = box_case({0, 30, 50, 60, 70, 90, 120}, {0, 25, 45, 55, 65, 90}, {1000, 1030});
  add_vertical_well(cs, "P", hm::WellType::Producer, 2, 2, 150, 0.1);
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  ASSERT_TRUE(rep.ok);
  hm::EclipseLayout L;
  std::string error;
  ASSERT_TRUE(hm::make_eclipse_layout(cs.reservoir, mesh, {}, &L, &error)) << error;
  // 4 well cells, one per column, columns on rows j = 0, 2, 4: two slabs (I = nx+2 and nx+4).
  EXPECT_EQ(L.extra_columns, 3);
  int placed = 0;
  for (int j = 0; j < L.ny; ++j)
    for (int i = L.nx + 1; i < L.deck_nx; ++i) placed += L.deck_cell[i + L.deck_nx * j] >= 0;
  EXPECT_EQ(placed, 4);
}

TEST(EclipseLayout, ReservoirCellAwayFromItsLatticeDepthIsAnError) {
  Fixture fx;
  hm::EclipseLayout L;
  std::string error;
  ASSERT_TRUE(hm::make_eclipse_layout(fx.cs.reservoir, fx.mesh, {}, &L, &error)) << error;
  int c = 0;
  while (fx.mesh.cell_region[c] != hm::kReservoir) ++c;
  fx.mesh.cell_fv_center[c].z += 0.5;
  EXPECT_FALSE(hm::make_eclipse_layout(fx.cs.reservoir, fx.mesh, {}, &L, &error));
  EXPECT_NE(error.find("cell " + std::to_string(c) + ": FV centre depth"), std::string::npos) << error;
  EXPECT_NE(error.find("is not the lattice cell centre depth"), std::string::npos) << error;
}

TEST(EclipseLayout, DuplicateOrOutOfRangeIjkIsAnError) {
  Fixture fx;
  hm::EclipseLayout L;
  std::string error;
  std::vector<int> res;
  for (int c = 0; c < fx.mesh.n_cells(); ++c)
    if (fx.mesh.cell_region[c] == hm::kReservoir) res.push_back(c);
  hm::PolyMesh dup = fx.mesh;
  dup.cell_ijk[res[1]] = dup.cell_ijk[res[0]];
  dup.cell_fv_center[res[1]].z = dup.cell_fv_center[res[0]].z;
  EXPECT_FALSE(hm::make_eclipse_layout(fx.cs.reservoir, dup, {}, &L, &error));
  EXPECT_NE(error.find("have the same (i,j,k)"), std::string::npos) << error;
  hm::PolyMesh out = fx.mesh;
  out.cell_ijk[res[0]][1] = 5;
  EXPECT_FALSE(hm::make_eclipse_layout(fx.cs.reservoir, out, {}, &L, &error));
  EXPECT_NE(error.find("is outside the 6x5x4 reservoir lattice"), std::string::npos) << error;
}

TEST(EclipseConnections, EveryInteriorFaceIsCarriedExactlyOnce) {
  Fixture fx;
  hm::EclipseLayout L;
  std::string error;
  ASSERT_TRUE(hm::make_eclipse_layout(fx.cs.reservoir, fx.mesh, {}, &L, &error)) << error;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(fx.mesh, L, fx.trans);
  double faces = 0;
  int interior = 0, res_pairs = 0;
  for (int f = 0; f < fx.mesh.n_faces(); ++f) {
    if (fx.mesh.face_neighbour[f] < 0) continue;
    ++interior;
    faces += fx.trans.face[f];
    res_pairs += fx.mesh.cell_region[fx.mesh.face_owner[f]] == hm::kReservoir &&
                 fx.mesh.cell_region[fx.mesh.face_neighbour[f]] == hm::kReservoir;
  }
  double carried = 0;
  int tran_entries = 0;
  for (const auto* v : {&conn.tranx, &conn.trany, &conn.tranz})
    for (double t : *v) {
      carried += t;
      tran_entries += t != 0;
    }
  for (const auto& r : conn.nnc) carried += r.t;
  EXPECT_NEAR(carried, faces, 1e-12 * faces);
  EXPECT_NEAR(conn.total, faces, 1e-12 * faces);
  EXPECT_EQ(conn.zero_faces, 0);
  EXPECT_EQ(conn.negative_faces, 0);
  // Lattice neighbours go to TRANX/Y/Z; everything touching a well cell is an NNC.
  EXPECT_EQ(tran_entries, res_pairs);
  EXPECT_EQ(static_cast<int>(conn.nnc.size()), interior - res_pairs);
  for (const auto& r : conn.nnc) {
    EXPECT_LT(r.a, r.b);
    const bool a_res = fx.mesh.cell_region[L.deck_cell[r.a]] == hm::kReservoir;
    const bool b_res = fx.mesh.cell_region[L.deck_cell[r.b]] == hm::kReservoir;
    EXPECT_FALSE(a_res && b_res);
  }
}

// Flow's rule (removeSmallNonCartesianTransmissibilities_): a pair of deck cells that are not logical
// neighbours whose summed T is below 1e-6 (or negative) is not connected; logical neighbours keep any
// T. drop_connections_flow_ignores zeroes exactly those pairs, all their faces.
TEST(EclipseConnections, PairsFlowLeavesOutAreZeroedAndNoOthers) {
  Fixture fx;
  hm::EclipseLayout L;
  std::string error;
  ASSERT_TRUE(hm::make_eclipse_layout(fx.cs.reservoir, fx.mesh, {}, &L, &error)) << error;
  // Interior faces by deck pair.
  std::map<std::pair<int32_t, int32_t>, std::vector<int32_t>> faces_of;
  for (int32_t f = 0; f < fx.mesh.n_faces(); ++f) {
    if (fx.mesh.face_neighbour[f] < 0) continue;
    const int32_t a = L.cell_deck_index[fx.mesh.face_owner[f]], b = L.cell_deck_index[fx.mesh.face_neighbour[f]];
    faces_of[{std::min(a, b), std::max(a, b)}].push_back(f);
  }
  std::vector<std::pair<int32_t, int32_t>> far, near;
  for (const auto& [pair, faces] : faces_of)
    (hm::flow_logical_neighbours(L, pair.first, pair.second) ? near : far).push_back(pair);
  ASSERT_GE(far.size(), 3u);
  ASSERT_GE(near.size(), 1u);
  hm::Transmissibilities t = fx.trans;
  auto set_pair = [&](std::pair<int32_t, int32_t> pair, double total) {
    const auto& faces = faces_of[pair];
    for (int32_t f : faces) t.face[f] = total / static_cast<double>(faces.size());
  };
  set_pair(far[0], 0.4 * hm::kFlowNncThreshold);   // dropped
  set_pair(far[1], -3.0);                          // dropped (flow's test is signed)
  set_pair(far[2], 2.0 * hm::kFlowNncThreshold);   // kept
  set_pair(near[0], 0.1 * hm::kFlowNncThreshold);  // kept: logical neighbours
  const hm::Transmissibilities before = t;
  EXPECT_EQ(hm::make_eclipse_connections(fx.mesh, L, t).below_flow_threshold, 1);
  const hm::FlowDroppedConnections d = hm::drop_connections_flow_ignores(fx.mesh, L, &t);
  EXPECT_EQ(d.pairs, 2);
  EXPECT_EQ(d.model_pairs, 0);
  EXPECT_NEAR(d.sum, 3.0 + 0.4 * hm::kFlowNncThreshold, 1e-12);
  for (int32_t f = 0; f < fx.mesh.n_faces(); ++f) {
    const int32_t a = L.cell_deck_index[fx.mesh.face_owner[f]];
    const int32_t b = fx.mesh.face_neighbour[f] < 0 ? -1 : L.cell_deck_index[fx.mesh.face_neighbour[f]];
    const std::pair<int32_t, int32_t> pair{std::min(a, b), std::max(a, b)};
    if (b >= 0 && (pair == far[0] || pair == far[1]))
      EXPECT_EQ(t.face[f], 0.0) << "face " << f;
    else
      EXPECT_EQ(t.face[f], before.face[f]) << "face " << f;
  }
  const hm::EclipseConnections after = hm::make_eclipse_connections(fx.mesh, L, t);
  EXPECT_EQ(after.below_flow_threshold, 0);
  EXPECT_EQ(after.negative_nnc, 0);
  // Applied twice, nothing more goes.
  EXPECT_EQ(hm::drop_connections_flow_ignores(fx.mesh, L, &t).pairs, 0);
}

TEST(EclipseDeck, WritesOurNumbersBitForBit) {
  Fixture fx;
  TempDir tmp("deck");
  hm::EclipseDeckInfo info;
  const hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, fx.geo, fx.trans, {}, &info);
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(list_files(tmp.path),
            (std::vector<std::string>{"DECK_TEST.DATA", "DECK_TEST_EDIT.INC", "DECK_TEST_GRID.GRDECL",
                                      "DECK_TEST_GRID.INC", "DECK_TEST_NNC.INC", "DECK_TEST_SCHEDULE.INC"}));
  EXPECT_EQ(info.data_file, (tmp.path / "DECK_TEST.DATA").string());
  const hm::EclipseLayout& L = info.layout;
  const std::string data = read_text(tmp.path / "DECK_TEST.DATA");
  EXPECT_NE(data.find("DIMENS\n" + std::to_string(L.deck_nx) + " 5 4 /"), std::string::npos);
  EXPECT_NE(data.find("PVTW\n200 1.0 1e-08 1 0.0 /"), std::string::npos) << data;
  EXPECT_NE(data.find("DENSITY\n1* 1000 1* /"), std::string::npos);

  // PORV = volume * porosity, exactly (shortest round-trip output).
  const std::string edit = read_text(tmp.path / "DECK_TEST_EDIT.INC");
  const std::vector<double> porv = eclipse_array(edit, "PORV");
  ASSERT_EQ(porv.size(), static_cast<size_t>(L.n_deck_cells()));
  for (int g = 0; g < L.n_deck_cells(); ++g) {
    const int32_t c = L.deck_cell[g];
    EXPECT_EQ(porv[g], c < 0 ? 0.0 : fx.geo.cell_volume[c] * fx.mesh.cell_porosity[c]) << g;
  }
  // TRANX/Y/Z and NNC: exactly the connections.
  const hm::EclipseConnections conn = hm::make_eclipse_connections(fx.mesh, L, fx.trans);
  EXPECT_EQ(eclipse_array(edit, "TRANX"), conn.tranx);
  EXPECT_EQ(eclipse_array(edit, "TRANY"), conn.trany);
  EXPECT_EQ(eclipse_array(edit, "TRANZ"), conn.tranz);
  const auto nnc = eclipse_records(read_text(tmp.path / "DECK_TEST_NNC.INC"), "NNC");
  ASSERT_EQ(nnc.size(), conn.nnc.size());
  EXPECT_EQ(info.nnc, static_cast<int>(conn.nnc.size()));
  for (size_t k = 0; k < nnc.size(); ++k) {
    ASSERT_EQ(nnc[k].size(), 7u);
    const auto a = L.deck_ijk(conn.nnc[k].a), b = L.deck_ijk(conn.nnc[k].b);
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(std::stoi(nnc[k][d]), a[d] + 1);
      EXPECT_EQ(std::stoi(nnc[k][3 + d]), b[d] + 1);
    }
    EXPECT_EQ(std::stod(nnc[k][6]), conn.nnc[k].t);
  }
  // COMPDAT: one record per wellbore cell, CF = the connection factor.
  const std::string sched = read_text(tmp.path / "DECK_TEST_SCHEDULE.INC");
  const auto compdat = eclipse_records(sched, "COMPDAT");
  const auto wells = hm::well_connection_factors(fx.mesh, fx.trans, 2);
  ASSERT_EQ(compdat.size(), wells[0].size() + wells[1].size());
  ASSERT_EQ(wells[0].size(), 16u);  // 4 cells around the hole x 4 layers
  size_t r = 0;
  for (int w = 0; w < 2; ++w)
    for (const auto& [cell, cf] : wells[w]) {
      const auto& rec = compdat[r++];
      ASSERT_EQ(rec.size(), 8u);
      EXPECT_EQ(rec[0], "'" + fx.cs.wells[w].name + "'");
      const auto ijk = L.deck_ijk(L.cell_deck_index[cell]);
      EXPECT_EQ(std::stoi(rec[1]), ijk[0] + 1);
      EXPECT_EQ(std::stoi(rec[2]), ijk[1] + 1);
      EXPECT_EQ(std::stoi(rec[3]), ijk[2] + 1);
      EXPECT_EQ(rec[4], rec[3]);
      EXPECT_EQ(rec[5], "'OPEN'");
      EXPECT_EQ(std::stod(rec[7]), cf);
    }
  const auto welspecs = eclipse_records(sched, "WELSPECS");
  ASSERT_EQ(welspecs.size(), 2u);
  EXPECT_EQ(std::stod(welspecs[0][4]), 1000.0);  // reference depth: first trajectory point
  EXPECT_NE(sched.find("WCONINJE\n'INJ' 'WATER' 'OPEN' 'BHP' 2* 260 /"), std::string::npos) << sched;
  EXPECT_NE(sched.find("WCONPROD\n'PROD' 'OPEN' 'BHP' 5* 150 /"), std::string::npos) << sched;

  // Grid include: ACTNUM marks exactly the mesh cells; ZCORN/COORD sizes.
  const std::string grid = read_text(tmp.path / "DECK_TEST_GRID.INC");
  const std::vector<double> actnum = eclipse_array(grid, "ACTNUM");
  ASSERT_EQ(actnum.size(), static_cast<size_t>(L.n_deck_cells()));
  EXPECT_EQ(std::accumulate(actnum.begin(), actnum.end(), 0.0), fx.mesh.n_cells());
  EXPECT_EQ(eclipse_array(grid, "ZCORN").size(), 8u * L.n_deck_cells());
  EXPECT_EQ(eclipse_array(grid, "COORD").size(), 6u * (L.deck_nx + 1) * (L.ny + 1));
}

TEST(EclipseDeck, BoxWithoutWellsIsThePlainLattice) {
  hm::CaseSpec cs = box_case({0, 10, 25, 45, 60}, {0, 12, 30, 50}, {1000, 1004, 1010, 1018});
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_mesh(cs, &rep);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  const hm::Transmissibilities trans = hm::compute_transmissibilities(mesh, geo);
  TempDir tmp("deck_box");
  hm::EclipseDeckInfo info;
  const hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), cs, mesh, geo, trans, {}, &info);
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(info.layout.extra_columns, 0);
  EXPECT_EQ(info.nnc, 0);
  EXPECT_EQ(info.tran_connections, 3 * 3 * 3 + 4 * 2 * 3 + 4 * 3 * 2);  // the lattice's interior faces
  const std::string data = read_text(tmp.path / "BOX.DATA");
  EXPECT_NE(data.find("DIMENS\n4 3 3 /"), std::string::npos);
  EXPECT_EQ(read_text(tmp.path / "BOX_NNC.INC").find("NNC\n"), std::string::npos);
  const std::string sched = read_text(tmp.path / "BOX_SCHEDULE.INC");
  EXPECT_EQ(sched.find("WELSPECS"), std::string::npos);
  EXPECT_EQ(sched.find("COMPDAT"), std::string::npos);
  // Logical neighbours carry the generic TPFA value of the lattice: A / (dx1/(2 k1) + dx2/(2 k2)).
  const std::vector<double> tranx = eclipse_array(read_text(tmp.path / "BOX_EDIT.INC"), "TRANX");
  ASSERT_EQ(tranx.size(), 36u);
  EXPECT_NEAR(tranx[0], hm::kDarcyMetric * 12 * 4 / (10 / (2 * 120.0) + 15 / (2 * 120.0)), 1e-12);
  EXPECT_EQ(tranx[3], 0.0);  // i = 4 has no +I neighbour
}

TEST(EclipseDeck, GrdeclIsTheStructuredReservoirAlone) {
  Fixture fx;
  TempDir tmp("grdecl");
  const std::string path = (tmp.path / "sub" / "R.GRDECL").string();
  const hm::WriteStatus st = hm::write_reservoir_grdecl(path, fx.cs.reservoir, fx.mesh);
  ASSERT_TRUE(st.ok) << st.message;
  const std::string text = read_text(path);
  EXPECT_NE(text.find("SPECGRID\n6 5 4 1 F /"), std::string::npos);
  const std::vector<double> actnum = eclipse_array(text, "ACTNUM");
  ASSERT_EQ(actnum.size(), 120u);
  int reservoir = 0;
  for (int c = 0; c < fx.mesh.n_cells(); ++c) reservoir += fx.mesh.cell_region[c] == hm::kReservoir;
  EXPECT_EQ(std::accumulate(actnum.begin(), actnum.end(), 0.0), reservoir);
  EXPECT_EQ(reservoir, 120 - 2 * 4 * 4);  // 4 cells per layer around each of the 2 holes
  const std::vector<double> zcorn = eclipse_array(text, "ZCORN");
  ASSERT_EQ(zcorn.size(), 8u * 120);
  EXPECT_EQ(zcorn.front(), 1000.0);
  EXPECT_EQ(zcorn.back(), 1030.0);
  EXPECT_EQ(eclipse_array(text, "COORD").size(), 6u * 7 * 6);
  EXPECT_EQ(eclipse_array(text, "PERMX"), std::vector<double>(120, 120.0));
  EXPECT_EQ(eclipse_array(text, "PORO"), std::vector<double>(120, 0.25));
}

TEST(EclipseDeckErrors, DirectoryUnderARegularFileFailsCleanly) {
  Fixture fx;
  TempDir tmp("deck_err");
  std::ofstream(tmp.path / "plain_file") << "x";
  const std::string dir = (tmp.path / "plain_file" / "deck").string();
  const hm::WriteStatus st = hm::write_eclipse_deck(dir, fx.cs, fx.mesh, fx.geo, fx.trans);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("write_eclipse_deck " + dir + ": cannot create directory"), std::string::npos)
      << st.message;
  EXPECT_EQ(list_files(tmp.path), std::vector<std::string>{"plain_file"});
}

TEST(EclipseDeckErrors, FailureOnTheLastRenameLeavesNoDeck) {
  Fixture fx;
  TempDir tmp("deck_err2");
  // NAME.DATA (renamed last) is a non-empty directory: every include was renamed before and must
  // be removed again.
  fs::create_directories(tmp.path / "DECK_TEST.DATA" / "keep");
  const hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, fx.geo, fx.trans);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("cannot rename"), std::string::npos) << st.message;
  EXPECT_TRUE(list_files(tmp.path).empty()) << list_files(tmp.path).front();
}

TEST(EclipseDeckErrors, InputProblemsAreReportedBeforeWriting) {
  Fixture fx;
  TempDir tmp("deck_err3");
  // A well with no wellbore face in the mesh.
  hm::CaseSpec three = fx.cs;
  add_vertical_well(three, "LOST", hm::WellType::Producer, 1, 1, 100, 0.1);
  hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), three, fx.mesh, fx.geo, fx.trans);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("well LOST has no cell on its wellbore"), std::string::npos) << st.message;
  // Transmissibilities of another mesh.
  hm::Transmissibilities other = fx.trans;
  other.face.pop_back();
  st = hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, fx.geo, other);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("sizes differ"), std::string::npos) << st.message;
  // An inverted cell.
  hm::MeshGeometry bad = fx.geo;
  bad.cell_volume[3] = -bad.cell_volume[3];
  st = hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, bad, fx.trans);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("cell 3 has a non-positive volume"), std::string::npos) << st.message;
  EXPECT_TRUE(list_files(tmp.path).empty());
  // The same inputs, unbroken, write.
  EXPECT_TRUE(hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, fx.geo, fx.trans).ok);
}

}  // namespace

namespace {

// The deck's SCHEDULE (issue 16): as typed, WTEST then `TSTEP first (end - first)` with end =
// max(1, kAsTypedRelaxationTimes relaxation times), first = clamp(tau / 2, 1 s, 1 day); a compressible case relaxes
// slower and runs longer; the steady
// deck for the optional flow options is two long steps; bad step lengths are refused.
std::string schedule_of(const std::string& data) { return data.substr(data.find("SCHEDULE")); }

TEST(EclipseDeck, AsTypedScheduleRunsAHundredRelaxationTimes) {
  Fixture fx;
  TempDir tmp("deck_sched");
  hm::EclipseDeckInfo info;
  ASSERT_TRUE(hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, fx.geo, fx.trans, {}, &info).ok);
  const std::string data = read_text(info.data_file);
  EXPECT_NE(data.find("-- Run: flow DECK_TEST.DATA"), std::string::npos);
  const double tau = hm::eclipse_relaxation_time_days(fx.cs, fx.mesh, fx.geo, info.well_connections);
  EXPECT_GT(tau, 0);
  EXPECT_EQ(info.relaxation_time_days, tau);
  EXPECT_EQ(info.end_days, std::max(1.0, hm::kAsTypedRelaxationTimes * tau));
  std::istringstream sched(schedule_of(data).substr(schedule_of(data).find("TSTEP\n") + 6));
  double first = 0, rest = 0;
  sched >> first >> rest;
  EXPECT_EQ(first, info.first_step_days);
  EXPECT_EQ(first, std::clamp(0.5 * tau, hm::kOneSecondInDays, 1.0));
  EXPECT_LT(first, 0.01);  // Cw = 1e-8: tau is far below a day
  EXPECT_NEAR(first + rest, info.end_days, 1e-12 * info.end_days);
  EXPECT_NE(schedule_of(data).find("WTEST\n'*' 0.01 'P' /\n/"), std::string::npos);

  // Compressible water: the relaxation time scales with Cw, the run with it (past the 1-day floor).
  hm::CaseSpec water = fx.cs;
  water.fluid.compressibility = 1e-3;
  hm::EclipseDeckInfo winfo;
  TempDir tmp2("deck_sched_water");
  ASSERT_TRUE(hm::write_eclipse_deck(tmp2.str(), water, fx.mesh, fx.geo, fx.trans, {}, &winfo).ok);
  EXPECT_NEAR(winfo.relaxation_time_days / info.relaxation_time_days, 1e-3 / std::max(fx.cs.fluid.compressibility, 1e-8),
              1e-9 * winfo.relaxation_time_days / info.relaxation_time_days);
  EXPECT_GT(winfo.end_days, 1.0);
  EXPECT_EQ(winfo.end_days, hm::kAsTypedRelaxationTimes * winfo.relaxation_time_days);
  EXPECT_EQ(winfo.first_step_days, std::clamp(0.5 * winfo.relaxation_time_days, hm::kOneSecondInDays, 1.0));
  EXPECT_GT(winfo.first_step_days, 0.01);

  // The steady deck: tstep_days in two report steps, no WTEST, the options in its first lines.
  hm::EclipseDeckOptions single;
  single.schedule = hm::EclipseSchedule::Steady;
  TempDir tmp3("deck_sched_single");
  hm::EclipseDeckInfo sinfo;
  ASSERT_TRUE(hm::write_eclipse_deck(tmp3.str(), fx.cs, fx.mesh, fx.geo, fx.trans, single, &sinfo).ok);
  const std::string sdata = read_text(sinfo.data_file);
  EXPECT_NE(schedule_of(sdata).find("TSTEP\n50000 50000 /"), std::string::npos) << schedule_of(sdata);
  EXPECT_EQ(schedule_of(sdata).find("WTEST"), std::string::npos);
  EXPECT_NE(sdata.find("-- Run: flow --enable-adaptive-time-stepping=false"), std::string::npos);
  EXPECT_EQ(sinfo.end_days, 1e5);

  // Refused step lengths.
  hm::EclipseDeckOptions bad;
  bad.first_step_days = -1;
  EXPECT_NE(hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, fx.geo, fx.trans, bad).message.find("first_step_days"),
            std::string::npos);
  bad.first_step_days = 0.01;
  bad.end_days = 0.005;  // before the end of the first step
  EXPECT_NE(hm::write_eclipse_deck(tmp.str(), fx.cs, fx.mesh, fx.geo, fx.trans, bad).message.find("end_days"),
            std::string::npos);
}

}  // namespace
