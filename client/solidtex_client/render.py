"""A small software renderer for colored triangle meshes (numpy only).

Orthographic camera looking at the centre of the mesh's bounding box from ``azimuth`` and
``elevation`` degrees, the mesh fit to the image with a small border (:class:`View`), a
z-buffer (:func:`~solidtex_client.raster.rasterize`), per-vertex colors interpolated
barycentrically, optional Lambert shading with face normals (:func:`face_shade`: ``ambient 0.35
+ 0.65 |n . l|``, light from the camera, a little above and to the left), white background;
the silhouette is centred in the image. Triangles that cover no pixel centre are splatted onto
their nearest pixel, so dense meshes at small image sizes show no holes.

This is the per-vertex renderer; :mod:`solidtex_client.pixel_render` colours every pixel from
the volume instead, with the same view and shading.
"""
from __future__ import annotations

import math
from typing import Sequence, Tuple

import numpy as np

from .mesh import ColoredMesh
from .raster import rasterize

# The largest image side (W and H) a View, hence render and render_pixels, accepts. The client's
# memory grows with the pixel count: render_pixels peaked at ~225 bytes per pixel with the mesh
# filling a 2048² view (~150 with half of it covered; tracemalloc), so 4096² takes up to ~4 GB
# and 8192² would take ~15 GB.
MAX_IMAGE_SIDE = 4096

_UP = {"y": (np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])),
       "z": (np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]))}


def image_size(size: Sequence[int]) -> Tuple[int, int]:
    """``(W, H)`` of an image ``size``, each an integer in [1, :data:`MAX_IMAGE_SIDE`]; a
    ValueError naming ``size`` otherwise."""
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be two integers (W, H), got {size!r}") from None
    if not (1 <= w <= MAX_IMAGE_SIDE and 1 <= h <= MAX_IMAGE_SIDE):
        raise ValueError(f"size must be in [1, {MAX_IMAGE_SIDE}] pixels per side, got {(w, h)} "
                         f"(memory grows with the pixel count, ~225 bytes per pixel)")
    return w, h


