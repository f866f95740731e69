"""Colours of arbitrary surface points of a mesh, fetched in one ``points`` batch.

A point on a mesh (in mesh coordinates) takes the colour of the finest voxel nearest its placed
position, exactly what ``surface`` gives a vertex and ``points`` gives the placed point. The
client places the points itself (:mod:`solidtex_client.placement`, the service's arithmetic),
rounds them to voxels, and sends each distinct voxel once as integer coordinates (exact in the
float32 body), so the service synthesizes only what those voxels depend on: unlike a ``surface``
request with extra ``points``, which synthesizes every vertex's voxel as well.

:func:`mesh_on_server` gives the mesh both sides agree on: a stored mesh's cleaned triangles
(``GET /v1/meshes/{id}/file``) and its ``bounds`` (which its placement is fit to).
"""
from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Dict, Iterator, Optional, Tuple

import numpy as np

from .errors import NotFound
from .mesh import MeshInput, TriangleMesh, mesh_bytes, parse_mesh_ply
from .placement import Placement, nearest_voxels

if TYPE_CHECKING:  # pragma: no cover
    from .client import Client


@dataclass
class SurfaceColors:
    """Colours of surface points: ``linear`` float32 (N, 3) linear RGB per point, ``voxels``
    int64 (N, 3) the voxel each point took its colour from, ``distinct_voxels`` how many
    distinct voxels were asked for, ``voxels_synthesized`` what the service synthesized for
    them (its ``X-Voxels-Synthesized``: every level's dependent voxels not already cached)."""

    linear: np.ndarray
    voxels: np.ndarray
    distinct_voxels: int
    voxels_synthesized: int


def surface_colors(client: "Client", volume_id: str, points: Any, placement: Placement,
                   timeout: Optional[float] = None) -> SurfaceColors:
    """Colours of mesh-coordinate ``points`` (N, 3) placed by ``placement``, from one
    ``points`` request on ``volume_id`` (``timeout``: its server-side deadline, seconds).

    The request holds each distinct voxel once; the answer's row for a point is exactly the
    ``points`` answer at the point's placed position. N may be 0 (no request is made).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    voxels = nearest_voxels(placement.apply(pts))
    if len(voxels) == 0:
        return SurfaceColors(np.zeros((0, 3), np.float32), voxels, 0, 0)
    distinct, inverse = np.unique(voxels, axis=0, return_inverse=True)
    rgb = client.points(volume_id, distinct.astype(np.float64), timeout=timeout)
    synthesized = int(client.last_response.headers.get("X-Voxels-Synthesized", -1))
    return SurfaceColors(rgb[inverse.reshape(-1)], voxels, len(distinct), synthesized)


@contextlib.contextmanager
def mesh_on_server(client: "Client", mesh_id: Optional[str] = None,
                   mesh: Optional[MeshInput] = None
                   ) -> Iterator[Tuple[Dict[str, Any], TriangleMesh]]:
    """``(mesh object, its triangles)`` of a mesh on the service for the ``with`` block.

    Give exactly one of ``mesh_id`` (a stored mesh) and ``mesh`` (a mesh file, path or bytes:
    OBJ, PLY or OFF), which is uploaded for the block and deleted after it. The triangles are
    the service's cleaned ones in mesh coordinates (float32, as its file holds them); the
    object's ``bounds`` are what the service fits placements to.
    """
    if (mesh_id is None) == (mesh is None):
        raise ValueError("give exactly one of mesh_id and mesh")
    uploaded = None
    if mesh_id is not None:
        info = client.get_mesh(mesh_id)
    else:
        name = os.path.basename(os.fspath(mesh)) if isinstance(mesh, (str, os.PathLike)) else None
        info = uploaded = client.upload_mesh(mesh_bytes(mesh), name=name)  # type: ignore[arg-type]
    try:
        yield info, parse_mesh_ply(client.get_mesh_file(info["id"]))
    finally:
        if uploaded is not None:
            with contextlib.suppress(NotFound):
                client.delete_mesh(uploaded["id"])
