"""Reads a .vtu with VTK 9 (python3-vtk9) and measures, cell by cell, whether VTK reads our geometry
as ours and why VTK 9.1's own cell measures disagree where they do (docs/output-formats.md, "What
VTK 9.1 computes from a polyhedron"). Usage: vtk_agreement.py MESH.vtu (needs a cell array
`volume` with our volumes). Prints "@@ key value" lines; vtkCellValidator's own stdout is noise.

Our measures, on the points and faces VTK read (vtkCell.GetFace):
  face_volume_max_rel  volume by the divergence theorem over VTK's faces against `volume`
  convexity_max        the highest vertex above a face plane of its cell, over the cell diameter
  orientation_bad      cells with a face whose normal points towards the cell's vertex mean
VTK 9.1's measures and what explains their disagreement, reproduced cell by cell:
  size_*               vtkCellSizeFilter; a polyhedron's volume is the sum of the tetrahedra of
                       vtkPolyhedron::Triangulate (a Delaunay triangulation of the cell's points in a
                       bounding octahedron 2 bounding-box diagonals wide, vtkOrderedTriangulator);
                       `hole`: those tetrahedra leave a triangle inside the cell uncovered
  invalid_*            vtkCellValidator states. Bit 32 (faces oriented incorrectly) is measured from
                       the bounding-box centre (vtkPolyhedron's parametric centre), and is also set
                       when a face fails VTK's polygon check, which an edge shorter than 1e-3 of the
                       cell does (`short_edge`: ours). Bit 16 (non-convex): vtkPolyhedron::IsConvex's
                       edge test with vtkPolygon::ComputeCentroid, which projects a face on the x-y
                       plane unless its normal is horizontal to DBL_EPSILON (`centroid`), or its seam
                       test (`seam`). Bits 2 and 4 (intersecting edges, faces): FLT_EPSILON
                       tolerances (vtkLine::Intersection: 1e-6 relative) on a cell with an edge shorter than 1e-3 of its diameter.
"""
import collections
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

DBL_EPS = np.finfo(float).eps
FLT_EPS = float(np.finfo(np.float32).eps)  # vtkCellValidator's default tolerance


def newell(Q):
    n = np.zeros(3)
    for i in range(len(Q)):
        n += np.cross(Q[i] - Q[0], Q[(i + 1) % len(Q)] - Q[0])
    return n / np.linalg.norm(n)


def area_centroid(Q):
    m = Q.mean(0)
    A, C = 0.0, np.zeros(3)
    for i in range(len(Q)):
        t = np.linalg.norm(np.cross(Q[i] - m, Q[(i + 1) % len(Q)] - m)) / 2
        A += t
        C += t * (m + Q[i] + Q[(i + 1) % len(Q)]) / 3
    return C / A


def vtk91_normal(Q):
    """vtkPolygon::ComputeNormal (VTK 9.1) as VTK evaluates it."""
    if len(Q) == 3:
        n = np.cross(Q[2] - Q[1], Q[0] - Q[1])
        return n / np.linalg.norm(n)
    n = np.zeros(3)
    for i in range(len(Q)):
        v0, v1, v2 = Q[i], Q[(i + 1) % len(Q)], Q[(i + 2) % len(Q)]
        n += np.cross(v2 - v1, v0 - v1)
    return n / np.linalg.norm(n)


def vtk91_centroid(Q):
    """vtkPolygon::ComputeCentroid (VTK 9.1, replaced upstream by VTK commit 7d4bbe1b65 in 2025):
    the centroid of the x-y projection unless |n x z|^2 is 1 to DBL_EPSILON, then the third
    coordinate from the plane equation, divided by n_z."""
    n = vtk91_normal(Q)
    xo = yo = 0
    c = np.cross(n, [0.0, 0.0, 1.0])
    if abs(np.dot(c, c) - 1.0) <= DBL_EPS:
        yo = 1
        c = np.cross(n, [0.0, 1.0, 0.0])
        if abs(np.dot(c, c) - 1.0) <= DBL_EPS:
            xo = 1
    cx = cy = a = 0.0
    for i in range(len(Q)):
        p, q = Q[i], Q[(i + 1) % len(Q)]
        det = p[xo] * q[1 + yo] - q[xo] * p[1 + yo]
        cx += (p[xo] + q[xo]) * det
        cy += (p[1 + yo] + q[1 + yo]) * det
        a += det
    C = np.zeros(3)
    with np.errstate(all="ignore"):
        C[xo] = cx / (3 * a)
        C[1 + yo] = cy / (3 * a)
        z = 2 - xo - yo
        C[z] = (-n[xo] * C[xo] - n[1 + yo] * C[1 + yo] + np.dot(n, Q[0])) / n[z]
    return C


