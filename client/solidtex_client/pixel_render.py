"""Per-pixel remote rendering: every pixel coloured from the volume at its own surface point.

The mesh is rasterised in the view of :class:`~solidtex_client.render.View` (the same view as
the per-vertex :func:`~solidtex_client.render.render`): each object pixel gets the nearest face
under its centre and the barycentric weights of the centre on it, hence its *surface point*,
the weights applied to the face's three mesh-coordinate corners. All surface points go to the
service in one ``points`` batch (:func:`~solidtex_client.surface_colors.surface_colors`: each
distinct voxel once; compact pieces if the service refuses the batch as too large), so the colour is resolved per pixel at voxel resolution and only the
voxels behind visible pixels (and what they depend on) are synthesized; the vertices are not.

Unlit, an object pixel's sRGB8 value is exactly the service's sRGB8 encoding of the ``points``
answer at its surface point (:func:`~solidtex_client.srgb.encode_srgb8`). Lit, the linear colour
is scaled by the face's Lambert factor (:func:`~solidtex_client.render.face_shade`) before the
encoding: shading is applied to light, not to sRGB codes.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Dict, Mapping, Optional, Sequence

import numpy as np

from .mesh import MeshInput, TriangleMesh
from .placement import Placement, placement_from
from .render import View, face_shade, image_size
from .srgb import encode_srgb8
from .surface_colors import mesh_on_server, surface_colors

if TYPE_CHECKING:  # pragma: no cover
    from .client import Client


@dataclass
class PixelRender:
    """A per-pixel render of size (W, H).

    ``image`` uint8 (H, W, 3) sRGB, white background. ``face`` int64 (H, W): the face under
    each pixel, -1 for background. ``surface`` float64 (H, W, 3): the pixel's surface point in
    mesh coordinates (NaN for background). ``linear`` float32 (H, W, 3): the unshaded linear
    colour from the volume (0 for background). ``voxels`` int64 (H, W, 3): the voxel each object
    pixel shows (0 for background). ``view`` the camera, ``placement`` the mesh's placement in
    the volume, ``mesh`` the triangles rendered. ``stats``: ``object_pixels``,
    ``distinct_voxels`` (voxels asked for), ``voxels_synthesized`` (the service's count),
    ``points_requests`` (1 unless the service needed pieces), and the seconds spent
    rasterising, fetching and shading.
    """

    image: np.ndarray
    face: np.ndarray
    surface: np.ndarray
    linear: np.ndarray
    voxels: np.ndarray
    view: View
    placement: Placement
    mesh: TriangleMesh
    stats: Dict[str, Any] = field(default_factory=dict)


def surface_points(vertices: np.ndarray, faces: np.ndarray, face: np.ndarray,
                   bary: np.ndarray) -> np.ndarray:
    """float64 (..., 3): for each entry of ``face`` (>= 0) the point with barycentric weights
    ``bary`` (..., 3) on that face's corners; NaN where ``face`` is -1."""
    verts = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    face = np.asarray(face)
    out = np.full(face.shape + (3,), np.nan)
    hit = face >= 0
    corners = verts[faces[face[hit]]]                         # (n, 3 corners, 3)
    out[hit] = (np.asarray(bary)[hit][:, :, None] * corners).sum(1)
    return out


def render_pixels(client: "Client", volume_id: str, mesh_id: Optional[str] = None,
                  mesh: Optional[MeshInput] = None,
                  placement: Optional[Mapping[str, Any]] = None, azimuth: float = 30.0,
                  elevation: float = 20.0, size: Sequence[int] = (512, 512),
                  light: bool = True, up: str = "y", border: float = 0.05,
                  timeout: Optional[float] = None) -> PixelRender:
    """Render ``mesh`` textured by volume ``volume_id`` with one colour per pixel.

    Give a stored mesh's ``mesh_id`` or a ``mesh`` file (path or bytes; uploaded for the call
    and deleted after, see :func:`~solidtex_client.surface_colors.mesh_on_server`). ``placement``
    as for :meth:`~solidtex_client.client.Client.surface` (default: resolution 512, margin
    0.25). View arguments as for :func:`~solidtex_client.render.render`; ``size`` = (W, H) is
    at most :data:`~solidtex_client.render.MAX_IMAGE_SIDE` (4096) per side: the render's
    arrays take up to ~225 bytes per pixel (~4 GB at 4096², the mesh filling the view), so a
    larger image is refused (ValueError naming ``size``) before anything is sent.
    ``timeout``: the ``points`` request's server-side deadline, seconds.
    """
    w, h = image_size(size)
    with mesh_on_server(client, mesh_id, mesh) as (info, tri):
        place = placement_from(placement, info["bounds"])
        t0 = time.monotonic()
        view = View(tri.vertices, tri.faces, azimuth, elevation, (w, h), up, border)
        face, bary = view.rasterize(tri.vertices, tri.faces)
        surface = surface_points(tri.vertices, tri.faces, face, bary)
        hit = face >= 0
        t1 = time.monotonic()
        colors = surface_colors(client, volume_id, surface[hit], place, timeout=timeout)
        t2 = time.monotonic()
    linear = np.zeros((h, w, 3), np.float32)
    linear[hit] = colors.linear
    voxels = np.zeros((h, w, 3), np.int64)
    voxels[hit] = colors.voxels
    shaded = linear[hit]
    if light:
        shade = face_shade(tri.vertices, tri.faces, view.light())[face[hit]]
        shaded = (shaded * shade[:, None]).astype(np.float32)
    image = np.full((h, w, 3), 255, np.uint8)
    image[hit] = encode_srgb8(shaded)
    t3 = time.monotonic()
    stats = {"object_pixels": int(hit.sum()), "distinct_voxels": colors.distinct_voxels,
             "voxels_synthesized": colors.voxels_synthesized,
             "points_requests": colors.requests, "faces": int(len(tri.faces)),
             "rasterize_seconds": round(t1 - t0, 4), "points_seconds": round(t2 - t1, 4),
             "shade_seconds": round(t3 - t2, 4)}
    return PixelRender(image, face, surface, linear, voxels, view, place, tri, stats)
