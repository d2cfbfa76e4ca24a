// Transition meshes around real well blocks, through the whole pipeline (reservoir grid,
// radial well blocks, cavity extraction, transition, assembly), before optimisation.
// Issue #3 acceptance criteria on vertical, deviated, horizontal, bent and merged wells.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include "meshgen/case/case.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/transition/transition_internal.hpp"

namespace hm {
namespace {

std::string case_yaml(const std::string& name, const std::string& wells,
                      const std::string& x = "[0, 20, 30, 36, 40, 44, 48, 52, 56, 60, 64, 70, 80, 100]") {
  return "name: " + name + R"(
reservoir:
  x: )" + x + R"(
  y: [0, 20, 30, 36, 40, 44, 48, 52, 56, 60, 64, 70, 80, 100]
  z: [0, 6, 10, 13.5, 17, 20.5, 24, 27.5, 31, 34.5, 38, 44, 50]
wells:
)" + wells + R"(
transition: {dilation: 1.5, optimize: false}
)";
}

std::string well(const std::string& name, const std::string& trajectory, double drainage = 4.0,
                 const std::string& end_caps = "flat") {
  return "  - name: " + name + "\n    trajectory: " + trajectory +
         "\n    radius: 0.1\n    drainage_radius: " + std::to_string(drainage) +
         "\n    rings: 4\n    sectors: 12\n    segment_length: 3.0\n    bhp: 150\n    end_caps: " + end_caps + "\n";
}

struct WellMetrics {
  int cells = 0, faces = 0, vertices = 0;
  int polygons = 0, polygons_not_once = 0, bad_boundary = 0, negative_volumes = 0;
  double max_closure = 0, volume_error = 0, max_planarity = 0, max_convexity = 0;
  double min_site_margin = 1e300, min_orth = 90, mean_orth = 0;
  int n_orth = 0, sites_outside = 0;
  double min_orth_reservoir = 90, min_orth_well = 90;  ///< transition faces toward reservoir / well cells
  double max_planarity_interior = 0;  ///< faces between two transition cells only
  int faces_below_80 = 0;             ///< transition-transition faces with Q_O < 80 degrees
  double max_circle_error = 0;        ///< max over polygons of (distance of a node to the fitted circle) / mean edge
  double max_polygon_planarity = 0;   ///< max over polygons of (node distance to the mean plane) / mean edge
};

// Transition cells: the same properties as on the synthetic cavities. The cavity volume is
// the volume enclosed by its constrained polygons (fan triangles around each polygon's
// node mean, as the geometry pass does), so "transition volume == cavity volume" says the
// cells fill the cavity exactly.
WellMetrics measure(const HybridMesh& hm) {
  WellMetrics mt;
  const PolyMesh& m = hm.mesh;
  const MeshGeometry& geo = hm.geometry;
  std::map<std::tuple<double, double, double>, int32_t> node_at;
  for (int v = 0; v < m.n_nodes(); ++v) node_at[{m.nodes[v].x, m.nodes[v].y, m.nodes[v].z}] = v;
  std::map<std::vector<int32_t>, int> face_of;  // sorted nodes -> face
  for (int f = 0; f < m.n_faces(); ++f) {
    std::vector<int32_t> key(m.face_begin(f), m.face_end(f));
    std::sort(key.begin(), key.end());
    face_of[key] = f;
  }
  const ReservoirGrid& g = hm.grid;
  for (int f = 0; f < m.n_faces(); ++f) {
    if (m.face_neighbour[f] >= 0) continue;
    if (is_wellbore_patch(m.face_patch[f])) continue;
    bool ok = false;
    if (m.face_patch[f] == kOuterBoundary)
      for (int axis = 0; axis < 3 && !ok; ++axis) {
        const std::vector<double>& c = axis == 0 ? g.x : axis == 1 ? g.y : g.z;
        for (double v : {c.front(), c.back()}) {
          bool all = true;
          for (const int32_t* n = m.face_begin(f); n != m.face_end(f); ++n) all = all && m.nodes[*n][axis] == v;
          ok = ok || all;
        }
      }
    if (!ok) ++mt.bad_boundary;
  }
  double cavity_volume = 0;
  for (const Cavity& cav : hm.cavities.cavities)
    for (const ConstrainedFace& q : cav.faces) {
      ++mt.polygons;
      std::vector<int32_t> key;
      Vec3 gq;
      for (int32_t v : q.nodes) {
        const Vec3 p = hm.cavity_node_coords[v];
        gq += p / static_cast<double>(q.nodes.size());
        auto it = node_at.find({p.x, p.y, p.z});
        key.push_back(it == node_at.end() ? -1 : it->second);
      }
      for (size_t i = 0; i < q.nodes.size(); ++i) {  // normal into the cavity: minus sign
        const Vec3 a = hm.cavity_node_coords[q.nodes[i]], b = hm.cavity_node_coords[q.nodes[(i + 1) % q.nodes.size()]];
        cavity_volume -= dot(gq, cross(a, b)) / 6.0;
      }
      const transition_detail::PolygonFrame fr = transition_detail::fit_polygon(q.nodes, hm.cavity_node_coords);
      mt.max_circle_error = std::max(mt.max_circle_error, fr.circle_error / fr.mean_edge);
      for (int32_t v : q.nodes)
        mt.max_polygon_planarity = std::max(mt.max_polygon_planarity,
                                            std::abs(dot(hm.cavity_node_coords[v] - gq, fr.normal)) / fr.mean_edge);
      std::sort(key.begin(), key.end());
      auto it = face_of.find(key);
      int transition_sides = 0;
      if (it != face_of.end()) {
        const int f = it->second;
        transition_sides += m.cell_region[m.face_owner[f]] == kTransition;
        transition_sides += m.face_neighbour[f] >= 0 && m.cell_region[m.face_neighbour[f]] == kTransition;
      }
      mt.polygons_not_once += transition_sides != 1;
    }
  double transition_volume = 0;
  std::set<int> tfaces, tnodes;
  double orth_sum = 0;
  for (int c = 0; c < m.n_cells(); ++c) {
    double asum = 0;
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) asum += norm(geo.face_area[*f]);
    mt.max_closure = std::max(mt.max_closure, norm(cell_area_sum(m, geo, c)) / asum);
    if (geo.cell_volume[c] <= 0) ++mt.negative_volumes;
    if (m.cell_region[c] != kTransition) continue;
    ++mt.cells;
    transition_volume += geo.cell_volume[c];
    const double h = hm.cell_h_ref[c];
    std::set<int32_t> cell_nodes;
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) cell_nodes.insert(m.face_begin(*f), m.face_end(*f));
    tnodes.insert(cell_nodes.begin(), cell_nodes.end());
    double margin = 1e300;
    for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
      const int f = *fp;
      tfaces.insert(f);
      const Vec3 n = normalized(m.face_sign(f, c) * geo.face_area[f]);
      const Vec3 x0 = geo.face_centroid[f];
      const int other_cell = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
      const bool interior = other_cell >= 0 && m.cell_region[other_cell] == kTransition;
      for (const int32_t* v = m.face_begin(f); v != m.face_end(f); ++v) {
        const double dist = std::abs(dot(m.nodes[*v] - x0, n)) / h;
        mt.max_planarity = std::max(mt.max_planarity, dist);
        if (interior) mt.max_planarity_interior = std::max(mt.max_planarity_interior, dist);
      }
      for (int32_t v : cell_nodes) mt.max_convexity = std::max(mt.max_convexity, dot(m.nodes[v] - x0, n) / h);
      margin = std::min(margin, -dot(m.cell_fv_center[c] - x0, n) / h);
      const int other = other_cell;
      if (other < 0) continue;
      const Vec3 d = m.cell_fv_center[other] - m.cell_fv_center[c];
      const double a = 90.0 - std::atan2(norm(cross(d, n)), std::abs(dot(d, n))) * 180.0 / M_PI;
      if (m.cell_region[other] == kReservoir) mt.min_orth_reservoir = std::min(mt.min_orth_reservoir, a);
      if (m.cell_region[other] == kWell) mt.min_orth_well = std::min(mt.min_orth_well, a);
      if (other > c && interior) {
        mt.min_orth = std::min(mt.min_orth, a);
        orth_sum += a;
        ++mt.n_orth;
        mt.faces_below_80 += a < 80;
      }
    }
    mt.min_site_margin = std::min(mt.min_site_margin, margin);
    mt.sites_outside += margin <= 0;
  }
  // A cavity reaching the reservoir boundary is open there: the transition cells' faces in the
  // boundary planes close it (outward from the cavity).
  for (int f = 0; f < hm.mesh.n_faces(); ++f) {
    if (hm.mesh.face_patch[f] != kOuterBoundary || hm.mesh.cell_region[hm.mesh.face_owner[f]] != kTransition) continue;
    Vec3 g;
    for (const int32_t* v = hm.mesh.face_begin(f); v != hm.mesh.face_end(f); ++v)
      g += hm.mesh.nodes[*v] / static_cast<double>(hm.mesh.face_size(f));
    for (int i = 0; i < hm.mesh.face_size(f); ++i) {
      const Vec3 a = hm.mesh.nodes[hm.mesh.face_begin(f)[i]],
                 b = hm.mesh.nodes[hm.mesh.face_begin(f)[(i + 1) % hm.mesh.face_size(f)]];
      cavity_volume += dot(g, cross(a, b)) / 6.0;
    }
  }
  mt.mean_orth = mt.n_orth ? orth_sum / mt.n_orth : 90;
  mt.volume_error = std::abs(transition_volume - cavity_volume) / cavity_volume;
  mt.faces = static_cast<int>(tfaces.size());
  mt.vertices = static_cast<int>(tnodes.size());
  return mt;
}