def local_test_fails(pairs, normals, centroids):
    """vtkPolyhedron::IsConvex's test per edge: the mean of the two faces' centroids must not be
    above either face."""
    for a, b in pairs:
        with np.errstate(all="ignore"):
            m = (centroids[a] + centroids[b]) / 2
            d0, d1 = np.dot(normals[a], m - centroids[a]), np.dot(normals[b], m - centroids[b])
        if not (d0 <= 0 and d1 <= 0):
            return True
    return False


def seam_test_fails(edge_faces, P, normals, centroids):
    """vtkPolyhedron::IsConvex's second test (VTK 9.1): project on the x-y plane, count the seam
    edges at each vertex and the "right-2-seam" vertices (a convex polytope has one)."""
    eps = np.finfo(np.float32).eps
    d = collections.Counter()
    px = {}
    r = 0
    for (w0, w1), (a, b) in edge_faces:
        x = (P[w0], P[w1])
        n = (x[1] - x[0]) / np.linalg.norm(x[1] - x[0])
        if abs(n[0]) < eps and abs(n[1]) < eps:
            continue
        nperp = np.array([n[1], -n[0], 0.0])
        mid = (x[0] + x[1]) / 2
        with np.errstate(all="ignore"):
            t0, t1 = np.dot(nperp, centroids[a] - mid), np.dot(nperp, centroids[b] - mid)
            if (t0 < 0) != (t1 < 0):
                continue
            top = normals[a][2] if centroids[a][2] > centroids[b][2] else normals[b][2]
        if abs(top) < eps:
            continue
        for i, v in enumerate((w0, w1)):
            other = x[1 - i][0]
            if d[v] == 2:
                return True
            if d[v] == 0:
                d[v] = 1
                px[v] = other
            else:
                d[v] += 1
                if x[i][0] > other and x[i][0] > px[v]:
                    if r == 0:
                        r = 1
                    else:
                        return True
    return False


