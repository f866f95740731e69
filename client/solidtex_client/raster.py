"""Triangle rasterisation with numpy: which triangle covers each pixel centre, and where.

Screen coordinates are pixels: pixel (i, j) (column i, row j) covers [i, i+1) x [j, j+1) and
its centre is (i + 0.5, j + 0.5). A triangle covers a pixel when the centre lies inside it or
on its edges (a 1e-9 barycentric tolerance). The answer for a covered pixel is the triangle's
index and the barycentric weights (w0, w1, w2) of the centre, so anything linear over the
triangle (mesh positions, colours, UVs) can be interpolated exactly at the centre; in an
orthographic view screen-space weights are also the weights on the 3D triangle.

Triangles are processed in batches of similar screen size (``_FRAGMENT_BUDGET`` candidate
pixels per batch), so ~100K triangles take well under a second at 512x512.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterator, Optional

import numpy as np

_FRAGMENT_BUDGET = 1 << 21  # candidate pixels per batch
_INSIDE_TOL = 1e-9          # barycentric slack, so centres on shared edges are not lost


@dataclass
class Fragments:
    """Covered pixel centres of one batch: ``tri`` triangle indices, ``pix`` flat pixel
    indices (``row * width + column``), ``bary`` (n, 3) float64 weights summing to 1."""

    tri: np.ndarray
    pix: np.ndarray
    bary: np.ndarray


def _as_xy(x: np.ndarray, y: np.ndarray) -> tuple:
    x = np.asarray(x, np.float64)
    y = np.asarray(y, np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or y.shape != x.shape:
        raise ValueError(f"x and y must both be (M, 3) corner coordinates, got {x.shape} and "
                         f"{y.shape}")
    return x, y


def fragments(x: np.ndarray, y: np.ndarray, width: int, height: int,
              triangles: Optional[np.ndarray] = None) -> Iterator[Fragments]:
    """The pixel centres covered by each triangle, in batches.

    ``x``, ``y``: (M, 3) screen coordinates of the triangles' corners (pixels, see the module
    doc). ``triangles``: which of the M to rasterise (default all). Degenerate triangles (zero
    screen area) cover nothing. Every (triangle, covered pixel) pair is yielded exactly once.
    """
    x, y = _as_xy(x, y)
    w, h = int(width), int(height)
    ids = np.arange(len(x)) if triangles is None else np.asarray(triangles, np.int64)
    if len(ids) == 0:
        return
    xs, ys = x[ids], y[ids]
    x0 = np.maximum(np.ceil(xs.min(1) - 0.5), 0)
    x1 = np.minimum(np.floor(xs.max(1) - 0.5), w - 1)
    y0 = np.maximum(np.ceil(ys.min(1) - 0.5), 0)
    y1 = np.minimum(np.floor(ys.max(1) - 0.5), h - 1)
    area = ((xs[:, 1] - xs[:, 0]) * (ys[:, 2] - ys[:, 0])
            - (xs[:, 2] - xs[:, 0]) * (ys[:, 1] - ys[:, 0]))
    # Triangles far off screen have huge boxes clipped to nothing; NaN corners fail every test.
    todo = (x1 >= x0) & (y1 >= y0) & (np.abs(area) > 1e-12)
    sel = np.flatnonzero(todo)
    if len(sel) == 0:
        return
    ids, x0, x1, y0, y1, area = (ids[sel], x0[sel].astype(np.int64), x1[sel].astype(np.int64),
                                 y0[sel].astype(np.int64), y1[sel].astype(np.int64), area[sel])
    span = np.maximum(x1 - x0, y1 - y0) + 1
    bucket = np.ceil(np.log2(span)).astype(np.int64)
    for b in np.unique(bucket):
        s = 1 << int(b)
        members = np.flatnonzero(bucket == b)
        oy, ox = np.divmod(np.arange(s * s), s)
        step = max(1, _FRAGMENT_BUDGET // (s * s))
        for start in range(0, len(members), step):
            m = members[start:start + step]
            qx = x0[m, None] + ox[None, :]
            qy = y0[m, None] + oy[None, :]
            ti, oi = np.nonzero((qx <= x1[m, None]) & (qy <= y1[m, None]))
            mm = m[ti]
            t = ids[mm]
            cx, cy = qx[ti, oi] + 0.5, qy[ti, oi] + 0.5
            xa, xb, xc = x[t, 0], x[t, 1], x[t, 2]
            ya, yb, yc = y[t, 0], y[t, 1], y[t, 2]
            inv = 1.0 / area[mm]
            w0 = ((xb - cx) * (yc - cy) - (xc - cx) * (yb - cy)) * inv
            w1 = ((xc - cx) * (ya - cy) - (xa - cx) * (yc - cy)) * inv
            w2 = 1.0 - w0 - w1
            inside = (w0 >= -_INSIDE_TOL) & (w1 >= -_INSIDE_TOL) & (w2 >= -_INSIDE_TOL)
            if not inside.any():
                continue
            pix = qy[ti, oi][inside] * w + qx[ti, oi][inside]
            yield Fragments(t[inside], pix, np.stack([w0[inside], w1[inside], w2[inside]], 1))


def rasterize(x: np.ndarray, y: np.ndarray, depth: np.ndarray, width: int, height: int,
              splat: bool = True) -> tuple:
    """Z-buffered coverage: for every pixel the nearest triangle (largest ``depth``) whose
    surface covers its centre.

    ``depth``: (M, 3) per-corner depth, larger is nearer (interpolated linearly, exact for an
    orthographic view). With ``splat``, a triangle that contains no pixel centre is drawn
    at its centroid's pixel with weights (1/3, 1/3, 1/3), so dense meshes at small image sizes
    show no holes. Returns ``(face, bary)``: ``face`` int64 (H, W), -1 where nothing is drawn;
    ``bary`` float64 (H, W, 3), the weights of the pixel's point on that face (zeros where
    nothing is drawn).
    """
    x, y = _as_xy(x, y)
    depth = np.asarray(depth, np.float64)
    if depth.shape != x.shape:
        raise ValueError(f"depth must be (M, 3) like x, got {depth.shape}")
    w, h = int(width), int(height)
    if w < 1 or h < 1:
        raise ValueError(f"image size must be positive, got {(w, h)}")
    zbuf = np.full(h * w, -np.inf)
    face = np.full(h * w, -1, np.int64)
    bary = np.zeros((h * w, 3))
    finite = np.isfinite(x).all(1) & np.isfinite(y).all(1) & np.isfinite(depth).all(1)

    def resolve(tri: np.ndarray, pix: np.ndarray, wts: np.ndarray) -> None:
        dep = (wts * depth[tri]).sum(1)
        order = np.lexsort((dep, pix))        # per pixel, nearest last
        ps = pix[order]
        last = np.ones(len(ps), bool)
        last[:-1] = ps[1:] != ps[:-1]
        sel = order[last]
        tri, pix, dep, wts = tri[sel], pix[sel], dep[sel], wts[sel]
        win = dep > zbuf[pix]
        zbuf[pix[win]] = dep[win]
        face[pix[win]] = tri[win]
        bary[pix[win]] = wts[win]

    if splat:
        x0 = np.ceil(x.min(1) - 0.5)
        x1 = np.floor(x.max(1) - 0.5)
        y0 = np.ceil(y.min(1) - 0.5)
        y1 = np.floor(y.max(1) - 0.5)
        area = ((x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0])
                - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0]))
        empty = np.flatnonzero(((x1 < x0) | (y1 < y0)) & finite & (np.abs(area) > 0))
        if len(empty):
            ix = np.floor(x[empty].mean(1)).astype(np.int64)
            iy = np.floor(y[empty].mean(1)).astype(np.int64)
            ok = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
            n = int(ok.sum())
            if n:
                resolve(empty[ok], (iy * w + ix)[ok], np.full((n, 3), 1.0 / 3.0))
    for frag in fragments(x, y, w, h, np.flatnonzero(finite)):
        resolve(frag.tri, frag.pix, frag.bary)
    return face.reshape(h, w), bary.reshape(h, w, 3)


def coverage(x: np.ndarray, y: np.ndarray, width: int, height: int) -> tuple:
    """Coverage without depth, for layouts whose triangles do not overlap (a UV atlas).

    Returns ``(face, bary)`` as :func:`rasterize` does, without splatting. Where triangles do
    share a centre (on a common edge), the one with the larger index wins: both give the same
    point of their shared edge.
    """
    x, y = _as_xy(x, y)
    w, h = int(width), int(height)
    if w < 1 or h < 1:
        raise ValueError(f"image size must be positive, got {(w, h)}")
    face = np.full(h * w, -1, np.int64)
    bary = np.zeros((h * w, 3))
    for frag in fragments(x, y, w, h):
        order = np.lexsort((frag.tri, frag.pix))      # per pixel, largest index last
        ps = frag.pix[order]
        last = np.ones(len(ps), bool)
        last[:-1] = ps[1:] != ps[:-1]
        sel = order[last]
        win = frag.tri[sel] > face[frag.pix[sel]]     # against earlier batches too
        face[frag.pix[sel][win]] = frag.tri[sel][win]
        bary[frag.pix[sel][win]] = frag.bary[sel][win]
    return face.reshape(h, w), bary.reshape(h, w, 3)