void run_case(const char* name, const CaseSpec& cs, int expected_cavities) {
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh hm = build_hybrid_mesh(cs, opts);
  const WellMetrics mt = measure(hm);
  int corrections = 0, hidden = 0, snapped = 0, ambiguous = 0, splits = 0;
  for (const TransitionReport& r : hm.transition_reports) {
    corrections += r.site_corrections, hidden += r.hidden_sites, snapped += r.snapped_vertices;
    ambiguous += r.ambiguous_vertices, splits += r.split_boxes;
    EXPECT_EQ(r.unmatched_external_faces, 0);
    EXPECT_EQ(r.missing_polygons, 0);
  }
  std::printf("[%s] cavities %zu polygons %d | cells %d faces %d vertices %d | corrections %d splits %d hidden %d "
              "snapped %d ambiguous %d | orth min %.4f mean %.4f (n %d) | planarity %.2e convexity %.2e "
              "site-margin %.2e (outside %d) | closure %.1e volume err %.1e | interior planarity %.2e, "
              "faces < 80 deg %d, orth toward reservoir min %.4f, toward well min %.4f | polygons: circle error %.1e, non-planarity %.1e\n",
              name, hm.cavities.cavities.size(), mt.polygons, mt.cells, mt.faces, mt.vertices, corrections, splits,
              hidden, snapped, ambiguous, mt.min_orth, mt.mean_orth, mt.n_orth, mt.max_planarity, mt.max_convexity,
              mt.min_site_margin, mt.sites_outside, mt.max_closure, mt.volume_error, mt.max_planarity_interior,
              mt.faces_below_80, mt.min_orth_reservoir, mt.min_orth_well, mt.max_circle_error, mt.max_polygon_planarity);
  for (const TransitionReport& r : hm.transition_reports) {
    std::printf("   stages: delaunay %.3f s, sites %.3f s (%d iterations), power %.3f s; shifts: identification %.2e m,"
                " snap %.2e m\n", r.seconds_delaunay, r.seconds_sites, r.correction_iterations, r.seconds_power,
                r.max_identification_shift, r.max_snap_shift);
    for (const std::string& n : r.notes) std::printf("   note: %s\n", n.c_str());
  }
  EXPECT_EQ(static_cast<int>(hm.cavities.cavities.size()), expected_cavities);
  EXPECT_TRUE(hm.build_report.ok);
  EXPECT_EQ(mt.bad_boundary, 0);
  EXPECT_EQ(mt.polygons_not_once, 0);
  EXPECT_EQ(mt.negative_volumes, 0);
  EXPECT_LT(mt.max_closure, 1e-9);
  EXPECT_LT(mt.volume_error, 1e-9);
  EXPECT_GT(mt.cells, 0);
  EXPECT_EQ(mt.sites_outside, 0);
  // Convex with planar faces, to within the non-co-circularity of the constrained polygons
  // (a power vertex identified with a polygon's node moves by up to that misfit; paper 5.7)
  // and the numerical-coincidence merge of power vertices (closer than 1e-9 of the cavity
  // diagonal): relative to the smallest cells that is up to ~1e-7 (measured 5e-8, three wells).
  const double tol = 1e-7 + 2.0 * mt.max_circle_error;
  EXPECT_LT(mt.max_convexity, tol);
  EXPECT_LT(mt.max_planarity_interior, tol);
  if (mt.max_circle_error < 1e-9) {  // co-circular polygons only: orthogonal to round-off
    EXPECT_GT(mt.min_orth, 90.0 - 1e-5);
  } else {
    EXPECT_GT(mt.mean_orth, 89.5);  // paper, before optimisation: mean 89.78
  }
}

