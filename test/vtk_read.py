#!/usr/bin/python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
"""Reads a VtkExporter .pvd collection and every file it lists, and prints what they hold (test_unit_vtk_export).

Run with Debian's /usr/bin/python3 (python3-vtk9, python3-meshio: scripts/install-deps.sh). Each file is decoded
independently of the C++ writer by up to three readers, which must agree value for value (exit 1 otherwise):
  1. by VTK's own XML readers (the authority: what ParaView runs) - vtkXMLPolyDataReader (.vtp),
     vtkXMLStructuredGridReader (.vts), vtkXMLImageDataReader (.vti). Any VTK error or warning while reading
     (an ErrorEvent/WarningEvent on the reader, any text sent to VTK's output window, a reader error code) fails
     the file. Required: without VTK the script prints "error ..." telling to run scripts/install-deps.sh;
  2. by meshio's own decoder of binary-appended VTK XML (meshio.vtu._vtu: _parse_raw_binary walks the appended
     blocks by their UInt64 byte counts and matches each to the DataArray whose offset it starts at;
     VtuReader.read_data decodes one array) - skipped, with "meshio no" printed, when meshio is not installed;
     (meshio's read() only takes UnstructuredGrid, .vtu, not PolyData, StructuredGrid or ImageData)
  3. by this script: xml.etree for the XML, struct for the appended blocks, checking that the blocks tile the
     appended section exactly (each array starts where the previous ended, nothing after the last).
Output, one record per line:
  vtk <VTK version>
  meshio yes|no
  dataset <timestep> <part> <file>                  (the .pvd entries, in order)
  file <file> <VTKFile type>
  attr <name> <value>                               (attributes of the dataset element, e.g. WholeExtent)
  piece <name> <value>                              (attributes of the Piece)
  array <section> <name> <type> <components> <count> <values...>   (floats as repr: exact doubles)
  voxel <i> <j> <k> <x> <y> <z>     (ImageData: each cell's centre, VTK's index-to-physical map of (i+.5, j+.5, k+.5))
  reader <VTK reader class> meshio|- struct      (the decoders that agreed on this file)
  end
"""
import os
import re
import struct
import sys
import xml.etree.ElementTree as ET

FORMATS = {"Float32": "f", "Float64": "d", "Int8": "b", "UInt8": "B", "Int16": "h", "UInt16": "H",
           "Int32": "i", "UInt32": "I", "Int64": "q", "UInt64": "Q"}

try:
    import numpy as np
    from meshio.vtu._vtu import VtuReader, _parse_raw_binary
    HAVE_MESHIO = True
except ImportError:
    HAVE_MESHIO = False

try:
    import numpy as np
    from vtkmodules.util.misc import calldata_type
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import VTK_STRING, vtkOutputWindow, vtkStringOutputWindow, vtkVersion
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPolyDataReader, vtkXMLStructuredGridReader
    VTK_IMPORT_ERROR = None
except ImportError as e:
    VTK_IMPORT_ERROR = str(e)


def fail(msg):
    print("error " + msg)
    sys.exit(1)


def split_file(raw, path):
    """XML root (without the binary) and the appended bytes after the '_'."""
    m = re.search(rb'<AppendedData encoding="raw">\s*_', raw)
    if not m:
        fail(path + ": no raw AppendedData")
    start = m.end()
    end = raw.rfind(b"</AppendedData>")
    if end < start:
        fail(path + ": no </AppendedData>")
    tail = raw[end:]
    root = ET.fromstring(raw[:m.start()] + b"<AppendedData/>" + tail[len(b"</AppendedData>"):])
    return root, raw[start:end]


