"""Colored triangle meshes as the service sends them (``POST /v1/volumes/{id}/surface``).

The PLY answer is binary little-endian 1.0 with exactly::

    element vertex N      property float x, y, z          (mesh coordinates)
                          property uchar red, green, blue (sRGB8)
    element face M        property list uchar int vertex_indices   (triangles)

:func:`parse_colored_ply` reads that layout (comments allowed) and raises
:class:`PlyFormatError` (a ``ValueError``) for anything else; :meth:`ColoredMesh.to_ply`
writes it. A stored mesh's file (``GET /v1/meshes/{id}/file``) has the same layout without the
colour properties: :func:`parse_mesh_ply` reads it as a :class:`TriangleMesh`.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

MeshInput = Union[str, "os.PathLike[str]", bytes, bytearray, memoryview]

_FLOAT = {"float", "float32"}
_UCHAR = {"uchar", "uint8"}
_INT = {"int", "int32"}
_VERTEX_PROPS = {"x": _FLOAT, "y": _FLOAT, "z": _FLOAT,
                 "red": _UCHAR, "green": _UCHAR, "blue": _UCHAR}
_POSITION_PROPS = {"x", "y", "z"}
_COLOR_PROPS = {"red", "green", "blue"}
_FACE_DTYPE = np.dtype([("n", "u1"), ("i", "<i4", (3,))])  # packed: 13 bytes per face


class PlyFormatError(ValueError):
    """The bytes are not a colored PLY in the layout the service sends."""


def mesh_bytes(mesh: MeshInput) -> bytes:
    """The bytes of a mesh file: ``mesh`` is a path or the bytes themselves."""
    if isinstance(mesh, (bytes, bytearray, memoryview)):
        return bytes(mesh)
    if isinstance(mesh, (str, os.PathLike)):
        with open(mesh, "rb") as f:
            return f.read()
    raise TypeError(f"unsupported mesh type {type(mesh).__name__}: give a path or bytes")


@dataclass
class ColoredMesh:
    """A triangle mesh with one sRGB8 color per vertex.

    ``vertices`` float32 (N, 3) in mesh coordinates, ``colors`` uint8 (N, 3) sRGB,
    ``faces`` int32 (M, 3) vertex indices, ``headers`` the HTTP headers of the answer
    (``X-Target-Voxels``, ``X-Bounding-Voxels``, ``X-Voxels-Synthesized``) when it came
    from the service.
    """

    vertices: np.ndarray
    colors: np.ndarray
    faces: np.ndarray
    headers: Dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(np.asarray(self.vertices, dtype=np.float32).reshape(-1, 3))
        self.colors = np.ascontiguousarray(np.asarray(self.colors).reshape(-1, 3))
        if self.colors.dtype != np.uint8:
            c = self.colors
            if c.size and (np.min(c) < 0 or np.max(c) > 255):
                raise ValueError("colors must lie in [0, 255]")
            self.colors = c.astype(np.uint8)
        self.faces = np.ascontiguousarray(np.asarray(self.faces, dtype=np.int32).reshape(-1, 3))
        if len(self.colors) != len(self.vertices):
            raise ValueError(f"{len(self.vertices)} vertices but {len(self.colors)} colors")
        if self.faces.size and (self.faces.min() < 0 or self.faces.max() >= len(self.vertices)):
            raise ValueError("face index out of range")

    def header_int(self, name: str) -> int:
        """An integer header of the service's answer (``KeyError`` if absent)."""
        for k, v in self.headers.items():
            if k.lower() == name.lower():
                return int(v)
        raise KeyError(name)

    def to_ply(self) -> bytes:
        """Binary little-endian PLY bytes in the layout :func:`parse_colored_ply` reads."""
        n, m = len(self.vertices), len(self.faces)
        head = ("ply\nformat binary_little_endian 1.0\n"
                f"element vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
                "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                f"element face {m}\nproperty list uchar int vertex_indices\nend_header\n")
        vdt = np.dtype([("p", "<f4", (3,)), ("c", "u1", (3,))])
        v = np.empty(n, vdt)
        v["p"] = self.vertices
        v["c"] = self.colors
        f = np.empty(m, _FACE_DTYPE)
        f["n"] = 3
        f["i"] = self.faces
        return head.encode("ascii") + v.tobytes() + f.tobytes()


@dataclass
class TriangleMesh:
    """A triangle mesh: ``vertices`` float32 (N, 3) in mesh coordinates, ``faces`` int32
    (M, 3) vertex indices."""

    vertices: np.ndarray
    faces: np.ndarray

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(np.asarray(self.vertices, dtype=np.float32).reshape(-1, 3))
        self.faces = np.ascontiguousarray(np.asarray(self.faces, dtype=np.int32).reshape(-1, 3))
        if self.faces.size and (self.faces.min() < 0 or self.faces.max() >= len(self.vertices)):
            raise ValueError("face index out of range")


def _header(data: bytes) -> Tuple[List[List[str]], int]:
    if not data.startswith(b"ply"):
        raise PlyFormatError("not a PLY file (no 'ply' magic)")
    end = data.find(b"end_header")
    if end < 0 or end > 65536:
        raise PlyFormatError("PLY header has no 'end_header' line in its first 64 KiB")
    nl = data.find(b"\n", end)
    if nl < 0:
        raise PlyFormatError("PLY header ends without a newline after 'end_header'")
    try:
        text = data[:end].decode("ascii")
    except UnicodeDecodeError:
        raise PlyFormatError("PLY header is not ASCII")
    lines = [ln.strip().split() for ln in text.replace("\r", "").split("\n")]
    return [ln for ln in lines if ln], nl + 1


def parse_colored_ply(data: Union[bytes, bytearray, memoryview]) -> ColoredMesh:
    """A :class:`ColoredMesh` from the service's colored PLY bytes (layout: module doc).

    Raises :class:`PlyFormatError` for another format (ASCII, big-endian), other or missing
    properties, non-triangle faces, out-of-range indices, or a body of the wrong length.
    """
    vertices, colors, faces = _parse_ply(data, colors=True)
    return ColoredMesh(vertices, colors, faces)


def parse_mesh_ply(data: Union[bytes, bytearray, memoryview]) -> TriangleMesh:
    """A :class:`TriangleMesh` from a stored mesh's file (the module doc's layout without
    colours; colours, when present, are read and dropped). Errors as for
    :func:`parse_colored_ply`."""
    vertices, _, faces = _parse_ply(data, colors=False)
    return TriangleMesh(vertices, faces)


def _parse_ply(data: Union[bytes, bytearray, memoryview], colors: bool
               ) -> Tuple[np.ndarray, Optional[np.ndarray], np.ndarray]:
    data = bytes(data)
    lines, body_at = _header(data)
    if lines[0] != ["ply"]:
        raise PlyFormatError("first line must be 'ply'")
    elements: List[Dict[str, Any]] = []
    fmt = None
    for ln in lines[1:]:
        key = ln[0]
        if key in ("comment", "obj_info"):
            continue
        if key == "format":
            fmt = ln[1:]
        elif key == "element":
            if len(ln) != 3 or not ln[2].isdigit():
                raise PlyFormatError(f"bad element line {' '.join(ln)!r}")
            elements.append({"name": ln[1], "count": int(ln[2]), "props": []})
        elif key == "property":
            if not elements:
                raise PlyFormatError("property before any element")
            elements[-1]["props"].append(ln[1:])
        else:
            raise PlyFormatError(f"unexpected header line {' '.join(ln)!r}")
    if fmt != ["binary_little_endian", "1.0"]:
        raise PlyFormatError(f"expected 'format binary_little_endian 1.0', got "
                             f"{' '.join(fmt) if fmt else 'no format line'!r}")
    names = [e["name"] for e in elements]
    if names != ["vertex", "face"]:
        raise PlyFormatError(f"expected elements vertex then face, got {names}")
    vertex, face = elements
    # vertex properties: exactly x, y, z (float) and red, green, blue (uchar), in header order
    fields = []
    seen = set()
    for prop in vertex["props"]:
        if len(prop) != 2 or prop[1] not in _VERTEX_PROPS:
            raise PlyFormatError(f"unexpected vertex property {' '.join(prop)!r} "
                                 "(expected float x,y,z and uchar red,green,blue)")
        typ, name = prop
        if typ not in _VERTEX_PROPS[name]:
            raise PlyFormatError(f"vertex property {name} has type {typ}, expected "
                                 f"{'float' if _VERTEX_PROPS[name] is _FLOAT else 'uchar'}")
        if name in seen:
            raise PlyFormatError(f"vertex property {name} given twice")
        seen.add(name)
        fields.append((name, "<f4" if typ in _FLOAT else "u1"))
    required = _VERTEX_PROPS if colors or seen & _COLOR_PROPS else _POSITION_PROPS
    missing = [k for k in required if k not in seen]
    if missing:
        raise PlyFormatError(f"vertex properties missing: {', '.join(missing)}")
    if len(face["props"]) != 1:
        raise PlyFormatError(f"face must have exactly one property, got {face['props']}")
    fp = face["props"][0]
    if (len(fp) != 4 or fp[0] != "list" or fp[1] not in _UCHAR or fp[2] not in _INT
            or fp[3] not in ("vertex_indices", "vertex_index")):
        raise PlyFormatError(f"face property must be 'list uchar int vertex_indices', got "
                             f"{' '.join(fp)!r}")
    vdt = np.dtype(fields)
    n, m = vertex["count"], face["count"]
    need = n * vdt.itemsize + m * _FACE_DTYPE.itemsize
    have = len(data) - body_at
    if have != need:
        raise PlyFormatError(f"body has {have} bytes; {n} vertices and {m} triangles need {need}")
    v = np.frombuffer(data, vdt, count=n, offset=body_at)
    f = np.frombuffer(data, _FACE_DTYPE, count=m, offset=body_at + n * vdt.itemsize)
    if m and not np.all(f["n"] == 3):
        bad = int(np.flatnonzero(f["n"] != 3)[0])
        raise PlyFormatError(f"face {bad} has {int(f['n'][bad])} vertices; only triangles are read")
    faces = f["i"].astype(np.int32)
    if m and (faces.min() < 0 or faces.max() >= n):
        bad = int(np.flatnonzero((faces < 0).any(1) | (faces >= n).any(1))[0])
        raise PlyFormatError(f"face {bad} has a vertex index out of range [0, {n}): "
                             f"{faces[bad].tolist()}")
    vertices = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float32)
    rgb = None
    if seen & _COLOR_PROPS:
        rgb = np.stack([v["red"], v["green"], v["blue"]], axis=1).astype(np.uint8)
    return vertices, rgb, faces
