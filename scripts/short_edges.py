#!/usr/bin/env python3
"""Short edges of the transition cells of a mesh.vtu (issue 13's "no edge shorter than 5 % of h").

For each transition cell (region 1), from VTK's own reading of its faces: the shortest distinct edge
over h, h the cell's mean distinct edge length (Q_S's h without a reference length); and the edges
shorter than 1e-3 h and 1e-5 h (kSliverEdge) by how many of their ends are constrained (a node of a
reservoir or well cell). Usage: /usr/bin/python3 scripts/short_edges.py OUT/mesh.vtu
"""
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def main(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    region = vtk_to_numpy(grid.GetCellData().GetArray("region"))
    points = vtk_to_numpy(grid.GetPoints().GetData())
    constrained = np.zeros(len(points), bool)
    ids = vtk.vtkIdList()
    for c in np.nonzero(region != 1)[0]:
        grid.GetCellPoints(int(c), ids)
        for i in range(ids.GetNumberOfIds()):
            constrained[ids.GetId(i)] = True
    ratios, shortest = [], []
    tiny = {1e-3: [0, 0, 0], 1e-5: [0, 0, 0]}
    for c in np.nonzero(region == 1)[0]:
        cell = grid.GetCell(int(c))
        edges = set()
        for f in range(cell.GetNumberOfFaces()):
            face = cell.GetFace(f)
            n = face.GetNumberOfPoints()
            for i in range(n):
                a, b = face.GetPointId(i), face.GetPointId((i + 1) % n)
                edges.add((min(a, b), max(a, b)))
        edges = list(edges)
        lengths = np.array([np.linalg.norm(points[a] - points[b]) for a, b in edges])
        h = lengths.mean()
        ratios.append(lengths.min() / h)
        shortest.append(lengths.min())
        for limit, count in tiny.items():
            for (a, b), length in zip(edges, lengths):
                if length < limit * h:
                    count[int(constrained[a]) + int(constrained[b])] += 1
    ratios = np.array(ratios)
    print(f"{path}: {len(ratios)} transition cells; shortest edge / h: median {np.median(ratios):.3g}; "
          f"cells below 0.05 h: {np.sum(ratios < 0.05)} ({100 * np.mean(ratios < 0.05):.0f} %), "
          f"below 0.01 h: {np.sum(ratios < 0.01)}; shortest edge {min(shortest):.3g} m")
    for limit, count in tiny.items():
        print(f"  cell-edges below {limit:g} h with 0 / 1 / 2 constrained ends: {count[0]} / {count[1]} / {count[2]}")


if __name__ == "__main__":
    main(sys.argv[1])