void run(const char* name, const std::string& yaml, int expected_cavities) {
  run_case(name, parse_case(yaml), expected_cavities);
}

TEST(TransitionWells, Vertical) { run("vertical", case_yaml("vertical", well("V", "[[50, 50, 14], [50, 50, 36]]")), 1); }

TEST(TransitionWells, Deviated45) {
  run("deviated45", case_yaml("deviated45", well("D", "[[40, 50, 16], [56, 50, 32]]")), 1);
}

TEST(TransitionWells, Horizontal) {
  run("horizontal", case_yaml("horizontal", well("H", "[[33, 50, 25], [67, 50, 25]]")), 1);
}

TEST(TransitionWells, Bent) {
  run("bent", case_yaml("bent", well("B", "[[48, 50, 16], [48, 50, 26], [58, 50, 34]]")), 1);
}

TEST(TransitionWells, TwoMergedWells) {
  run("two merged", case_yaml("merged", well("A", "[[46, 50, 14], [46, 50, 36]]") + well("B", "[[55, 52, 14], [55, 52, 36]]")), 1);
}

// Hemispherical end caps (docs/architecture.md "End caps"): the caps' outer shells are constrained
// polygons like the cylinder's side, every run_case property holds.
TEST(TransitionWells, HemisphereCaps) {
  run("vertical, caps", case_yaml("vcaps", well("V", "[[50, 50, 14], [50, 50, 36]]", 4.0, "hemisphere")), 1);
  run("deviated45, caps", case_yaml("dcaps", well("D", "[[40, 50, 16], [56, 50, 32]]", 4.0, "hemisphere")), 1);
  run("bent, caps", case_yaml("bcaps", well("B", "[[48, 50, 16], [48, 50, 26], [58, 50, 34]]", 4.0, "hemisphere")), 1);
  run("two merged, caps",
      case_yaml("mcaps", well("A", "[[46, 50, 14], [46, 50, 36]]", 4.0, "hemisphere") +
                             well("B", "[[55, 52, 14], [55, 52, 36]]", 4.0, "hemisphere")),
      1);
  run_case("accuracy_vertical (caps)", load_case(std::string(HM_SOURCE_DIR) + "/examples/accuracy_vertical.yaml"), 1);
}