def decode_struct(root, data, path):
    """{id(DataArray element): values} with the blocks checked to tile the data exactly."""
    header = root.get("header_type")
    if header != "UInt64" or root.get("byte_order") != "LittleEndian":
        fail(path + ": header_type/byte_order")
    arrays = root.findall(".//DataArray")
    arrays_by_offset = sorted(arrays, key=lambda a: int(a.get("offset")))
    pos = 0
    values = {}
    for a in arrays_by_offset:
        if a.get("format") != "appended":
            fail(path + ": array not appended")
        off = int(a.get("offset"))
        if off != pos:
            fail(f"{path}: array {a.get('Name')} at offset {off}, expected {pos}")
        (nbytes,) = struct.unpack_from("<Q", data, off)
        fmt = FORMATS[a.get("type")]
        size = struct.calcsize(fmt)
        if nbytes % size:
            fail(f"{path}: {a.get('Name')} has {nbytes} bytes, not a multiple of {size}")
        if off + 8 + nbytes > len(data):
            fail(f"{path}: {a.get('Name')} runs past the appended data")
        values[id(a)] = list(struct.unpack_from("<%d%s" % (nbytes // size, fmt), data, off + 8))
        pos = off + 8 + nbytes
    # Only the line break and indentation before </AppendedData> may follow the last block.
    if data[pos:].strip(b" \n") != b"":
        fail(f"{path}: {len(data) - pos} unexpected bytes after the last array")
    return arrays, values


def decode_meshio(path):
    """The arrays in document order, decoded by meshio's binary-appended reader."""
    root = _parse_raw_binary(path)
    reader = VtuReader.__new__(VtuReader)  # only its array decoder: read() refuses non-UnstructuredGrid types
    reader.compression = None
    reader.header_type = root.get("header_type")
    reader.byte_order = root.get("byte_order")
    reader.appended_data = root.find("AppendedData").text.strip()[1:]
    return [np.asarray(reader.read_data(a)).reshape(-1).tolist() for a in root.findall(".//DataArray")]


def vtk_reader_class(kind):
    return {"PolyData": vtkXMLPolyDataReader, "StructuredGrid": vtkXMLStructuredGridReader,
            "ImageData": vtkXMLImageDataReader}[kind]


def read_vtk(path, kind):
    """The dataset as VTK's XML reader for `kind` reads it; any error or warning on the way fails."""
    log = vtkStringOutputWindow()  # everything VTK would print (parser, executive, reader) lands here
    vtkOutputWindow.SetInstance(log)
    reader = vtk_reader_class(kind)()
    messages = []

    @calldata_type(VTK_STRING)
    def on_message(obj, event, text):
        messages.append(f"{event}: {text}")

    reader.AddObserver("ErrorEvent", on_message)
    reader.AddObserver("WarningEvent", on_message)
    reader.SetFileName(path)
    reader.Update()
    if messages or log.GetOutput().strip() or reader.GetErrorCode() != 0:
        fail(f"{path}: {reader.GetClassName()} reported errors (error code {reader.GetErrorCode()}): "
             + " | ".join(messages + [log.GetOutput().strip()]).replace("\n", " "))
    out = reader.GetOutput()
    if out is None or out.GetClassName() != "vtk" + kind:
        fail(f"{path}: {reader.GetClassName()} gave no vtk{kind}")
    return reader, out


def check_vtk(path, kind, root, arrays, values):
    """Checks that VTK's reader gives every array of the file (values, type, components), the piece's sizes and
    the dataset attributes exactly as the struct decoder; returns the voxel-centre lines for ImageData."""
    reader, out = read_vtk(path, kind)
    name = reader.GetClassName()
    ds = root.find(kind)
    piece = ds.find("Piece")

    def same(what, got, want):
        if len(got) != len(want) or any(x != y for x, y in zip(got, want)):
            fail(f"{path}: {name} and struct disagree on {what}: {list(got)[:12]} vs {list(want)[:12]}")

    def data_array(section, a, vtk_array):
        if vtk_array is None:
            fail(f"{path}: {name} has no {section} array {a.get('Name')}")
        arr = vtk_to_numpy(vtk_array)
        if arr.dtype != np.dtype(FORMATS[a.get("type")]):
            fail(f"{path}: {name} reads {section}/{a.get('Name')} as {arr.dtype}, the file says {a.get('type')}")
        if vtk_array.GetNumberOfComponents() != int(a.get("NumberOfComponents", "1")):
            fail(f"{path}: {name}: {section}/{a.get('Name')} has {vtk_array.GetNumberOfComponents()} components")
        same(section + "/" + a.get("Name"), arr.reshape(-1).tolist(), values[id(a)])

    # Sizes.
    npts = out.GetNumberOfPoints()
    if kind == "PolyData":
        if npts != int(piece.get("NumberOfPoints")):
            fail(f"{path}: {name} reads {npts} points, the piece says {piece.get('NumberOfPoints')}")
        for tag, cells in (("Verts", out.GetVerts()), ("Lines", out.GetLines()), ("Strips", out.GetStrips()),
                           ("Polys", out.GetPolys())):
            n = int(piece.get("NumberOf" + tag, "0"))
            if cells.GetNumberOfCells() != n:
                fail(f"{path}: {name} reads {cells.GetNumberOfCells()} {tag}, the piece says {n}")
            section = piece.find(tag)
            if section is None:
                continue
            for a in section.findall("DataArray"):
                if a.get("Name") == "connectivity":
                    same(tag + "/connectivity", vtk_to_numpy(cells.GetConnectivityArray()).tolist(), values[id(a)])
                elif a.get("Name") == "offsets":  # VTK's offsets start with a 0 that the file leaves out
                    off = vtk_to_numpy(cells.GetOffsetsArray()).tolist()
                    if not off or off[0] != 0:
                        fail(f"{path}: {name}: {tag} offsets do not start at 0")
                    same(tag + "/offsets", off[1:], values[id(a)])
                else:
                    fail(f"{path}: unexpected {tag} array {a.get('Name')}")
    else:
        want = [int(v) for v in ds.get("WholeExtent").split()]
        same("WholeExtent", list(out.GetExtent()), want)
        if npts != (want[1] - want[0] + 1) * (want[3] - want[2] + 1) * (want[5] - want[4] + 1):
            fail(f"{path}: {name} reads {npts} points for extent {want}")
    # Points (ImageData has none: they follow from Origin/Spacing/Direction).
    pts = piece.find("Points")
    if pts is not None:
        data_array("Points", pts.find("DataArray"), out.GetPoints().GetData() if out.GetPoints() else None)
    # Point and cell data: the same arrays, no more.
    for section, data in (("PointData", out.GetPointData()), ("CellData", out.GetCellData())):
        elem = piece.find(section)
        listed = elem.findall("DataArray") if elem is not None else []
        if data.GetNumberOfArrays() != len(listed):
            fail(f"{path}: {name} reads {data.GetNumberOfArrays()} {section} arrays, the file has {len(listed)}")
        for a in listed:
            data_array(section, a, data.GetAbstractArray(a.get("Name")))
    voxels = []
    if kind == "ImageData":
        same("Origin", list(out.GetOrigin()), [float(v) for v in ds.get("Origin").split()])
        same("Spacing", list(out.GetSpacing()), [float(v) for v in ds.get("Spacing").split()])
        m = out.GetDirectionMatrix()
        same("Direction", [m.GetElement(r, c) for r in range(3) for c in range(3)],
             [float(v) for v in ds.get("Direction").split()])
        e = out.GetExtent()
        for k in range(e[4], e[5]):
            for j in range(e[2], e[3]):
                for i in range(e[0], e[1]):
                    x = [0.0, 0.0, 0.0]
                    out.TransformContinuousIndexToPhysicalPoint(i + 0.5, j + 0.5, k + 0.5, x)
                    voxels.append(f"voxel {i} {j} {k} " + " ".join(repr(float(c)) for c in x))
    return name, voxels


def fmt_value(v):
    return repr(float(v)) if isinstance(v, float) else str(int(v))


def read_file(path, name):
    with open(path, "rb") as f:
        raw = f.read()
    root, data = split_file(raw, path)
    kind = root.get("type")
    arrays, values = decode_struct(root, data, path)
    vtk_name, voxels = check_vtk(path, kind, root, arrays, values)
    if HAVE_MESHIO:
        via_meshio = decode_meshio(path)
        if len(via_meshio) != len(arrays):
            fail(path + ": meshio found another number of arrays")
        for a, mv in zip(arrays, via_meshio):
            sv = values[id(a)]
            if len(mv) != len(sv) or any(x != y for x, y in zip(mv, sv)):
                fail(f"{path}: meshio and struct disagree on {a.get('Name')}")
    print("file", name, kind)
    ds = root.find(kind)
    for k, v in ds.attrib.items():
        print("attr", k, v)
    piece = ds.find("Piece")
    for k, v in piece.attrib.items():
        print("piece", k, v)
    for section in piece:
        for a in section.findall("DataArray"):
            vals = values[id(a)]
            print("array", section.tag, a.get("Name", "-"), a.get("type"), a.get("NumberOfComponents", "1"),
                  len(vals), " ".join(fmt_value(v) for v in vals))
    for line in voxels:
        print(line)
    print("reader", vtk_name, "meshio" if HAVE_MESHIO else "-", "struct")
    print("end")


def main():
    pvd = sys.argv[1]
    if VTK_IMPORT_ERROR is not None:
        fail(f"{sys.executable} cannot import VTK's Python bindings ({VTK_IMPORT_ERROR}): the ParaView export is "
             "validated by VTK's own XML readers; run scripts/install-deps.sh (Debian package python3-vtk9)")
    print("vtk", vtkVersion.GetVTKVersion())
    print("meshio", "yes" if HAVE_MESHIO else "no")
    root = ET.parse(pvd).getroot()
    if root.get("type") != "Collection":
        fail(pvd + ": not a Collection")
    sets = root.find("Collection").findall("DataSet")
    for d in sets:
        print("dataset", repr(float(d.get("timestep"))), d.get("part"), d.get("file"))
    base = os.path.dirname(pvd)
    for d in sets:
        read_file(os.path.join(base, d.get("file")), d.get("file"))


if __name__ == "__main__":
    main()
