"""Where a mesh sits in a volume: ``world = scale * mesh + translate``, and its nearest voxels.

World units are finest voxels; voxel (i, j, k) is at world point (i, j, k). The service places
a stored mesh by ``{"resolution": R, "margin": M}`` (fit its bounding box, enlarged by M times
its longest side on every side, to R voxels along the longest side, the enlarged box's minimum
corner at the origin) or by an explicit ``{"scale": s, "translate": [x, y, z]}``.
:func:`fit_placement` repeats the service's arithmetic (``synth/mesh/mesh.cpp``
``fit_placement``: IEEE doubles, no fused multiply-add) so a client computes the same placement
bit for bit from the mesh's ``bounds`` without asking for a ``surface`` answer (which would
synthesize every vertex's voxel); :func:`nearest_voxels` rounds world points as the service's
``points`` targets do (C ``lround``: halves away from zero).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence, Tuple

import numpy as np

DEFAULT_RESOLUTION = 512
DEFAULT_MARGIN = 0.25
# Voxel coordinates are sent to `points` as float32; integers are exact below 2^24.
_MAX_EXACT = 1 << 24


@dataclass(frozen=True)
class Placement:
    """``world = scale * mesh + translate`` (world units are finest voxels)."""

    scale: float
    translate: Tuple[float, float, float]

    def apply(self, points: Any) -> np.ndarray:
        """World positions (float64, shape of ``points``) of mesh-coordinate ``points`` (..., 3):
        ``scale * p + translate`` per axis, a product then a sum, as the service computes it."""
        p = np.asarray(points, dtype=np.float64)
        return self.scale * p + np.asarray(self.translate, dtype=np.float64)

    def to_json(self) -> dict:
        """The ``{"scale", "translate"}`` form of the ``placement`` request key."""
        return {"scale": float(self.scale), "translate": [float(t) for t in self.translate]}


def _bounds(bounds: Mapping[str, Sequence[float]]) -> Tuple[np.ndarray, np.ndarray]:
    try:
        lo = np.asarray(bounds["min"], dtype=np.float64).reshape(3)
        hi = np.asarray(bounds["max"], dtype=np.float64).reshape(3)
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"bounds must be {{'min': [x, y, z], 'max': [x, y, z]}}, got {bounds!r}")
    return lo, hi


def fit_placement(bounds: Mapping[str, Sequence[float]], resolution: int = DEFAULT_RESOLUTION,
                  margin: float = DEFAULT_MARGIN) -> Placement:
    """The service's placement of a mesh with ``bounds`` (the Mesh object's ``bounds``) for
    ``{"resolution": resolution, "margin": margin}``: ``resolution`` voxels (an integer in
    [8, 4096]) along the longest side of the box enlarged by ``margin`` (in [0, 1]) of its
    longest side on every side."""
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) \
            or not 8 <= int(resolution) <= 4096:
        raise ValueError(f"placement resolution must be an integer in [8, 4096], got {resolution!r}")
    margin = float(margin)
    if not 0.0 <= margin <= 1.0:
        raise ValueError(f"placement margin must be in [0, 1], got {margin!r}")
    lo, hi = _bounds(bounds)
    longest = max(float(hi[0] - lo[0]), float(hi[1] - lo[1]), float(hi[2] - lo[2]))
    if not (longest > 0) or not math.isfinite(longest):
        raise ValueError("the mesh has no extent (all vertices coincide)")
    scale = int(resolution) / (longest * (1 + 2 * margin))
    translate = tuple(-scale * (float(lo[a]) - margin * longest) for a in range(3))
    if not math.isfinite(scale) or not all(math.isfinite(t) for t in translate):
        raise ValueError(f"the mesh's extent ({longest:.3g} along its longest side) is too "
                         "small to fit")
    return Placement(scale, translate)  # type: ignore[arg-type]


def placement_from(spec: Optional[Mapping[str, Any]],
                   bounds: Mapping[str, Sequence[float]]) -> Placement:
    """The :class:`Placement` a ``placement`` request value names for a mesh with ``bounds``:
    ``None`` or ``{"resolution"?, "margin"?}`` (defaults 512 and 0.25) fit the mesh;
    ``{"scale", "translate"}`` is taken as given (``scale`` > 0, finite numbers)."""
    spec = dict(spec or {})
    if "scale" in spec or "translate" in spec:
        unknown = set(spec) - {"scale", "translate"}
        if unknown or "scale" not in spec or "translate" not in spec:
            raise ValueError("placement takes either resolution/margin or both scale and "
                             f"translate, got keys {sorted(spec)}")
        scale = float(spec["scale"])
        translate = tuple(float(t) for t in spec["translate"])
        if not (scale > 0) or not math.isfinite(scale):
            raise ValueError(f"placement scale must be a positive finite number, got {scale!r}")
        if len(translate) != 3 or not all(math.isfinite(t) for t in translate):
            raise ValueError(f"placement translate must be 3 finite numbers, got {translate!r}")
        return Placement(scale, translate)  # type: ignore[arg-type]
    unknown = set(spec) - {"resolution", "margin"}
    if unknown:
        raise ValueError(f"unknown placement keys {sorted(unknown)}")
    return fit_placement(bounds, spec.get("resolution", DEFAULT_RESOLUTION),
                         spec.get("margin", DEFAULT_MARGIN))


def lround(x: Any) -> np.ndarray:
    """C's ``lround`` of float64 values (nearest integer, halves away from zero), exactly, as
    float64."""
    x = np.asarray(x, dtype=np.float64)
    a = np.abs(x)
    f = np.floor(a)
    # a - floor(a) is exact for a >= 0 (its fraction bits); x - floor(x) is not for x < 0
    # (-0.49999999999999994 + 1 rounds to 0.5).
    return np.copysign(f + (a - f >= 0.5), x)


def nearest_voxels(world: Any) -> np.ndarray:
    """int64 (..., 3) voxels nearest world points, as the service rounds ``points`` targets.

    Raises ``ValueError`` for non-finite points or coordinates of 2^24 voxels or more (they
    would not survive the float32 ``points`` body exactly)."""
    w = np.asarray(world, dtype=np.float64)
    if not np.all(np.isfinite(w)):
        raise ValueError("world points must be finite")
    v = lround(w)
    if v.size and np.abs(v).max() >= _MAX_EXACT:
        raise ValueError(f"world points reach {np.abs(v).max():.0f} voxels from the origin; "
                         f"the placement must keep them within 2^24")
    return v.astype(np.int64)