// Formerly a known limit (docs/transition.md): the horizontal case above with caps puts the caps'
// poles 4 m from 10 m reservoir cells; the site correction used to cycle there (12-28 pairs left
// between the reservoir polygons' sites and the cap's polar sites) and the mesher stopped. With the
// correction moving the site of a pair that can satisfy condition (6) (docs/transition.md) it
// meshes with its caps, on the first attempt, with every run_case property.
TEST(TransitionWells, HemisphereCapsNextToCoarseCellsMesh) {
  const CaseSpec cs = parse_case(case_yaml("hcaps", well("H", "[[33, 50, 25], [67, 50, 25]]", 4.0, "hemisphere")));
  run_case("horizontal, caps next to 10 m cells", cs, 1);
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh hm = build_hybrid_mesh(cs, opts);
  EXPECT_TRUE(hm.blocks.at(0).hemisphere_caps);
  for (const std::string& n : hm.notes)
    EXPECT_EQ(n.find("so that the transition mesh can be built"), std::string::npos) << n;  // no enlargement
}

// end_caps: auto (the default) keeps the caps where they can be meshed: the horizontal case next to
// coarse cells (which needed flat ends before) and a vertical well.
TEST(TransitionWells, AutoEndCapsKeepTheCapsWhereTheyMesh) {
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh h =
      build_hybrid_mesh(parse_case(case_yaml("hauto", well("H", "[[33, 50, 25], [67, 50, 25]]", 4.0, "auto"))), opts);
  EXPECT_TRUE(h.blocks.at(0).hemisphere_caps);
  for (const std::string& n : h.notes) EXPECT_EQ(n.find("closed with flat ends"), std::string::npos) << n;
  const HybridMesh v =
      build_hybrid_mesh(parse_case(case_yaml("vauto", well("V", "[[50, 50, 14], [50, 50, 36]]", 4.0, "auto"))), opts);
  EXPECT_TRUE(v.blocks.at(0).hemisphere_caps);
}

