"""Shared by the cases' post-processing scripts: the arrays of one VTK XML file that a run wrote.

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    from vtk_file import arrays
"""


def arrays(path):
    """name -> (components, flat list of floats): the points ("Points") and every point and cell
    data array of a VTK XML file in any encoding (zlib, binary or ascii), read with VTK's own
    reader (python3-vtk9); a cell array replaces a point array of the same name."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    vtu = path.endswith(".vtu")
    reader = vtk.vtkXMLUnstructuredGridReader() if vtu else vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    data = reader.GetOutput()
    points = data.GetPoints()
    xyz = [] if points is None else vtk_to_numpy(points.GetData()).ravel().tolist()
    out = {"Points": (3, xyz)}
    for attributes in (data.GetPointData(), data.GetCellData()):
        for k in range(attributes.GetNumberOfArrays()):
            a = attributes.GetArray(k)
            out[a.GetName()] = (a.GetNumberOfComponents(), vtk_to_numpy(a).ravel().tolist())
    return out
