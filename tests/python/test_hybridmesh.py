"""Tests of the Python module hybridmesh (meshgen/python, docs/python.md); run by ctest (Python/unittest).

Needs build/python on sys.path (ctest sets PYTHONPATH) and HM_SOURCE_DIR (the repository root).
"""
import os
import tempfile
import unittest

import numpy as np

import hybridmesh

ROOT = os.environ.get("HM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
README_CASE = os.path.join(ROOT, "examples", "readme_example.yaml")


def read_text(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


class BuiltMesh(unittest.TestCase):
    """One mesh of the README's example, shared by the tests of this class."""

    @classmethod
    def setUpClass(cls):
        cls.case = hybridmesh.load_case(README_CASE)
        cls.mesh = hybridmesh.build(cls.case)

    def test_case_fields(self):
        self.assertEqual(self.case.name, "my_case")
        self.assertEqual(len(self.case.wells), 1)
        self.assertEqual(self.case.wells[0]["name"], "P1")
        self.assertEqual(len(self.case.wells[0]["trajectory"]), 3)
        # The defaults (docs/case-format.md), as meshed; nothing fitted or clipped in a box.
        self.assertEqual((self.case.wells[0]["rings"], self.case.wells[0]["sectors"]), (6, 12))
        self.assertEqual(self.case.wells[0]["segment_length"], 4.0)
        self.assertIsInstance(self.case.notes, list)

    def test_csr_faces_and_cells(self):
        m = self.mesh
        fp, fn = m.face_node_ptr, m.face_nodes
        self.assertEqual(fp.shape, (m.n_faces + 1,))
        self.assertEqual(fp[0], 0)
        self.assertEqual(fp[-1], len(fn))
        self.assertTrue(np.all(np.diff(fp) >= 3))
        self.assertTrue(np.all((fn >= 0) & (fn < m.n_nodes)))
        cp, cf = m.cell_face_ptr, m.cell_faces
        self.assertEqual(cp.shape, (m.n_cells + 1,))
        self.assertEqual(cp[-1], len(cf))
        # Every face is listed by its owner and, if interior, its neighbour: exactly once each.
        interior = m.face_neighbour >= 0
        listed = np.bincount(cf, minlength=m.n_faces)
        np.testing.assert_array_equal(listed, 1 + interior.astype(np.int64))
        np.testing.assert_array_equal(m.face_patch == -1, interior)
        np.testing.assert_array_equal(m.face_trans_mult, np.ones(m.n_faces))  # a box case: no multipliers
        np.testing.assert_array_equal(m.pore_volume_multiplier, np.ones(m.n_cells))
        cell_of_entry = np.repeat(np.arange(m.n_cells), np.diff(cp))
        is_owner = m.face_owner[cf] == cell_of_entry
        is_neighbour = m.face_neighbour[cf] == cell_of_entry
        self.assertTrue(np.all(is_owner ^ is_neighbour))

    def test_shapes(self):
        m = self.mesh
        self.assertEqual(m.nodes.shape, (m.n_nodes, 3))
        self.assertEqual(m.fv_centers.shape, (m.n_cells, 3))
        self.assertEqual(m.cell_centroids.shape, (m.n_cells, 3))
        self.assertEqual(m.face_areas.shape, (m.n_faces, 3))
        self.assertEqual(m.cell_ijk.shape, (m.n_cells, 3))
        self.assertEqual(m.volumes.shape, (m.n_cells,))
        self.assertEqual(m.transmissibilities.shape, (m.n_faces,))
        self.assertEqual(set(np.unique(m.cell_region)), {0, 1, 2})

    def test_volume_is_box_minus_wellbore_hole(self):
        m = self.mesh
        x, y, z = self.case.x, self.case.y, self.case.z
        box = (x[-1] - x[0]) * (y[-1] - y[0]) * (z[-1] - z[0])
        expected = box - m.wellbore_hole_volume
        self.assertGreater(m.wellbore_hole_volume, 0)
        self.assertTrue(np.all(m.volumes > 0))
        self.assertAlmostEqual(m.volumes.sum() / expected, 1.0, delta=1e-9)
        self.assertAlmostEqual(m.total_volume / expected, 1.0, delta=1e-9)

    def test_closure(self):
        # Sum of outward area vectors of every cell is zero (relative to the cell's total face area).
        m = self.mesh
        cp, cf = m.cell_face_ptr, m.cell_faces
        cell_of_entry = np.repeat(np.arange(m.n_cells), np.diff(cp))
        sign = np.where(m.face_owner[cf] == cell_of_entry, 1.0, -1.0)
        vec = m.face_areas[cf] * sign[:, None]
        total = np.zeros((m.n_cells, 3))
        np.add.at(total, cell_of_entry, vec)
        area = np.zeros(m.n_cells)
        np.add.at(area, cell_of_entry, np.linalg.norm(m.face_areas[cf], axis=1))
        self.assertLess(np.max(np.linalg.norm(total, axis=1) / area), 1e-9)

    def test_check_and_transmissibilities(self):
        report = hybridmesh.check(self.mesh)
        self.assertTrue(report["ok"], report)
        # checkMesh's skewness (docs/fvcheck.md): the example passes checkMesh, no face above its 4.
        skew = report["quality"]["openfoam_skewness"]
        self.assertEqual(skew["faces_above_checkmesh_limit"], 0, skew)
        self.assertGreater(skew["max"], 0.0)
        self.assertLess(skew["max"], skew["checkmesh_limit"])
        # checkMesh's non-orthogonality: below 90 degrees on every face (no error), the average of
        # mostly orthogonal faces a few degrees.
        ortho = report["quality"]["openfoam_nonorthogonality_deg"]
        self.assertEqual(ortho["error_faces"], 0, ortho)
        self.assertGreater(ortho["max"], ortho["average"])
        self.assertLess(ortho["max"], 90.0)
        self.assertLess(ortho["average"], 10.0)
        t = self.mesh.transmissibilities
        interior = self.mesh.face_neighbour >= 0
        self.assertTrue(np.all(np.isfinite(t)))
        self.assertTrue(np.all(t[interior] > 0))
        wellbore = self.mesh.face_patch >= 1
        self.assertTrue(np.all(t[wellbore] > 0))

    def test_arrays_are_read_only_views(self):
        with self.assertRaises(ValueError):
            self.mesh.volumes[0] = 1.0
        v = self.mesh.volumes
        self.assertFalse(v.flags.owndata)

    def test_export(self):
        with tempfile.TemporaryDirectory() as d:
            written = hybridmesh.export(self.mesh, d, ["vtu", "eclipse"])
            self.assertIn(os.path.join(d, "mesh.vtu"), written)
            with open(os.path.join(d, "mesh.vtu"), "rb") as f:
                self.assertIn(b"<VTKFile", f.read(200))
            self.assertTrue(os.path.isfile(os.path.join(d, "eclipse", "MY_CASE.DATA")))
            with self.assertRaises(hybridmesh.InputError):
                hybridmesh.export(self.mesh, d, ["stl"])

    def test_summary(self):
        s = self.mesh.summary()
        self.assertEqual(sum(s["cells"][k] for k in ("reservoir", "transition", "well")), self.mesh.n_cells)


def shifted_readme_case(dx, dy):
    """The README case's text moved by (dx, dy): its x and y axes and every trajectory point."""
    out = []
    for line in read_text(README_CASE).splitlines():
        key = line.strip().split(":")[0]
        if key in ("x", "y"):
            d = dx if key == "x" else dy
            values = line.split("[")[1].split("]")[0].split(",")
            line = "  %s: [%s]" % (key, ", ".join(repr(float(v) + d) for v in values))
        elif key == "trajectory":
            points = line.split("[[")[1].split("]]")[0].split("], [")
            moved = []
            for p in points:
                x, y, z = (float(v) for v in p.split(","))
                moved.append("[%r, %r, %r]" % (x + dx, y + dy, z))
            line = "    trajectory: [%s]" % ", ".join(moved)
        out.append(line)
    return "\n".join(out) + "\n"


class FieldCoordinates(unittest.TestCase):
    """build() meshes in the local frame as meshgen does: a case moved to UTM values gives the same mesh."""

    def test_translated_case_gives_the_same_mesh(self):
        dx, dy = 452000.0, 6780000.0
        local = hybridmesh.build(hybridmesh.parse_case(shifted_readme_case(0.0, 0.0)), optimize=False)
        field = hybridmesh.build(hybridmesh.parse_case(shifted_readme_case(dx, dy)), optimize=False)
        self.assertEqual(field.n_cells, local.n_cells)
        self.assertEqual(field.n_faces, local.n_faces)
        np.testing.assert_array_equal(field.face_nodes, local.face_nodes)
        np.testing.assert_array_equal(field.face_owner, local.face_owner)
        shift = np.array([dx, dy, 0.0])
        # The nodes come back in the case's coordinates: the local mesh's plus the shift, to round-off at 7e6.
        np.testing.assert_allclose(field.nodes - shift, local.nodes, rtol=0, atol=1e-8)
        np.testing.assert_allclose(field.face_centroids - shift, local.face_centroids, rtol=0, atol=1e-8)
        # Volumes are those of the written coordinates (rounded to 9.3e-10 m at 7e6: round_to_written_frame):
        # 4.9e-9 relative on the 5e-4 m3 wellbore cells.
        np.testing.assert_allclose(field.volumes, local.volumes, rtol=1e-7)
        self.assertTrue(hybridmesh.check(field)["ok"])


class BadInput(unittest.TestCase):
    def test_bad_value_names_the_key(self):
        text = read_text(README_CASE).replace("radius: 0.1", "radius: -0.1")
        with self.assertRaises(hybridmesh.InputError) as ctx:
            hybridmesh.parse_case(text)
        self.assertTrue(str(ctx.exception).startswith("wells[0].radius:"), str(ctx.exception))

    def test_input_error_is_a_value_error(self):
        with self.assertRaises(ValueError):
            hybridmesh.load_case(os.path.join(ROOT, "examples", "no_such_case.yaml"))

    def test_good_text_parses(self):
        cs = hybridmesh.parse_case(read_text(README_CASE))
        self.assertEqual(cs.name, "my_case")


def box_grdecl(nx, ny, nz):
    """A box of nx x ny x nz cells of 10 m as GRDECL text, PERMX/Y 100, PERMZ 10 mD, PORO 0.2."""
    n = nx * ny * nz
    coord = "".join(f"{10 * i} {10 * j} 1000 {10 * i} {10 * j} 1050\n" for j in range(ny + 1) for i in range(nx + 1))
    zcorn = "".join(f"{4 * nx * ny}*{1000 + 10 * (k + s)}\n" for k in range(nz) for s in (0, 1))
    return (f"SPECGRID\n {nx} {ny} {nz} 1 F /\nCOORD\n{coord}/\nZCORN\n{zcorn}/\n"
            f"PERMX\n{n}*100 /\nPERMY\n{n}*100 /\nPERMZ\n{n}*10 /\nPORO\n{n}*0.2 /\n")


class ModelMultipliers(unittest.TestCase):
    """A 4 x 3 x 5 box of 10 m cells given as GRDECL with MULTZ 0.5: meshed as its corner-point cells,
    every face between two layers carries 0.5, every other face 1, and the transmissibilities include it."""

    def test_multz_on_the_faces_between_layers(self):
        nx, ny, nz = 4, 3, 5
        n = nx * ny * nz
        text = box_grdecl(nx, ny, nz)
        with tempfile.TemporaryDirectory() as d:
            for name, extra in (("plain", ""), ("mult", f"MULTZ\n{n}*0.5 /\n")):
                with open(os.path.join(d, name + ".GRDECL"), "w", encoding="utf-8") as f:
                    f.write(text + extra)
            plain = hybridmesh.build(hybridmesh.parse_case("name: p\nreservoir: {grdecl: plain.GRDECL}\n", d))
            mult = hybridmesh.build(hybridmesh.parse_case("name: m\nreservoir: {grdecl: mult.GRDECL}\n", d))
        m = mult.face_trans_mult
        self.assertEqual(m.shape, (mult.n_faces,))
        interior = mult.face_neighbour >= 0
        ijk = mult.cell_ijk
        between_layers = interior & (ijk[mult.face_owner, 2] != ijk[np.where(interior, mult.face_neighbour, 0), 2])
        self.assertGreater(between_layers.sum(), 30)
        np.testing.assert_array_equal(m[between_layers], 0.5)
        np.testing.assert_array_equal(m[~between_layers], 1.0)
        np.testing.assert_array_equal(plain.face_trans_mult, np.ones(plain.n_faces))
        # Same cells either way (sorted by ijk): the vertical pairs' transmissibilities are halved.
        def by_pair(mesh):
            t, ijk = mesh.transmissibilities, mesh.cell_ijk
            out = {}
            for f in np.nonzero(mesh.face_neighbour >= 0)[0]:
                a, b = tuple(ijk[mesh.face_owner[f]]), tuple(ijk[mesh.face_neighbour[f]])
                out[tuple(sorted((a, b)))] = out.get(tuple(sorted((a, b))), 0.0) + t[f]
            return out
        p, q = by_pair(plain), by_pair(mult)
        self.assertEqual(p.keys(), q.keys())
        for pair, t in p.items():
            expected = 0.5 if pair[0][2] != pair[1][2] else 1.0
            self.assertAlmostEqual(q[pair] / t, expected, places=12)

    def test_multpv_on_the_cells(self):
        """MULTPV 2.5 on the top layer's cells: their pore-volume multiplier, 1 elsewhere."""
        nx, ny, nz = 4, 3, 5
        n = nx * ny * nz
        text = box_grdecl(nx, ny, nz) + f"MULTPV\n{nx * ny}*2.5 {n - nx * ny}*1 /\n"
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "pv.GRDECL"), "w", encoding="utf-8") as f:
                f.write(text)
            mesh = hybridmesh.build(hybridmesh.parse_case("name: pv\nreservoir: {grdecl: pv.GRDECL}\n", d))
        top = mesh.cell_ijk[:, 2] == 0
        self.assertEqual(top.sum(), nx * ny)
        np.testing.assert_allclose(mesh.pore_volume_multiplier[top], 2.5, rtol=1e-12)
        np.testing.assert_array_equal(mesh.pore_volume_multiplier[~top], 1.0)

    def test_nnc_between_cells_sharing_no_face(self):
        """NNC between two corner cells of the box: one connection without a face, its cells and T as given;
        none without the keyword."""
        nx, ny, nz = 4, 3, 5
        with tempfile.TemporaryDirectory() as d:
            for name, extra in (("plain", ""), ("nnc", "NNC\n 1 1 1 4 3 5 2.5 /\n/\n")):
                with open(os.path.join(d, name + ".GRDECL"), "w", encoding="utf-8") as f:
                    f.write(box_grdecl(nx, ny, nz) + extra)
            plain = hybridmesh.build(hybridmesh.parse_case("name: p\nreservoir: {grdecl: plain.GRDECL}\n", d))
            mesh = hybridmesh.build(hybridmesh.parse_case("name: n\nreservoir: {grdecl: nnc.GRDECL}\n", d))
        self.assertEqual(plain.nnc_cells.shape, (0, 2))
        self.assertEqual(mesh.nnc_cells.shape, (1, 2))
        ends = sorted(tuple(mesh.cell_ijk[c]) for c in mesh.nnc_cells[0])
        self.assertEqual(ends, [(0, 0, 0), (nx - 1, ny - 1, nz - 1)])
        np.testing.assert_allclose(mesh.nnc_transmissibilities, [2.5], rtol=1e-12)


if __name__ == "__main__":
    unittest.main()