// end_caps: auto where the caps do not fit between an end and the reservoir boundary (the start
// 4.5 m below the top, R = 4 m: the cap would come within 0.5 m of it, the gap is 0.25 R = 1 m):
// flat ends, said in the notes, and the mesh has every run_case property. Where the caps fit,
// auto keeps them.
TEST(TransitionWells, AutoEndCapsFallBackToFlatEndsWhereCapsDoNotFit) {
  const CaseSpec cs = parse_case(case_yaml("vauto", well("V", "[[50, 50, 4.5], [50, 50, 36]]", 4.0, "auto")));
  run_case("vertical, auto caps near the top", cs, 1);
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh hm = build_hybrid_mesh(cs, opts);
  ASSERT_EQ(hm.blocks.size(), 1u);
  EXPECT_FALSE(hm.blocks[0].hemisphere_caps);
  bool said = false;
  for (const std::string& n : hm.notes)
    said = said || n.find("wells[0] (V): closed with flat ends (end_caps: auto): hemispherical caps do not fit") == 0;
  EXPECT_TRUE(said);
  const HybridMesh v =
      build_hybrid_mesh(parse_case(case_yaml("vauto", well("V", "[[50, 50, 14], [50, 50, 36]]", 4.0, "auto"))), opts);
  EXPECT_TRUE(v.blocks.at(0).hemisphere_caps);
}

// The paper's running example (examples/paper_single_well.yaml) and the three-well case
// (two cavities, one of them merged).
TEST(TransitionWells, PaperExample) {
  run_case("paper example", load_case(std::string(HM_SOURCE_DIR) + "/examples/paper_single_well.yaml"), 1);
}

TEST(TransitionWells, ThreeWells) {
  run_case("three wells", load_case(std::string(HM_SOURCE_DIR) + "/examples/three_wells.yaml"), 2);
}


