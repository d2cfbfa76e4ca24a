// consumer CASE.yaml: meshes a case through the installed HybridMesh package and checks the mesh:
// the builder matched every face, fvcheck's conformity holds, and the total volume is the box
// minus the exact wellbore holes (relative 1e-9). Exit 0 when all hold, 1 otherwise, 2 bad input.
#include <cmath>
#include <cstdio>
#include <exception>

#include "fvcheck/lib/checks.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer CASE.yaml\n");
    return 2;
  }
  try {
    hm::CaseSpec cs = hm::load_case(argv[1]);
    const hm::HybridMesh h = hm::build_hybrid_mesh(cs);
    const auto& r = cs.reservoir;
    const double box = (r.x.back() - r.x.front()) * (r.y.back() - r.y.front()) * (r.z.back() - r.z.front());
    double holes = 0;
    for (const hm::WellBlock& b : h.blocks) {
      cs.wells[b.well].end_caps = b.hemisphere_caps ? hm::EndCaps::Hemisphere : hm::EndCaps::Flat;  // as meshed
      holes += hm::exact_wellbore_hole_volume(cs, b.well, b.sectors);
    }
    const double expected = box - holes, volume = hm::total_volume(h.geometry);
    const double rel = std::abs(volume - expected) / expected;
    const hm::CheckResult conformity = hm::check_conformity(h.mesh, h.geometry);
    std::printf("consumer: %s: %d cells, volume %.9g m3, box minus wellbore holes %.9g m3 (rel. %.1e), "
                "builder %s, conformity %s\n",
                cs.name.c_str(), h.mesh.n_cells(), volume, expected, rel, h.build_report.ok ? "ok" : "FAILED",
                conformity.ok() ? "ok" : "FAILED");
    return rel < 1e-9 && h.build_report.ok && conformity.ok() ? 0 : 1;
  } catch (const hm::InputError& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: meshing failed: %s\n", e.what());
    return 1;
  }
}
