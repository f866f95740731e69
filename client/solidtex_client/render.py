"""A small software renderer for colored triangle meshes (numpy only).

Orthographic camera looking at the centre of the mesh's bounding box from ``azimuth`` and
``elevation`` degrees, the mesh fit to the image with a small border, a z-buffer, per-vertex
colors interpolated barycentrically, optional Lambert shading with face normals
(``ambient 0.35 + 0.65 |n . l|``, light from the camera, a little above and to the left), white
background; the silhouette is centred in the image. Triangles are rasterised in batches of
similar screen size, so ~100K triangles take well under a second at 512x512; triangles that
cover no pixel centre are splatted onto their nearest pixel, so dense meshes at small image
sizes show no holes.
"""
from __future__ import annotations

import math
from typing import Sequence, Tuple

import numpy as np

from .mesh import ColoredMesh

_UP = {"y": (np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])),
       "z": (np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]))}
_FRAGMENT_BUDGET = 1 << 21  # candidate pixels per batch


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


def render(mesh: ColoredMesh, azimuth: float = 30.0, elevation: float = 20.0,
           size: Sequence[int] = (512, 512), light: bool = True, up: str = "y",
           border: float = 0.05) -> np.ndarray:
    """Render ``mesh`` to an sRGB uint8 image of shape (H, W, 3), ``size`` = (W, H).

    ``border`` is the fraction of the smaller image side left empty around the mesh (at
    least one pixel). ``light=False`` shows the interpolated vertex colors unshaded.
    """
    w, h = int(size[0]), int(size[1])
    if w < 1 or h < 1:
        raise ValueError(f"image size must be positive, got {tuple(size)}")
    img = np.full((h, w, 3), 255, np.uint8)
    verts = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    colors = np.asarray(mesh.colors, dtype=np.float64).reshape(-1, 3)
    if len(faces) == 0:
        return img
    used = np.unique(faces)
    lo, hi = verts[used].min(0), verts[used].max(0)
    centre = (lo + hi) / 2
    right, cam_up, towards = camera_basis(azimuth, elevation, up)
    p = verts - centre
    sx, sy, depth = p @ right, p @ cam_up, p @ towards
    # centre the silhouette's extent (an orthographic view: a shift within the image plane)
    sx -= (sx[used].max() + sx[used].min()) / 2
    sy -= (sy[used].max() + sy[used].min()) / 2
    pad = max(1.0, border * min(w, h))
    ext_x = max(np.abs(sx[used]).max(), 1e-300)
    ext_y = max(np.abs(sy[used]).max(), 1e-300)
    k = min(max(w / 2 - pad, 0.5) / ext_x, max(h / 2 - pad, 0.5) / ext_y)
    px = w / 2 + k * sx   # pixel (i, j) has its centre at (i + 0.5, j + 0.5)
    py = h / 2 - k * sy

    x, y, z = px[faces], py[faces], depth[faces]                # (M, 3)
    col = colors[faces]                                          # (M, 3 vertices, 3 channels)
    n = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    n_len = np.linalg.norm(n, axis=1)
    solid = n_len > 0                                            # degenerate faces are not drawn
    if light:
        n /= np.maximum(n_len, 1e-300)[:, None]
        ldir = towards + 0.4 * cam_up - 0.3 * right
        ldir /= np.linalg.norm(ldir)
        shade = 0.35 + 0.65 * np.abs(n @ ldir)
        col = col * shade[:, None, None]

    zbuf = np.full(h * w, -np.inf)
    cbuf = np.zeros((h * w, 3))

    def resolve(pix: np.ndarray, dep: np.ndarray, rgb: np.ndarray) -> None:
        if len(pix) == 0:
            return
        order = np.lexsort((dep, pix))
        ps = pix[order]
        last = np.ones(len(ps), bool)
        last[:-1] = ps[1:] != ps[:-1]
        sel = order[last]
        pix, dep, rgb = pix[sel], dep[sel], rgb[sel]
        win = dep > zbuf[pix]
        zbuf[pix[win]] = dep[win]
        cbuf[pix[win]] = rgb[win]

    x0 = np.ceil(x.min(1) - 0.5).astype(np.int64)
    x1 = np.floor(x.max(1) - 0.5).astype(np.int64)
    y0 = np.ceil(y.min(1) - 0.5).astype(np.int64)
    y1 = np.floor(y.max(1) - 0.5).astype(np.int64)
    x0c, x1c = np.maximum(x0, 0), np.minimum(x1, w - 1)
    y0c, y1c = np.maximum(y0, 0), np.minimum(y1, h - 1)
    area = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])

    # Triangles that contain no pixel centre: splat the centroid onto its pixel.
    empty = ((x1 < x0) | (y1 < y0)) & solid
    if empty.any():
        cx, cy = x[empty].mean(1), y[empty].mean(1)
        ix, iy = np.floor(cx).astype(np.int64), np.floor(cy).astype(np.int64)
        ok = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
        resolve((iy * w + ix)[ok], z[empty].mean(1)[ok], col[empty].mean(1)[ok])

    todo = solid & ~empty & (x1c >= x0c) & (y1c >= y0c) & (np.abs(area) > 1e-12)
    ids = np.flatnonzero(todo)
    if len(ids):
        span = np.maximum(x1c[ids] - x0c[ids], y1c[ids] - y0c[ids]) + 1
        bucket = np.ceil(np.log2(span)).astype(np.int64)
        for b in np.unique(bucket):
            s = 1 << int(b)
            group = ids[bucket == b]
            oy, ox = np.divmod(np.arange(s * s), s)
            step = max(1, _FRAGMENT_BUDGET // (s * s))
            for start in range(0, len(group), step):
                t = group[start:start + step]
                qx = x0c[t, None] + ox[None, :]
                qy = y0c[t, None] + oy[None, :]
                valid = (qx <= x1c[t, None]) & (qy <= y1c[t, None])
                ti, oi = np.nonzero(valid)
                tt = t[ti]
                cx, cy = qx[ti, oi] + 0.5, qy[ti, oi] + 0.5
                xa, xb, xc = x[tt, 0], x[tt, 1], x[tt, 2]
                ya, yb, yc = y[tt, 0], y[tt, 1], y[tt, 2]
                inv = 1.0 / area[tt]
                w0 = ((xb - cx) * (yc - cy) - (xc - cx) * (yb - cy)) * inv
                w1 = ((xc - cx) * (ya - cy) - (xa - cx) * (yc - cy)) * inv
                w2 = 1.0 - w0 - w1
                inside = (w0 >= -1e-9) & (w1 >= -1e-9) & (w2 >= -1e-9)
                if not inside.any():
                    continue
                tt, w0, w1, w2 = tt[inside], w0[inside], w1[inside], w2[inside]
                pix = qy[ti, oi][inside] * w + qx[ti, oi][inside]
                dep = w0 * z[tt, 0] + w1 * z[tt, 1] + w2 * z[tt, 2]
                rgb = (w0[:, None] * col[tt, 0] + w1[:, None] * col[tt, 1]
                       + w2[:, None] * col[tt, 2])
                resolve(pix, dep, rgb)

    hit = np.isfinite(zbuf)
    flat = img.reshape(-1, 3)
    flat[hit] = np.clip(np.rint(cbuf[hit]), 0, 255).astype(np.uint8)
    return img
