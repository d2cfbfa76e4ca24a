// Python bindings (pybind11): `import hybridmesh` gives load_case / parse_case / build / check /
// export and the mesh's flat arrays as read-only numpy views. API: docs/python.md.
// The arrays are views into the C++ mesh (no copy); each keeps its Mesh object alive.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "exporters/eclipse/eclipse_deck.hpp"
#include "exporters/openfoam/openfoam_case.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "fvcheck/lib/quality.hpp"
#include "fvcheck/lib/report.hpp"
#include "fvcheck/lib/report_json.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/case/case.hpp"
#include "meshgen/core/cli.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "meshgen/pipeline/summary.hpp"

namespace py = pybind11;

namespace {

/// A built mesh with the case it came from; transmissibilities are computed on first use.
struct Mesh {
  hm::CaseSpec cs;
  hm::HybridMesh result;
  std::optional<hm::Transmissibilities> trans;

  const hm::Transmissibilities& transmissibilities() {
    if (!trans) trans = hm::compute_transmissibilities(result.mesh, result.geometry);
    return *trans;
  }
};

/// A read-only numpy view of `n` rows of `cols` values of T starting at `data`, owned by `owner`.
template <class T>
py::array view(const T* data, size_t n, size_t cols, py::handle owner) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(n)}, strides{static_cast<py::ssize_t>(cols * sizeof(T))};
  if (cols > 1) {
    shape.push_back(static_cast<py::ssize_t>(cols));
    strides.push_back(sizeof(T));
  }
  py::array a(py::dtype::of<T>(), shape, strides, data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}
