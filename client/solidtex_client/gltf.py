"""A binary glTF 2.0 (.glb) writer for one textured triangle mesh.

The file holds one scene with one node and one mesh primitive: ``POSITION`` (float32 VEC3, with
the ``min``/``max`` the specification requires), ``NORMAL`` (optional, unit float32 VEC3),
``TEXCOORD_0`` (float32 VEC2) and uint32 indices, and one material whose
``pbrMetallicRoughness.baseColorTexture`` is the PNG embedded in the binary chunk (glTF
reads base colour textures as sRGB). UV (0, 0) is the image's top-left corner and v grows
downwards, glTF's convention: texel (i, j), column i of row j, covers u in [i/W, (i+1)/W) and
v in [j/H, (j+1)/H). The material is double-sided (the service accepts unoriented meshes),
fully rough and not metallic; the sampler filters trilinearly and clamps at the edges.
"""
from __future__ import annotations

import json
import struct
from typing import Any, Dict, List, Mapping, Optional

import numpy as np

_FLOAT, _UINT32 = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_LINEAR, _LINEAR_MIPMAP_LINEAR, _CLAMP_TO_EDGE = 9729, 9987, 33071
_GLB_MAGIC, _JSON_CHUNK, _BIN_CHUNK = 0x46546C67, 0x4E4F534A, 0x004E4942


def _pad4(data: bytes, fill: bytes) -> bytes:
    return data + fill * (-len(data) % 4)


def write_glb(positions: Any, indices: Any, uvs: Any, png: bytes,
              normals: Optional[Any] = None, name: str = "solidtex",
              extras: Optional[Mapping[str, Any]] = None) -> bytes:
    """The .glb bytes of a mesh with ``positions`` (V, 3), ``indices`` (M, 3) into them,
    ``uvs`` (V, 2) in glTF's convention (module doc), optional unit ``normals`` (V, 3), and
    the base colour texture ``png`` (PNG bytes, sRGB). ``extras`` (JSON-serialisable) go on
    the node. Raises ``ValueError`` for inconsistent shapes, indices out of range, non-finite
    values or bytes that are not a PNG."""
    pos = np.ascontiguousarray(np.asarray(positions, dtype="<f4").reshape(-1, 3))
    idx = np.ascontiguousarray(np.asarray(indices, dtype=np.int64).reshape(-1, 3))
    uv = np.ascontiguousarray(np.asarray(uvs, dtype="<f4").reshape(-1, 2))
    if len(pos) == 0 or len(idx) == 0:
        raise ValueError("a glTF mesh needs at least one vertex and one triangle")
    if len(uv) != len(pos):
        raise ValueError(f"{len(pos)} positions but {len(uv)} uvs")
    if idx.min() < 0 or idx.max() >= len(pos):
        raise ValueError("index out of range")
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(uv))):
        raise ValueError("positions and uvs must be finite")
    if not bytes(png[:8]) == b"\x89PNG\r\n\x1a\n":
        raise ValueError("the texture must be PNG bytes")
    arrays: List[tuple] = [("POSITION", pos, "VEC3", _FLOAT, _ARRAY_BUFFER)]
    if normals is not None:
        nrm = np.ascontiguousarray(np.asarray(normals, dtype="<f4").reshape(-1, 3))
        if len(nrm) != len(pos):
            raise ValueError(f"{len(pos)} positions but {len(nrm)} normals")
        arrays.append(("NORMAL", nrm, "VEC3", _FLOAT, _ARRAY_BUFFER))
    arrays.append(("TEXCOORD_0", uv, "VEC2", _FLOAT, _ARRAY_BUFFER))
    arrays.append(("indices", idx.astype("<u4").reshape(-1), "SCALAR", _UINT32,
                   _ELEMENT_ARRAY_BUFFER))

    blob = bytearray()
    views: List[Dict[str, Any]] = []
    accessors: List[Dict[str, Any]] = []
    attributes: Dict[str, int] = {}
    for key, data, kind, component, target in arrays:
        raw = data.tobytes()
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(raw),
                      "target": target})
        blob += _pad4(raw, b"\0")
        acc: Dict[str, Any] = {"bufferView": len(views) - 1, "componentType": component,
                               "count": int(len(data)), "type": kind}
        if key == "POSITION":
            acc["min"] = [float(v) for v in pos.min(0)]
            acc["max"] = [float(v) for v in pos.max(0)]
        accessors.append(acc)
        if key != "indices":
            attributes[key] = len(accessors) - 1
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(png)})
    blob += _pad4(bytes(png), b"\0")
    node: Dict[str, Any] = {"mesh": 0, "name": name}
    if extras:
        node["extras"] = dict(extras)
    doc = {
        "asset": {"version": "2.0", "generator": "solidtex-client bake"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [node],
        "meshes": [{"name": name, "primitives": [{
            "attributes": attributes, "indices": len(accessors) - 1, "material": 0,
            "mode": 4}]}],
        "materials": [{"name": name, "doubleSided": True, "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "texCoord": 0},
            "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "textures": [{"sampler": 0, "source": 0}],
        "samplers": [{"magFilter": _LINEAR, "minFilter": _LINEAR_MIPMAP_LINEAR,
                      "wrapS": _CLAMP_TO_EDGE, "wrapT": _CLAMP_TO_EDGE}],
        "images": [{"bufferView": len(views) - 1, "mimeType": "image/png"}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    text = _pad4(json.dumps(doc, separators=(",", ":")).encode("utf-8"), b" ")
    body = bytes(blob)
    total = 12 + 8 + len(text) + 8 + len(body)
    return (struct.pack("<III", _GLB_MAGIC, 2, total)
            + struct.pack("<II", len(text), _JSON_CHUNK) + text
            + struct.pack("<II", len(body), _BIN_CHUNK) + body)