def main(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    n = g.GetNumberOfCells()
    ours = vtk_to_numpy(g.GetCellData().GetArray("volume"))
    cs = vtk.vtkCellSizeFilter()
    cs.SetInputData(g)
    cs.ComputeVolumeOn()
    cs.Update()
    vsize = vtk_to_numpy(cs.GetOutput().GetCellData().GetArray("Volume"))
    cv = vtk.vtkCellValidator()
    cv.SetInputData(g)
    cv.Update()
    state = vtk_to_numpy(cv.GetOutput().GetCellData().GetArray("ValidityState")).astype(int)

    out = collections.OrderedDict()
    out["cells"] = n
    out["polyhedra"] = int(sum(1 for c in range(n) if g.GetCellType(c) == vtk.VTK_POLYHEDRON))
    fv_max = conv_max = 0.0
    orient_bad = 0
    size_bad = size_hole = size_unexplained = 0
    size_max = 0.0
    inv = collections.Counter()
    for c in range(n):
        # A hexahedron's volume is VTK's exact formula (checked by size_* over every cell); the
        # per-cell measures below run on every polyhedron and on every cell VTK flags.
        rel = abs(vsize[c] - ours[c]) / abs(ours[c])
        size_max = max(size_max, rel)
        if g.GetCellType(c) != vtk.VTK_POLYHEDRON and state[c] == 0 and rel <= 1e-6:
            continue
        cell = g.GetCell(c)
        faces = []
        for k in range(cell.GetNumberOfFaces()):
            f = cell.GetFace(k)
            faces.append([f.GetPointId(i) for i in range(f.GetNumberOfPoints())])
        pts = sorted(set(i for f in faces for i in f))
        X = np.array([g.GetPoint(i) for i in pts])
        P = {i: np.array(g.GetPoint(i)) for i in pts}
        lo, hi = X.min(0), X.max(0)
        diam = np.linalg.norm(hi - lo)
        mean = X.mean(0)
        bbox_centre = (lo + hi) / 2
        vol = 0.0
        bbox_outside = False
        short_edge = min(np.linalg.norm(P[f[i]] - P[f[(i + 1) % len(f)]]) for f in faces for i in range(len(f))) < 1e-3 * diam
        rejected_face = False
        normals, vtk_c, true_c = [], [], []
        for f in faces:
            Q = np.array([P[i] for i in f])
            nrm, ac = newell(Q), area_centroid(Q)
            for i in range(len(Q)):
                vol += np.dot(np.cross(Q[i] - mean, Q[(i + 1) % len(Q)] - mean), ac - mean) / 6
            conv_max = max(conv_max, max(np.dot(nrm, x - ac) for x in X) / diam)
            if np.dot(nrm, ac - mean) <= 0:
                orient_bad += 1
            if np.dot(nrm, bbox_centre - ac) >= 0:
                bbox_outside = True
            if state[c] & 32 and not rejected_face:
                rejected_face = vtk.vtkCellValidator.Check(cell.GetFace(faces.index(f)), FLT_EPS) != 0
            normals.append(vtk91_normal(Q))
            vtk_c.append(vtk91_centroid(Q))
            true_c.append(ac)
        fv_max = max(fv_max, abs(vol - ours[c]) / abs(ours[c]))
        if rel > 1e-6:
            size_bad += 1
            hole = False
            if g.GetCellType(c) == vtk.VTK_POLYHEDRON:
                ids, tp = vtk.vtkIdList(), vtk.vtkPoints()
                cell.Triangulate(0, ids, tp)
                T = np.array([ids.GetId(i) for i in range(ids.GetNumberOfIds())]).reshape(-1, 4)
                tv = sum(abs(np.dot(np.cross(P[t[1]] - P[t[0]], P[t[2]] - P[t[0]]), P[t[3]] - P[t[0]])) / 6 for t in T)
                count = collections.Counter()
                for t in T:
                    for k in range(4):
                        count[tuple(sorted(np.delete(t, k)))] += 1
                fsets = [set(f) for f in faces]
                uncovered = [t for t, m in count.items() if m == 1 and not any(set(t) <= s for s in fsets)]
                hole = bool(uncovered) and abs(tv - vsize[c]) <= 1e-9 * abs(ours[c])
            size_hole += hole
            size_unexplained += not hole
        s = int(state[c])
        if s:
            inv["invalid"] += 1
            if s & 32:
                inv["invalid_orientation"] += 1
                inv["invalid_orientation_bbox"] += bbox_outside
                # FacesAreOrientedCorrectly also fails when a face fails VTK's polygon check, which
                # happens on faces with an edge shorter than 1e-3 of the cell (our short edges).
                by_face = not bbox_outside and rejected_face and short_edge
                inv["invalid_orientation_short_edge"] += by_face
                inv["invalid_orientation_unexplained"] += not (bbox_outside or by_face)
            if s & 16:
                inv["invalid_nonconvex"] += 1
                edges = collections.defaultdict(list)
                for j, f in enumerate(faces):
                    for i in range(len(f)):
                        edges[tuple(sorted((f[i], f[(i + 1) % len(f)])))].append(j)
                pairs = [js for js in edges.values() if len(js) == 2]
                ef = [(e, js) for e, js in edges.items() if len(js) == 2]
                by_centroid = local_test_fails(pairs, normals, vtk_c) and not local_test_fails(pairs, normals, true_c)
                by_seam = not by_centroid and seam_test_fails(ef, P, normals, vtk_c)
                inv["invalid_nonconvex_centroid"] += by_centroid
                inv["invalid_nonconvex_seam"] += by_seam
                if by_seam and not seam_test_fails(ef, P, normals, true_c):
                    inv["invalid_nonconvex_seam_centroid"] += 1
                if not (by_centroid or by_seam):
                    print("## nonconvex flag not reproduced: cell", c, "type", g.GetCellType(c))
            if s & 6:
                inv["invalid_intersecting"] += 1
                inv["invalid_intersecting_unexplained"] += not short_edge
            if s & ~(32 | 16 | 6):
                inv["invalid_other"] += 1
    out["face_volume_max_rel"] = fv_max
    out["convexity_max"] = conv_max
    out["orientation_bad"] = orient_bad
    out["size_bad"] = size_bad
    out["size_max_rel"] = size_max
    out["size_hole"] = size_hole
    out["size_unexplained"] = size_unexplained
    for k in ("invalid", "invalid_orientation", "invalid_orientation_bbox", "invalid_orientation_short_edge",
              "invalid_orientation_unexplained", "invalid_nonconvex",
              "invalid_nonconvex_centroid",
              "invalid_nonconvex_seam", "invalid_nonconvex_seam_centroid", "invalid_intersecting", "invalid_intersecting_unexplained", "invalid_other"):
        out[k] = inv[k]
    for k, v in out.items():
        print("@@", k, repr(v), flush=True)


if __name__ == "__main__":
    main(sys.argv[1])
