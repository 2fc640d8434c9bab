"""Reads the VTK files beamrail writes (optimizer/output/vtk_output.hpp): .pvd collections whose frames
are XML PolyData (.vtp) with raw appended data. A reader for that subset of the format, so that the
report needs no VTK library; the tests read the same files with VTK's own readers."""

import json
import os
import xml.etree.ElementTree as ET

import numpy as np

_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt8": "u1",
          "UInt64": "<u8"}


class PolyData:
    """One .vtp file: points (n x 3), point_data / cell_data / field_data (name -> array, or a
    list of str for string arrays), and cells {"Verts"|"Lines"|"Polys": list of index arrays}."""

    def __init__(self, path):
        with open(path, "rb") as f:
            raw = f.read()
        start = raw.index(b"<AppendedData")
        data = raw.index(b"_", raw.index(b">", start)) + 1
        root = ET.fromstring(raw[:start] + b"</VTKFile>")
        if root.get("header_type") != "UInt64" or root.get("byte_order") != "LittleEndian":
            raise ValueError(f"{path}: not a file beamrail wrote (header {root.attrib})")

        def array(node):
            offset = data + int(node.get("offset"))
            size = int(np.frombuffer(raw, "<u8", 1, offset)[0])
            block = raw[offset + 8:offset + 8 + size]
            if node.get("type") == "String":
                return [s.decode() for s in block.split(b"\0")[:-1]]
            values = np.frombuffer(block, _TYPES[node.get("type")])
            n = int(node.get("NumberOfComponents", "1"))
            return values.reshape(-1, n) if n > 1 else values

        poly = root.find("PolyData")
        self.field_data = {}
        fd = poly.find("FieldData")
        if fd is not None:
            for a in fd:
                self.field_data[a.get("Name")] = array(a)[0]
        piece = poly.find("Piece")
        self.points = array(piece.find("Points")[0])
        self.point_data = {a.get("Name"): array(a) for a in piece.find("PointData") or []}
        self.cell_data = {a.get("Name"): array(a) for a in piece.find("CellData") or []}
        self.cells = {}
        for kind in ("Verts", "Lines", "Polys"):
            node = piece.find(kind)
            if node is None:
                continue
            arrays = {a.get("Name"): array(a) for a in node}
            ends = arrays["offsets"]
            starts = np.concatenate([[0], ends[:-1]])
            conn = arrays["connectivity"]
            self.cells[kind] = [conn[s:e] for s, e in zip(starts, ends)]


class Collection:
    """A .pvd file: frames in file order, each a (time, {part name: path})."""

    def __init__(self, path):
        self.path = path
        folder = os.path.dirname(path)
        frames = {}
        order = []
        for d in ET.parse(path).getroot().find("Collection"):
            t = d.get("timestep")
            if t not in frames:
                frames[t] = {}
                order.append(t)
            frames[t][d.get("name") or d.get("part")] = os.path.join(folder, d.get("file"))
        self.frames = [(float(t), frames[t]) for t in order]

    def read(self, k, part):
        return PolyData(self.frames[k][1][part])


def contents(results):
    """vtk/contents.json of a results folder, or None."""
    path = os.path.join(results, "vtk", "contents.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)