template <class T>
py::array view(const std::vector<T>& v, py::handle owner) {
  return view(v.data(), v.size(), 1, owner);
}
py::array view(const std::vector<hm::Vec3>& v, py::handle owner) {
  static_assert(sizeof(hm::Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
  return view(reinterpret_cast<const double*>(v.data()), v.size(), 3, owner);
}
/// An optional per-face or per-cell factor of the mesh (empty: 1 everywhere) as n values.
py::array view_or_ones(const std::vector<double>& v, int n, py::handle owner) {
  if (!v.empty()) return view(v, owner);
  py::array_t<double> ones(static_cast<py::ssize_t>(n));
  std::fill(ones.mutable_data(), ones.mutable_data() + n, 1.0);
  return std::move(ones);
}

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(
      j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

/// The case with each well's end caps as meshed (auto may have fallen back to flat ends), in the
/// mesh's permeability frame (docs/anisotropy.md; volumes are the physical ones).
hm::CaseSpec case_as_meshed(const Mesh& m) {
  hm::CaseSpec cs = hm::scaled_case(m.cs, m.result.frame);
  for (const hm::WellBlock& b : m.result.blocks)
    cs.wells.at(b.well).end_caps = b.hemisphere_caps ? hm::EndCaps::Hemisphere : hm::EndCaps::Flat;
  return cs;
}

py::dict check_mesh(Mesh& m) {
  const hm::HybridMesh& r = m.result;
  hm::FvReport report = hm::run_fvcheck(r.mesh, hm::CheckOptions{}, r.cell_h_ref, &r.build_report);
  report.source = m.cs.name;
  if (report.structure.ok) {
    const hm::Transmissibilities& t = m.transmissibilities();
    report.transmissibility = hm::summarize_transmissibilities(t.face);
    report.transmissibility.negative_halves = t.negative;
  }
  return json_to_python(hm::report_json(report)).cast<py::dict>();
}

std::vector<std::string> export_mesh(Mesh& m, const std::string& out_dir, const std::vector<std::string>& formats) {
  const hm::HybridMesh& r = m.result;
  bool vtu = false, eclipse = false, openfoam = false;
  for (const std::string& f : formats) {
    if (f == "vtu") vtu = true;
    else if (f == "eclipse") eclipse = true;
    else if (f == "openfoam") openfoam = true;
    else throw hm::InputError("formats: unknown format '" + f + "' (expected vtu, eclipse or openfoam)");
  }
  if (const std::string why = hm::create_output_directory(out_dir); !why.empty()) throw hm::InputError(why);
  const std::string dir = out_dir + "/";
  std::vector<std::string> written;
  auto need = [](const hm::WriteStatus& st) {
    if (!st.ok) throw std::runtime_error("export: " + st.message);
  };
  if (vtu) {
    // The same file as meshgen's mesh.vtu: the mesh's own data, cavity, volume, h_ref, Q_S/Q_O/Q_P.
    need(hm::write_vtu(dir + "mesh.vtu", r.mesh,
                       hm::mesh_file_quality_arrays(r.mesh, r.geometry, r.cell_cavity, r.cell_h_ref)));
    written.push_back(dir + "mesh.vtu");
  }
  if (eclipse) {
    hm::EclipseDeckInfo info;
    // The deck's transmissibilities, as meshgen --export eclipse writes them and solver_demo solves with
    // (on a corner-point model's cells OPM's form; `transmissibilities` above stays the checker's).
    hm::Transmissibilities deck_trans =
        hm::compute_transmissibilities(r.mesh, r.geometry, hm::deck_transmissibility_options());
    hm::FlowDroppedConnections dropped;
    std::string no_layout;  // write_eclipse_deck below says why
    hm::drop_connections_flow_ignores(m.cs.reservoir, r.mesh, {}, &deck_trans, &dropped, &no_layout);
    need(hm::write_eclipse_deck(dir + "eclipse", m.cs, r.mesh, r.geometry, deck_trans, {}, &info));
    written.push_back(info.data_file);
  }
  if (openfoam) {
    hm::OpenFoamOptions of;
    for (const hm::WellSpec& w : m.cs.wells) of.well_names.push_back(w.name);
    of.n_wells = static_cast<int>(m.cs.wells.size());
    need(hm::write_openfoam_case(dir + "openfoam", r.mesh, of));
    written.push_back(dir + "openfoam/");
  }
  return written;
}

}  // namespace

PYBIND11_MODULE(hybridmesh, mod) {
  mod.doc() = "HybridMesh: 3D hybrid meshes (Cartesian reservoir + radial wells + power-diagram transition)";
  py::register_exception<hm::InputError>(mod, "InputError", PyExc_ValueError);

  py::class_<hm::CaseSpec>(mod, "Case", "A validated case file (docs/case-format.md).")
      .def_property_readonly("name", [](const hm::CaseSpec& c) { return c.name; })
      .def_property_readonly("x", [](const hm::CaseSpec& c) { return c.reservoir.x; }, "reservoir node x (m)")
      .def_property_readonly("y", [](const hm::CaseSpec& c) { return c.reservoir.y; }, "reservoir node y (m)")
      .def_property_readonly("z", [](const hm::CaseSpec& c) { return c.reservoir.z; }, "reservoir node depths (m)")
      .def_property_readonly("wells", [](const hm::CaseSpec& c) {
        py::list wells;
        for (const hm::WellSpec& w : c.wells) {
          py::dict d;
          d["name"] = w.name;
          d["radius"] = w.radius;
          d["drainage_radius"] = w.drainage_radius;
          d["bhp"] = w.bhp;
          d["rings"] = w.rings;
          d["sectors"] = w.sectors;
          d["segment_length"] = w.segment_length;
          std::vector<std::vector<double>> traj;
          for (const hm::Vec3& p : w.trajectory) traj.push_back({p.x, p.y, p.z});
          d["trajectory"] = traj;
          wells.append(d);
        }
        return wells;
      })
      .def_property_readonly("notes", [](const hm::CaseSpec& c) { return c.notes; },
                             "what reading the case changed (paths clipped, layers split, faces fitted ...)");

  mod.def("load_case", &hm::load_case, py::arg("path"),
          "Reads and validates a YAML case file; raises InputError('key.path: reason').");
  mod.def("parse_case", &hm::parse_case, py::arg("yaml_text"), py::arg("base_dir") = std::string(),
          "Same as load_case, from YAML text; base_dir: where relative paths (reservoir.grdecl) start.");

  py::class_<Mesh, std::shared_ptr<Mesh>>(mod, "Mesh", "A conforming hybrid mesh (docs/mesh-layout.md).")
      .def_property_readonly("n_nodes", [](const Mesh& m) { return m.result.mesh.n_nodes(); })
      .def_property_readonly("n_faces", [](const Mesh& m) { return m.result.mesh.n_faces(); })
      .def_property_readonly("n_cells", [](const Mesh& m) { return m.result.mesh.n_cells(); })
      .def_property_readonly("nodes", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.nodes, s); })
      .def_property_readonly("face_node_ptr", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.face_node_ptr, s); })
      .def_property_readonly("face_nodes", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.face_nodes, s); })
      .def_property_readonly("face_owner", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.face_owner, s); })
      .def_property_readonly("face_neighbour", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.face_neighbour, s); })
      .def_property_readonly("face_patch", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.face_patch, s); })
      .def_property_readonly(
          "face_trans_mult",
          [](py::object s) {
            const hm::PolyMesh& m = s.cast<Mesh&>().result.mesh;
            return view_or_ones(m.face_trans_mult, m.n_faces(), s);
          },
          "n_faces: the corner-point model's transmissibility multiplier of each face (1 where it has none)")
      .def_property_readonly("cell_face_ptr", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.cell_face_ptr, s); })
      .def_property_readonly("cell_faces", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.cell_faces, s); })
      .def_property_readonly("cell_region", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.cell_region, s); })
      .def_property_readonly("cell_ijk", [](py::object s) {
        const auto& v = s.cast<Mesh&>().result.mesh.cell_ijk;
        return view(v.empty() ? nullptr : v[0].data(), v.size(), 3, s);
      })
      .def_property_readonly("fv_centers", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.cell_fv_center, s); })
      .def_property_readonly("cell_centroids", [](py::object s) { return view(s.cast<Mesh&>().result.geometry.cell_centroid, s); })
      .def_property_readonly("volumes", [](py::object s) { return view(s.cast<Mesh&>().result.geometry.cell_volume, s); })
      .def_property_readonly("face_areas", [](py::object s) { return view(s.cast<Mesh&>().result.geometry.face_area, s); })
      .def_property_readonly("face_centroids", [](py::object s) { return view(s.cast<Mesh&>().result.geometry.face_centroid, s); })
      .def_property_readonly("permeability", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.cell_perm, s); })
      .def_property_readonly("porosity", [](py::object s) { return view(s.cast<Mesh&>().result.mesh.cell_porosity, s); })
      .def_property_readonly(
          "pore_volume_multiplier",
          [](py::object s) {
            const hm::PolyMesh& m = s.cast<Mesh&>().result.mesh;
            return view_or_ones(m.cell_pore_volume_mult, m.n_cells(), s);
          },
          "n_cells: the corner-point model's pore-volume multiplier of each cell (MULTPV, PORV; 1 where it has none)")
      .def_property_readonly(
          "nnc_cells",
          [](py::object s) {
            const auto& v = s.cast<Mesh&>().result.mesh.nnc_cells;
            return view(v.empty() ? nullptr : v[0].data(), v.size(), 2, s);
          },
          "(n_nncs, 2): the cells of each connection without a face (the model's NNC)")
      .def_property_readonly("nnc_transmissibilities",
                             [](py::object s) { return view(s.cast<Mesh&>().result.mesh.nnc_trans, s); },
                             "n_nncs: their transmissibilities (cP.rm3/day/bar)")
      .def_property_readonly("transmissibilities",
                             [](py::object s) { return view(s.cast<Mesh&>().transmissibilities().face, s); },
                             "n_faces: TPFA transmissibility (cP.rm3/day/bar); wellbore faces: connection factor")
      .def_property_readonly("half_transmissibilities_owner",
                             [](py::object s) { return view(s.cast<Mesh&>().transmissibilities().half_owner, s); })
      .def_property_readonly("half_transmissibilities_neighbour",
                             [](py::object s) { return view(s.cast<Mesh&>().transmissibilities().half_neighbour, s); })
      .def_property_readonly("total_volume", [](const Mesh& m) { return hm::total_volume(m.result.geometry); })
      .def_property_readonly("wellbore_hole_volume",
                             [](const Mesh& m) {
                               const hm::CaseSpec cs = case_as_meshed(m);
                               double v = 0;
                               for (const hm::WellBlock& b : m.result.blocks)
                                 v += hm::exact_wellbore_hole_volume(cs, b.well, b.sectors);
                               return v;
                             },
                             "exact volume of the wellbore holes, from the case and the sectors as meshed")
      .def_property_readonly("case", [](const Mesh& m) { return m.cs; })
      .def_property_readonly("notes", [](const Mesh& m) { return m.result.notes; })
      .def_property_readonly("builder_ok", [](const Mesh& m) { return m.result.build_report.ok; })
      .def("summary", [](const Mesh& m) { return json_to_python(hm::make_summary(m.cs, m.result)); },
           "The summary.json that meshgen writes, as a dict.");

  mod.def(
      "build",
      [](const hm::CaseSpec& cs, bool optimize, bool transition) {
        auto m = std::make_shared<Mesh>();
        m->cs = cs;
        hm::PipelineOptions opts;
        opts.optimize = optimize;
        opts.build_transition = transition;
        py::gil_scoped_release unlock;
        // As meshgen: mesh in the local frame (meshgen/pipeline/local_frame.hpp), then give the mesh and its
        // geometry back in the case's coordinates.
        const hm::Vec3 origin = hm::case_origin(cs);
        m->result = hm::build_hybrid_mesh_in_local_frame(m->cs, opts);
        hm::translate_mesh(m->result.mesh, origin);
        for (hm::Vec3& p : m->result.geometry.face_centroid) p += origin;
        for (hm::Vec3& p : m->result.geometry.cell_centroid) p += origin;
        return m;
      },
      py::arg("case"), py::arg("optimize") = true, py::arg("transition") = true,
      "Meshes the case (meshgen's job). Raises InputError for bad input, RuntimeError for a meshing failure.");
  mod.def("check", &check_mesh, py::arg("mesh"),
          "Runs fvcheck's checks; returns its JSON report as a dict (docs/fvcheck.md; report['ok']).");
  mod.def("export", &export_mesh, py::arg("mesh"), py::arg("out_dir"),
          py::arg("formats") = std::vector<std::string>{"vtu"},
          "Writes OUT_DIR/mesh.vtu, OUT_DIR/eclipse/NAME.DATA, OUT_DIR/openfoam/ for formats among "
          "'vtu', 'eclipse', 'openfoam'; returns the paths written.");
}