def camera_basis(azimuth: float, elevation: float, up: str = "y") -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(right, camera_up, towards_camera) unit vectors for the view.

    With ``up="y"``, azimuth 0 and elevation 0 look from +z towards -z (x to the right, y
    up); positive azimuth turns the camera towards +x, positive elevation raises it. With
    ``up="z"`` the same view looks from -y.
    """
    if up not in _UP:
        raise ValueError("up must be 'y' or 'z'")
    upv, front, side = _UP[up]
    az, el = math.radians(azimuth), math.radians(elevation)
    c = math.cos(el) * (math.cos(az) * front + math.sin(az) * side) + math.sin(el) * upv
    c /= np.linalg.norm(c)
    right = np.cross(upv, c)
    n = np.linalg.norm(right)
    if n < 1e-9:  # looking straight along the up axis
        right = math.cos(az) * side - math.sin(az) * front
        n = np.linalg.norm(right)
    right /= n
    cam_up = np.cross(c, right)
    return right, cam_up / np.linalg.norm(cam_up), c


class View:
    """An orthographic view of a mesh fit to a ``size`` = (W, H) image (:func:`image_size`: at
    most :data:`MAX_IMAGE_SIDE` per side).

    ``right``, ``up``, ``towards`` are the camera's unit axes (:func:`camera_basis`); a mesh
    point p lands at pixel coordinates ``x = W/2 + k ((p - c).right - ox)``, ``y = H/2 -
    k ((p - c).up - oy)`` (``c`` the centre of the used vertices' box, ``k`` = ``scale``
    pixels per mesh unit, (``ox``, ``oy``) = ``shift`` centres the silhouette) with depth
    ``(p - c).towards`` (larger is nearer).
    ``border`` is the fraction of the smaller image side left empty around the mesh (at
    least one pixel).
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, azimuth: float = 30.0,
                 elevation: float = 20.0, size: Sequence[int] = (512, 512), up: str = "y",
                 border: float = 0.05) -> None:
        w, h = image_size(size)
        self.width, self.height = w, h
        self.right, self.up, self.towards = camera_basis(azimuth, elevation, up)
        verts = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        used = np.unique(faces) if len(faces) else np.arange(len(verts))
        if len(used) == 0:
            self.centre, self.scale, self.shift = np.zeros(3), 1.0, np.zeros(2)
            return
        lo, hi = verts[used].min(0), verts[used].max(0)
        self.centre = (lo + hi) / 2
        p = verts[used] - self.centre
        sx, sy = p @ self.right, p @ self.up
        # centre the silhouette's extent (an orthographic view: a shift within the image plane)
        self.shift = np.array([(sx.max() + sx.min()) / 2, (sy.max() + sy.min()) / 2])
        sx, sy = sx - self.shift[0], sy - self.shift[1]
        pad = max(1.0, border * min(w, h))
        ext_x = max(np.abs(sx).max(), 1e-300)
        ext_y = max(np.abs(sy).max(), 1e-300)
        self.scale = min(max(w / 2 - pad, 0.5) / ext_x, max(h / 2 - pad, 0.5) / ext_y)

    def project(self, points: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pixel coordinates (x, y) and depth of mesh-coordinate ``points`` (..., 3)."""
        p = np.asarray(points, np.float64) - self.centre
        x = self.width / 2 + self.scale * (p @ self.right - self.shift[0])
        y = self.height / 2 - self.scale * (p @ self.up - self.shift[1])
        return x, y, p @ self.towards

    def light(self) -> np.ndarray:
        """The unit direction towards the light: from the camera, a little above and left."""
        d = self.towards + 0.4 * self.up - 0.3 * self.right
        return d / np.linalg.norm(d)

    def rasterize(self, vertices: np.ndarray, faces: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """``(face, bary)`` buffers of the mesh in this view (see
        :func:`~solidtex_client.raster.rasterize`); degenerate faces are not drawn."""
        verts = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        x, y, z = self.project(verts)
        return rasterize(x[faces], y[faces], z[faces], self.width, self.height)


def face_shade(vertices: np.ndarray, faces: np.ndarray, light: np.ndarray) -> np.ndarray:
    """Lambert factor per face, ``0.35 + 0.65 |n . light|`` with the unit face normal ``n``
    (both sides lit alike: meshes need not be oriented); 1 for degenerate faces."""
    verts = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    n = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    n_len = np.linalg.norm(n, axis=1)
    cos = np.abs(n @ light) / np.maximum(n_len, 1e-300)
    return np.where(n_len > 0, 0.35 + 0.65 * cos, 1.0)


def render(mesh: ColoredMesh, azimuth: float = 30.0, elevation: float = 20.0,
           size: Sequence[int] = (512, 512), light: bool = True, up: str = "y",
           border: float = 0.05) -> np.ndarray:
    """Render ``mesh`` with its per-vertex colors to an sRGB uint8 image of shape (H, W, 3),
    ``size`` = (W, H).

    ``border`` as for :class:`View`. ``light=False`` shows the interpolated vertex colors
    unshaded; with light the sRGB8 vertex colors are scaled by :func:`face_shade`.
    """
    view = View(mesh.vertices, mesh.faces, azimuth, elevation, size, up, border)
    img = np.full((view.height, view.width, 3), 255, np.uint8)
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        return img
    face, bary = view.rasterize(mesh.vertices, faces)
    hit = face >= 0
    f = face[hit]
    col = np.asarray(mesh.colors, dtype=np.float64)[faces[f]]       # (n, 3 corners, 3)
    rgb = (bary[hit][:, :, None] * col).sum(1)
    if light:
        rgb *= face_shade(mesh.vertices, faces, view.light())[f][:, None]
    img[hit] = np.clip(np.rint(rgb), 0, 255).astype(np.uint8)
    return img
