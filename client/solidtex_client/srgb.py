"""sRGB8 encoding of the service's linear colours, bit for bit as the service quantises them.

The service answers linear float32 RGB (``points``, ``float32`` cuts) or sRGB8 (PNG, ``uint8``
cuts, PLY vertex colours); its sRGB8 value of a linear value ``v`` is, in float32 arithmetic
(``synth/core/image.cpp`` ``linear_to_srgb`` and ``image_io.cpp`` ``to_srgb8``)::

    c = clamp(v, 0, 1)
    s = 0 if c <= 0;  1 if c >= 1;  12.92 c if c <= 0.0031308;  else 1.055 powf(c, 1/2.4) - 0.055
    code = lround(s * 255)

:func:`encode_srgb8` gives exactly that code for every float32, so a client that encodes a
``points`` answer gets the bytes the service would have sent as sRGB8. It does so with a table
of the 255 smallest float32 values at which the code steps up, found once by bisection over
float32 bit patterns with the C library's ``powf`` (the one the service calls; numpy's float32
power where libm cannot be loaded), evaluating the formula above in float32 step by step.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import functools
import math
from typing import Any, Callable, Optional

import numpy as np

_F32 = np.float32
_table: Optional[np.ndarray] = None


def _libm_powf() -> Optional[Callable[[float, float], float]]:
    name = ctypes.util.find_library("m")
    if not name:
        return None
    try:
        lib = ctypes.CDLL(name)
        powf = lib.powf
    except (OSError, AttributeError):
        return None
    powf.restype = ctypes.c_float
    powf.argtypes = [ctypes.c_float, ctypes.c_float]
    return powf


@functools.lru_cache(maxsize=1)
def _encoder() -> Callable[[np.float32], int]:
    """The service's code of one float32 value (the module doc's formula)."""
    powf = _libm_powf()
    if powf is not None:
        def pow32(a: np.float32, b: np.float32) -> np.float32:
            return _F32(powf(float(a), float(b)))   # ctypes passes and returns exact float32
    else:  # pragma: no cover - every supported platform has a loadable libm
        def pow32(a: np.float32, b: np.float32) -> np.float32:
            return np.power(a, b, dtype=_F32)
    exponent = _F32(1) / _F32(2.4)
    knee, slope, a, b, scale = _F32(0.0031308), _F32(12.92), _F32(1.055), _F32(0.055), _F32(255)

    def code(v: np.float32) -> int:
        c = min(max(v, _F32(0)), _F32(1))
        if c <= 0:
            s = _F32(0)
        elif c >= 1:
            s = _F32(1)
        elif c <= knee:
            s = _F32(c * slope)
        else:
            s = _F32(_F32(a * pow32(c, exponent)) - b)
        t = float(_F32(s * scale))
        return int(math.floor(t + 0.5)) if t >= 0 else -int(math.floor(-t + 0.5))  # lround
    return code


def srgb8_code(v: float) -> int:
    """The service's sRGB8 code of one linear value (rounded to float32 first), computed
    directly from the formula; :func:`encode_srgb8` uses a table built from this."""
    return _encoder()(_F32(v))


def thresholds() -> np.ndarray:
    """float32 (255,): entry k-1 is the smallest float32 whose code is at least k."""
    global _table
    if _table is None:
        code = _encoder()
        one = int(np.array(1.0, _F32).view(np.uint32))
        out = np.empty(255, _F32)
        lo = 0
        for k in range(1, 256):
            # smallest bit pattern in [lo, one] (non-negative floats order as their bits)
            hi = one
            while lo < hi:
                mid = (lo + hi) // 2
                if code(np.array(mid, np.uint32).view(_F32)[()]) >= k:
                    hi = mid
                else:
                    lo = mid + 1
            out[k - 1] = np.array(lo, np.uint32).view(_F32)
        _table = out
    return _table


def encode_srgb8(linear: Any) -> np.ndarray:
    """uint8 sRGB codes of linear values (any shape; rounded to float32 first, as the
    service holds them), equal to the service's own sRGB8 encoding. NaN encodes as 0."""
    v = np.asarray(linear, dtype=_F32)
    codes = np.searchsorted(thresholds(), v, side="right")
    codes[np.isnan(v)] = 0
    return codes.astype(np.uint8)
