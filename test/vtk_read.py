#!/usr/bin/python3
"""Reads a VtkExporter .pvd collection and every file it lists, and prints what they hold (test_unit_vtk_export).

Run with Debian's /usr/bin/python3 (python3-meshio). meshio's read() only takes the UnstructuredGrid type
(.vtu), not PolyData (.vtp), StructuredGrid (.vts) or ImageData (.vti), so each file is decoded twice,
independently of the C++ writer:
  1. by meshio's own decoder of binary-appended VTK XML (meshio.vtu._vtu: _parse_raw_binary walks the appended
     blocks by their UInt64 byte counts and matches each to the DataArray whose offset it starts at;
     VtuReader.read_data decodes one array) - skipped, with "meshio no" printed, when meshio is not installed;
  2. by this script: xml.etree for the XML, struct for the appended blocks, checking that the blocks tile the
     appended section exactly (each array starts where the previous ended, nothing after the last).
The two must agree value for value (exit 1 otherwise). Output, one record per line:
  meshio yes|no
  dataset <timestep> <part> <file>                  (the .pvd entries, in order)
  file <file> <VTKFile type>
  attr <name> <value>                               (attributes of the dataset element, e.g. WholeExtent)
  piece <name> <value>                              (attributes of the Piece)
  array <section> <name> <type> <components> <count> <values...>   (floats as repr: exact doubles)
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


def fmt_value(v):
    return repr(float(v)) if isinstance(v, float) else str(int(v))


def read_file(path, name):
    with open(path, "rb") as f:
        raw = f.read()
    root, data = split_file(raw, path)
    kind = root.get("type")
    arrays, values = decode_struct(root, data, path)
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
    print("end")


def main():
    pvd = sys.argv[1]
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
