"""Colours of arbitrary surface points of a mesh, fetched in one ``points`` batch (or pieces).

A point on a mesh (in mesh coordinates) takes the colour of the finest voxel nearest its placed
position, exactly what ``surface`` gives a vertex and ``points`` gives the placed point. The
client places the points itself (:mod:`solidtex_client.placement`, the service's arithmetic),
rounds them to voxels, and sends each distinct voxel once as integer coordinates (exact in the
float32 body), so the service synthesizes only what those voxels depend on: unlike a ``surface``
request with extra ``points``, which synthesizes every vertex's voxel as well.

All voxels go in one ``points`` request when the service's per-request limits admit it. A
large surface (the bunny at resolution 512 needs ~3.4 GB of working memory at once; the
default ``--max-request-mb`` is 1536) is refused before any work (422); the voxels are then
split in two at the median of their longest axis, recursively, until every piece is admitted
(:func:`voxel_colors`). Pieces are compact and sent neighbour after neighbour, so the
dependency halo they share is mostly found in the service's voxel cache.

:func:`mesh_on_server` gives the mesh both sides agree on: a stored mesh's cleaned triangles
(``GET /v1/meshes/{id}/file``) and its ``bounds`` (which its placement is fit to).
"""
from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Dict, Iterator, List, Optional, Tuple

import numpy as np

from .errors import NotFound, PayloadTooLarge, SolidtexError, Unprocessable
from .mesh import MeshInput, TriangleMesh, mesh_bytes, parse_mesh_ply
from .placement import Placement, nearest_voxels

if TYPE_CHECKING:  # pragma: no cover
    from .client import Client


@dataclass
class SurfaceColors:
    """Colours of surface points: ``linear`` float32 (N, 3) linear RGB per point, ``voxels``
    int64 (N, 3) the voxel each point took its colour from, ``distinct_voxels`` how many
    distinct voxels were asked for, ``voxels_synthesized`` what the service synthesized for
    them (the sum of its ``X-Voxels-Synthesized``: every level's dependent voxels not already
    cached), ``requests`` how many ``points`` requests it took (1 unless pieces were needed)."""

    linear: np.ndarray
    voxels: np.ndarray
    distinct_voxels: int
    voxels_synthesized: int
    requests: int = 1


def _too_large(error: SolidtexError) -> bool:
    """The service refused a points request for its size: 422 over the working-memory limit or
    ``--max-voxels`` (field ``points``; servers before this one named the memory limit ``size``),
    413 over the upload limit."""
    return isinstance(error, PayloadTooLarge) or (
        isinstance(error, Unprocessable) and error.field in ("size", "points"))


def _halves(voxels: np.ndarray, idx: np.ndarray) -> List[np.ndarray]:
    """``idx`` split at the median of its voxels' longest axis (near half first)."""
    v = voxels[idx]
    axis = int(np.argmax(v.max(0) - v.min(0)))
    order = idx[np.argsort(v[:, axis], kind="stable")]
    half = len(order) // 2
    return [order[half:], order[:half]]    # a stack: the first half is sent first


def voxel_colors(client: "Client", volume_id: str, voxels: np.ndarray,
                 timeout: Optional[float] = None) -> Tuple[np.ndarray, int, int]:
    """Linear colours float32 (N, 3) of integer ``voxels`` (N, 3), with the voxels the service
    synthesized for them and the number of ``points`` requests.

    One request when the service admits it; a request refused for its size is split in two
    (:func:`_halves`) and each half tried, depth first; once a piece of some size has been
    refused, pieces at least as large are split before they are sent. Any other error, or a
    refused single voxel, is raised.
    """
    out = np.empty((len(voxels), 3), np.float32)
    synthesized = requests = 0
    refused: Optional[int] = None
    stack = [np.arange(len(voxels))]
    while stack:
        idx = stack.pop()
        if refused is not None and len(idx) >= refused and len(idx) > 1:
            stack.extend(_halves(voxels, idx))
            continue
        try:
            rgb = client.points(volume_id, voxels[idx].astype(np.float64), timeout=timeout)
        except SolidtexError as e:
            if len(idx) <= 1 or not _too_large(e):
                raise
            refused = len(idx) if refused is None else min(refused, len(idx))
            stack.extend(_halves(voxels, idx))
            continue
        out[idx] = rgb
        synthesized += int(client.last_response.headers["X-Voxels-Synthesized"])
        requests += 1
    return out, synthesized, requests


def surface_colors(client: "Client", volume_id: str, points: Any, placement: Placement,
                   timeout: Optional[float] = None) -> SurfaceColors:
    """Colours of mesh-coordinate ``points`` (N, 3) placed by ``placement``, from one
    ``points`` request on ``volume_id`` (or compact pieces when the service refuses one for
    its size, see :func:`voxel_colors`; ``timeout``: each request's server-side deadline,
    seconds).

    Each distinct voxel is asked for once; the answer's row for a point is exactly the
    ``points`` answer at the point's placed position. N may be 0 (no request is made).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    voxels = nearest_voxels(placement.apply(pts))
    if len(voxels) == 0:
        return SurfaceColors(np.zeros((0, 3), np.float32), voxels, 0, 0, 0)
    distinct, inverse = np.unique(voxels, axis=0, return_inverse=True)
    rgb, synthesized, requests = voxel_colors(client, volume_id, distinct, timeout=timeout)
    return SurfaceColors(rgb[inverse.reshape(-1)], voxels, len(distinct), synthesized, requests)


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