// Tip sites (docs/transition.md "Tip sites"): the accuracy case's vertical well, with flat ends, has a cavity
// reaching 12 m beyond each end. Weight-0 sites grade the cells there; the mesh keeps every
// property of run_case (each polygon exactly one face, auto-centred sites, convex cells, exact
// volume), the free cells are exactly the transition cells with no constrained face, and their
// size grows with the distance from the tip.
TEST(TransitionWells, TipSitesGradeTheCellsBeyondTheEnds) {
  CaseSpec cs = load_case(std::string(HM_SOURCE_DIR) + "/examples/accuracy_vertical.yaml");
  cs.wells[0].end_caps = EndCaps::Flat;  // tip sites grade the cavity beyond flat ends
  run_case("tip sites", cs, 1);
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh hm = build_hybrid_mesh(cs, opts);
  int free_sites = 0;
  for (const TransitionReport& r : hm.transition_reports) free_sites += r.free_sites;
  EXPECT_GT(free_sites, 0);
  const PolyMesh& m = hm.mesh;
  const Vec3 top = cs.wells[0].trajectory.front(), bottom = cs.wells[0].trajectory.back();
  int free_cells = 0;
  double worst_ratio = 0;
  for (int c = 0; c < m.n_cells(); ++c) {
    if (m.cell_region[c] != kTransition) continue;
    bool constrained = false;
    Vec3 lo{1e300, 1e300, 1e300}, hi = -lo;
    for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
      const int32_t other = m.face_owner[*fp] == c ? m.face_neighbour[*fp] : m.face_owner[*fp];
      constrained = constrained || other < 0 || m.cell_region[other] != kTransition;
      for (const int32_t* v = m.face_begin(*fp); v != m.face_end(*fp); ++v)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], m.nodes[*v][k]), hi[k] = std::max(hi[k], m.nodes[*v][k]);
    }
    if (constrained) continue;
    ++free_cells;
    const Vec3 x = m.cell_fv_center[c];
    // Beyond an end plane (z is depth: the well runs from `top` down to `bottom`).
    EXPECT_TRUE(x.z < top.z || x.z > bottom.z) << "free cell " << c << " beside the well";
    EXPECT_GT(hm.cell_h_ref[c], 0.0);
    const double distance = std::min(norm(x - top), norm(x - bottom));
    worst_ratio = std::max(worst_ratio, norm(hi - lo) / distance);
  }
  EXPECT_EQ(free_cells, free_sites);
  std::printf("[tip sites] %d free cells, largest diameter / distance to the tip %.2f\n", free_cells, worst_ratio);
  EXPECT_LT(worst_ratio, 2.0);
}


// Recovery is per cavity (docs/architecture.md, "Refusals and recovery"): two wells in cavities of
// their own take, together, exactly the transition builds each takes alone, and each keeps the end
// caps it gets alone: a refusal in one cavity rebuilds nothing in the other.
TEST(TransitionWells, OnlyTheRefusedCavityIsRebuilt) {
  // The usual refined box, extended in x by a second refined region for the second well.
  auto two_region_case = [](const std::string& name, const std::string& wells) {
    return case_yaml(name, wells,
                     "[0, 20, 30, 36, 40, 44, 48, 52, 56, 60, 64, 70, 80, 100, 110, 116, 120, 124, 128, 132, 136, "
                     "140, 144, 150, 160, 180, 200]");
  };
  const std::string h = well("H", "[[33, 50, 25], [67, 50, 25]]", 4.0, "auto");
  const std::string v = well("V", "[[132, 50, 14], [132, 50, 36]]", 4.0, "auto");
  const HybridMesh h_alone = build_hybrid_mesh(parse_case(two_region_case("h_alone", h)));
  const HybridMesh v_alone = build_hybrid_mesh(parse_case(two_region_case("v_alone", v)));
  const HybridMesh both = build_hybrid_mesh(parse_case(two_region_case("h_and_v", h + v)));
  ASSERT_EQ(both.cavities.cavities.size(), 2u);
  EXPECT_EQ(both.transition_builds, h_alone.transition_builds + v_alone.transition_builds);
  EXPECT_EQ(both.blocks.at(0).hemisphere_caps, h_alone.blocks.at(0).hemisphere_caps);
  EXPECT_EQ(both.blocks.at(1).hemisphere_caps, v_alone.blocks.at(0).hemisphere_caps);
  EXPECT_TRUE(both.self_check.ok()) << both.self_check.message;
  std::printf("[ recovery  ] transition builds: H alone %d, V alone %d, H and V %d\n", h_alone.transition_builds,
              v_alone.transition_builds, both.transition_builds);
  // Before main's site-correction change (12e7bb2) both cavities were refused here (2 + 2 builds);
  // now neither is, and the case needs a new refused cavity to exercise the recovery.
  if (h_alone.transition_builds + v_alone.transition_builds == 2)
    GTEST_SKIP() << "no cavity is refused in this case any more: recovery not exercised";
}

}  // namespace
}  // namespace hm
