#!/usr/bin/python3
"""Opens every file of every ParaView collection (*.pvd) in OUTPUT_DIR/vtk with VTK's own XML
readers (the ones ParaView uses) and checks what a person opening them would rely on: the file
parses, it has points (and cells where the writer says so), every data array has one tuple per
point or cell and only finite values. Prints one line per collection; exits 1 on the first
problem, naming the file and what is wrong.

usage: check_vtk.py OUTPUT_DIR
"""
import math
import os
import sys
import xml.etree.ElementTree as ET

# the XML readers' module only, not `import vtk` (every VTK module: 0.3 s more CPU a call)
from vtkmodules.vtkCommonCore import vtkObject
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader


def fail(msg):
    print(f"check_vtk: {msg}")
    sys.exit(1)


def check_arrays(path, data, count, where):
    for k in range(data.GetNumberOfArrays()):
        a = data.GetArray(k)
        if a.GetNumberOfTuples() != count:
            fail(f"{path}: {where} array '{a.GetName()}' has {a.GetNumberOfTuples()} tuples, "
                 f"expected {count}")
        for c in range(a.GetNumberOfComponents()):
            lo, hi = a.GetRange(c)
            if not (math.isfinite(lo) and math.isfinite(hi)):
                fail(f"{path}: {where} array '{a.GetName()}' has non-finite values")


def main():
    if len(sys.argv) != 2:
        fail("usage: check_vtk.py OUTPUT_DIR")
    vtk_dir = os.path.join(sys.argv[1], "vtk")
    collections = sorted(f for f in os.listdir(vtk_dir) if f.endswith(".pvd"))
    if not collections:
        fail(f"{vtk_dir}: no .pvd collection")
    vtkObject.GlobalWarningDisplayOff()
    for pvd in collections:
        root = ET.parse(os.path.join(vtk_dir, pvd)).getroot()
        sets = root.findall("./Collection/DataSet")
        if not sets:
            fail(f"{pvd}: empty collection")
        times = [float(s.get("timestep")) for s in sets]
        if times != sorted(times):
            fail(f"{pvd}: time steps are not increasing")
        for s in sets:
            path = os.path.join(vtk_dir, s.get("file"))
            if not os.path.isfile(path):
                fail(f"{pvd}: lists {s.get('file')}, which does not exist")
            reader = (vtkXMLUnstructuredGridReader() if path.endswith(".vtu")
                      else vtkXMLPolyDataReader())
            if not reader.CanReadFile(path):
                fail(f"{path}: VTK cannot read it")
            reader.SetFileName(path)
            reader.Update()
            out = reader.GetOutput()
            if reader.GetErrorCode() != 0:
                fail(f"{path}: VTK reader error {reader.GetErrorCode()}")
            n_points, n_cells = out.GetNumberOfPoints(), out.GetNumberOfCells()
            if n_points == 0 or n_cells == 0:
                fail(f"{path}: {n_points} points, {n_cells} cells")
            check_arrays(path, out.GetPointData(), n_points, "point")
            check_arrays(path, out.GetCellData(), n_cells, "cell")
        print(f"{pvd}: {len(sets)} files, last with {n_points} points, {n_cells} cells: ok")


if __name__ == "__main__":
    main()
