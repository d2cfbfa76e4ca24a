#include "vtu_mesh_arrays.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>

#include "meshgen/core/parallel.hpp"

namespace hm {

namespace {

// One per-cell field of PolyMesh: its array name, components, and how to get / set component d.
struct Field {
  const char* name;
  int components;
  bool integer;
  std::function<double(const PolyMesh&, size_t c, int d)> get;
  std::function<void(PolyMesh&, size_t c, int d, double v)> set;
  /// An optional field (null for the others): whether the mesh carries it (else it is not written), and
  /// how a mesh read back makes room for it (an absent one is not missing: the mesh has none).
  std::function<bool(const PolyMesh&)> carried = nullptr;
  std::function<void(PolyMesh&)> make_room = nullptr;
  bool positive = false;  ///< values must be > 0
};

double at(const Vec3& v, int d) { return d == 0 ? v.x : d == 1 ? v.y : v.z; }
void put(Vec3& v, int d, double x) { (d == 0 ? v.x : d == 1 ? v.y : v.z) = x; }

#define HM_RADIAL_INT(NAME, MEMBER)                                                                          \
  Field{NAME, 1, true, [](const PolyMesh& m, size_t c, int) { return double(m.cell_radial[c].MEMBER); }, \
        [](PolyMesh& m, size_t c, int, double v) { m.cell_radial[c].MEMBER = static_cast<int32_t>(v); }}
#define HM_RADIAL_REAL(NAME, MEMBER)                                                               \
  Field{NAME, 1, false, [](const PolyMesh& m, size_t c, int) { return m.cell_radial[c].MEMBER; }, \
        [](PolyMesh& m, size_t c, int, double v) { m.cell_radial[c].MEMBER = v; }}

const std::vector<Field>& fields() {
  static const std::vector<Field> f = {
      {"region", 1, true, [](const PolyMesh& m, size_t c, int) { return double(m.cell_region[c]); },
       [](PolyMesh& m, size_t c, int, double v) { m.cell_region[c] = static_cast<int32_t>(v); }},
      {"fv_center", 3, false, [](const PolyMesh& m, size_t c, int d) { return at(m.cell_fv_center[c], d); },
       [](PolyMesh& m, size_t c, int d, double v) { put(m.cell_fv_center[c], d, v); }},
      {"ijk", 3, true, [](const PolyMesh& m, size_t c, int d) { return double(m.cell_ijk[c][d]); },
       [](PolyMesh& m, size_t c, int d, double v) { m.cell_ijk[c][d] = static_cast<int32_t>(v); }},
      {"permeability", 3, false, [](const PolyMesh& m, size_t c, int d) { return at(m.cell_perm[c], d); },
       [](PolyMesh& m, size_t c, int d, double v) { put(m.cell_perm[c], d, v); }},
      {"porosity", 1, false, [](const PolyMesh& m, size_t c, int) { return m.cell_porosity[c]; },
       [](PolyMesh& m, size_t c, int, double v) { m.cell_porosity[c] = v; }},
      {"pore_volume_multiplier", 1, false, [](const PolyMesh& m, size_t c, int) { return m.cell_pore_volume_mult[c]; },
       [](PolyMesh& m, size_t c, int, double v) { m.cell_pore_volume_mult[c] = v; },
       [](const PolyMesh& m) { return !m.cell_pore_volume_mult.empty(); },
       [](PolyMesh& m) { m.cell_pore_volume_mult.assign(static_cast<size_t>(m.n_cells()), 1.0); }, true},
      HM_RADIAL_INT("radial_well", well),
      HM_RADIAL_INT("radial_ring", ring),
      HM_RADIAL_INT("radial_sector", sector),
      HM_RADIAL_INT("radial_segment", segment),
      HM_RADIAL_INT("radial_band", band),
      HM_RADIAL_REAL("radial_r_in", r_in),
      HM_RADIAL_REAL("radial_r_out", r_out),
      HM_RADIAL_REAL("radial_r_center", r_center),
      HM_RADIAL_REAL("radial_angle", angle),
      HM_RADIAL_REAL("radial_length", length),
      {"radial_cap_center", 3, false,
       [](const PolyMesh& m, size_t c, int d) { return at(m.cell_radial[c].cap_center, d); },
       [](PolyMesh& m, size_t c, int d, double v) { put(m.cell_radial[c].cap_center, d, v); }},
      // The mesh's permeability frame (one value per mesh, repeated per cell; docs/anisotropy.md).
      {"metric_scale", 3, false, [](const PolyMesh& m, size_t, int d) { return at(m.metric_scale, d); },
       [](PolyMesh& m, size_t, int d, double v) { put(m.metric_scale, d, v); }},
  };
  return f;
}

#undef HM_RADIAL_INT
#undef HM_RADIAL_REAL

}  // namespace

std::vector<VtuCellArray> mesh_cell_arrays(const PolyMesh& m) {
  const size_t nc = static_cast<size_t>(m.n_cells());
  std::vector<VtuCellArray> out;
  for (const Field& f : fields()) {
    if (f.carried && !f.carried(m)) continue;
    VtuCellArray a;
    a.name = f.name;
    a.components = f.components;
    a.integer = f.integer;
    const size_t n = nc * static_cast<size_t>(f.components);
    if (f.integer) a.ints.resize(n);
    else a.values.resize(n);
    parallel_ranges(static_cast<int64_t>(nc), [&](int64_t begin, int64_t end) {
      for (size_t c = static_cast<size_t>(begin); c < static_cast<size_t>(end); ++c)
        for (int d = 0; d < f.components; ++d) {
          const double v = f.get(m, c, d);
          const size_t i = c * static_cast<size_t>(f.components) + static_cast<size_t>(d);
          if (f.integer) a.ints[i] = static_cast<int32_t>(v);
          else a.values[i] = v;
        }
    });
    out.push_back(std::move(a));
  }
  return out;
}

bool is_mesh_array_name(const std::string& name) {
  for (const Field& f : fields())
    if (name == f.name) return true;
  return false;
}

bool RestoredArrays::has(const std::string& name) const {
  return is_mesh_array_name(name) && std::find(missing.begin(), missing.end(), name) == missing.end();
}

RestoredArrays restore_mesh_cell_arrays(const std::vector<VtuCellArray>& arrays, PolyMesh& m) {
  RestoredArrays r;
  const size_t nc = static_cast<size_t>(m.n_cells());
  for (const Field& f : fields()) {
    const auto it = std::find_if(arrays.begin(), arrays.end(), [&](const VtuCellArray& a) { return a.name == f.name; });
    if (it == arrays.end()) {
      if (!f.make_room) r.missing.push_back(f.name);
      continue;
    }
    const VtuCellArray& a = *it;
    // 1-component permeability (isotropic) is accepted for files written by other tools.
    const bool isotropic = std::string(f.name) == "permeability" && a.components == 1;
    if (a.components != f.components && !isotropic) {
      r.error = a.name + ": " + std::to_string(a.components) + " components, expected " + std::to_string(f.components);
      return r;
    }
    if (a.values.size() != nc * static_cast<size_t>(a.components)) {
      r.error = a.name + ": " + std::to_string(a.values.size()) + " values for " + std::to_string(nc) + " cells";
      return r;
    }
    // Cells in parallel (each writes its own cell), except metric_scale: every cell writes the
    // mesh's one value, the last cell's wins. The error names the first bad cell in cell order.
    if (f.make_room) f.make_room(m);
    const bool per_mesh = std::string(f.name) == "metric_scale";
    std::atomic<int64_t> first_bad{static_cast<int64_t>(nc)};
    auto restore = [&](int64_t b, int64_t e) {
      for (int64_t c = b; c < e; ++c)
        for (int d = 0; d < f.components; ++d) {
          const double v = a.values[static_cast<size_t>(c) * a.components + (isotropic ? 0 : d)];
          const bool ok = std::isfinite(v) && (!f.integer || (v == std::floor(v) && std::fabs(v) < 2147483647.0)) &&
                          (!f.positive || v > 0);
          if (!ok) {
            int64_t seen = first_bad.load();
            while (c < seen && !first_bad.compare_exchange_weak(seen, c)) {
            }
            return;
          }
          f.set(m, static_cast<size_t>(c), d, v);
        }
    };
    if (per_mesh) restore(0, static_cast<int64_t>(nc));
    else parallel_ranges(static_cast<int64_t>(nc), restore);
    if (first_bad.load() < static_cast<int64_t>(nc)) {
      r.error = a.name + ": cell " + std::to_string(first_bad.load()) + ": " +
                (f.integer ? "not a 32-bit integer" : f.positive ? "not a finite number > 0" : "not a finite number");
      return r;
    }
  }
  return r;
}

}  // namespace hm
