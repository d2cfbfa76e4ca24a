# Writes the seed corpus of fuzz_vtu (tests/fuzz/corpus_vtu/): a hexahedron and a polyhedron with
# region, fv_center and face_patch, by VTK's own writer in six encodings. Usage: /usr/bin/python3 make_corpus_vtu.py DIR
import vtk, sys
out = sys.argv[1]
pts = vtk.vtkPoints()
for k in range(2):
    for j in range(2):
        for i in range(3):
            pts.InsertNextPoint(i, j, k)
P = lambda i, j, k: k * 6 + j * 3 + i
g = vtk.vtkUnstructuredGrid()
g.SetPoints(pts)
hexa = [P(0,0,0), P(1,0,0), P(1,1,0), P(0,1,0), P(0,0,1), P(1,0,1), P(1,1,1), P(0,1,1)]
g.InsertNextCell(vtk.VTK_HEXAHEDRON, 8, hexa)
faces = [[P(1,0,1), P(1,1,1), P(1,1,0), P(1,0,0)], [P(2,0,0), P(2,1,0), P(2,1,1), P(2,0,1)],
         [P(1,0,0), P(2,0,0), P(2,0,1), P(1,0,1)], [P(1,1,0), P(1,1,1), P(2,1,1), P(2,1,0)],
         [P(1,1,0), P(2,1,0), P(2,0,0), P(1,0,0)], [P(1,0,1), P(2,0,1), P(2,1,1), P(1,1,1)]]
stream = [len(faces)]
for f in faces:
    stream += [len(f)] + f
ids = vtk.vtkIdList()
for v in stream:
    ids.InsertNextId(v)
g.InsertNextCell(vtk.VTK_POLYHEDRON, ids)
reg = vtk.vtkIntArray(); reg.SetName("region")
for v in (0, 1): reg.InsertNextValue(v)
g.GetCellData().AddArray(reg)
c = vtk.vtkDoubleArray(); c.SetName("fv_center"); c.SetNumberOfComponents(3)
c.InsertNextTuple3(0.5, 0.5, 0.5); c.InsertNextTuple3(1.5, 0.5, 0.5)
g.GetCellData().AddArray(c)
fp = vtk.vtkIntArray(); fp.SetName("face_patch")
for v in [0, -1, 0, 0, 0, 0, -1, 0, 0, 0, 1, 0]: fp.InsertNextValue(v)
g.GetFieldData().AddArray(fp)
for name, C, mode in [("ascii", None, "ascii"), ("binary", None, "binary"), ("appended", None, "appended"),
                      ("zlib_appended", vtk.vtkZLibDataCompressor, "appended"), ("lz4_binary", vtk.vtkLZ4DataCompressor, "binary"),
                      ("lzma_appended", vtk.vtkLZMADataCompressor, "appended")]:
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(g)
    if C is None: w.SetCompressorTypeToNone()
    else: w.SetCompressor(C())
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    w.SetHeaderType(w.UInt32 if "lz4" in name else w.UInt64)
    w.SetFileName("%s/%s.vtu" % (out, name))
    w.Write()
