#!/usr/bin/python3
"""Reads one VTK XML file (.vtp or .vtu) with VTK's own reader (the one ParaView uses) and prints
everything it holds, one array per line, each value in Python's shortest round-trip form (so a
value printed here reads back bit for bit):

  points N 3 v v v ...
  cells verts|polys|cells K connectivity c c ... offsets o o ...
  types K t t ...                                  (.vtu)
  point NAME TYPE N C v v v ...
  cell NAME TYPE N C v v v ...

Exits 1 with a message when VTK cannot read the file. usage: vtk_arrays.py FILE
"""
import sys

# Only the XML readers' module (and what it depends on), not `import vtk`, which loads every VTK
# module: about 0.2 s of CPU a call instead of 0.5 (tests call this once per file).
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader


def values(a):
    return " ".join(repr(float(v)) if a.dtype.kind == "f" else str(int(v))
                    for v in a.reshape(-1))


def array_line(kind, a):
    n = vtk_to_numpy(a)
    print(f"{kind} {a.GetName()} {a.GetDataTypeAsString()} {a.GetNumberOfTuples()} "
          f"{a.GetNumberOfComponents()} {values(n)}".rstrip())


def cell_line(kind, cells):
    print(f"cells {kind} {cells.GetNumberOfCells()} connectivity "
          f"{values(vtk_to_numpy(cells.GetConnectivityArray()))} offsets "
          f"{values(vtk_to_numpy(cells.GetOffsetsArray()))}")


def main():
    if len(sys.argv) != 2:
        print("usage: vtk_arrays.py FILE")
        sys.exit(1)
    path = sys.argv[1]
    vtu = path.endswith(".vtu")
    reader = vtkXMLUnstructuredGridReader() if vtu else vtkXMLPolyDataReader()
    if not reader.CanReadFile(path):
        print(f"vtk_arrays: {path}: VTK cannot read it")
        sys.exit(1)
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        print(f"vtk_arrays: {path}: VTK reader error {reader.GetErrorCode()}")
        sys.exit(1)
    out = reader.GetOutput()
    pts = out.GetPoints()
    if pts is None:
        print(f"points {out.GetNumberOfPoints()} 3")
    else:
        print(f"points {pts.GetNumberOfPoints()} 3 {values(vtk_to_numpy(pts.GetData()))}".rstrip())
    if vtu:
        cell_line("cells", out.GetCells())
        types = vtk_to_numpy(out.GetCellTypesArray())
        print(f"types {len(types)} {values(types)}".rstrip())
    else:
        cell_line("verts", out.GetVerts())
        cell_line("polys", out.GetPolys())
    for kind, data in (("point", out.GetPointData()), ("cell", out.GetCellData())):
        for k in range(data.GetNumberOfArrays()):
            array_line(kind, data.GetArray(k))
    for kind, data in (("point", out.GetPointData()), ("cell", out.GetCellData())):
        for attr, getter in (("Scalars", data.GetScalars), ("Vectors", data.GetVectors),
                             ("Tensors", data.GetTensors)):
            a = getter()
            if a is not None:
                print(f"active {kind} {attr} {a.GetName()}")


if __name__ == "__main__":
    main()
