"""HTTP client for the solidtex service: one method per operation of proto/openapi.json.

Units: world coordinates and sizes are finest-level voxels (a ``slice`` or ``cut`` with
``scale=s`` counts the voxels of pyramid dataset s); timeouts and deadlines are seconds.
Colors: ``uint8`` answers are sRGB-encoded 8-bit, ``float32`` answers are linear RGB.
Every error answer raises the :mod:`solidtex_client.errors` exception for its status.
"""
from __future__ import annotations

import io
import json as _json
import os
import struct
import time
import zlib
from urllib.parse import quote, urlencode
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import requests

from .errors import JobFailed, error_from_response
from .mesh import ColoredMesh, MeshInput, mesh_bytes, parse_colored_ply

ImageInput = Union[str, "os.PathLike[str]", bytes, bytearray, memoryview, np.ndarray, Any]

_CUT_ACCEPT = {
    "uint8": "application/octet-stream",
    "float32": "application/octet-stream; dtype=float32",
    "png": "image/png",
    "png_bytes": "image/png",
}
_REGION_ACCEPT = {
    "vdb": "application/x-vdb",
    "uint8": "application/octet-stream",
    "float32": "application/octet-stream; dtype=float32",
}
_SURFACE_ACCEPT = {"ply": "application/x-ply", "json": "application/json"}


# ----------------------------------------------------------------------------------------
# Image encoding


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def encode_png(array: np.ndarray) -> bytes:
    """PNG bytes for an HxW, HxWx1, HxWx3 or HxWx4 array.

    ``uint8`` gives an 8-bit PNG, ``uint16`` a 16-bit PNG (both lossless). Float arrays are
    taken as display-referred values in [0, 1] (the same encoding as the integer PNGs, i.e.
    sRGB-encoded, not linear): they are clipped and quantised to a 16-bit PNG. Other integer
    types must lie in [0, 65535] and become 16-bit.
    """
    a = np.asarray(array)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[:, :, 0]
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] not in (2, 3, 4)):
        raise ValueError(f"image array must be HxW or HxWx1/2/3/4, got shape {a.shape}")
    if a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError("image array is empty")
    if a.dtype == np.uint8:
        depth, data = 8, a
    elif a.dtype == np.uint16:
        depth, data = 16, a
    elif np.issubdtype(a.dtype, np.floating):
        if not np.all(np.isfinite(a)):
            raise ValueError("image array has NaN or infinite values")
        depth, data = 16, np.round(np.clip(a, 0.0, 1.0) * 65535.0).astype(np.uint16)
    elif np.issubdtype(a.dtype, np.integer) or a.dtype == np.bool_:
        if a.min() < 0 or a.max() > 65535:
            raise ValueError("integer image values must lie in [0, 65535]")
        depth, data = 16, a.astype(np.uint16)
    else:
        raise ValueError(f"unsupported image dtype {a.dtype}")
    h, w = data.shape[:2]
    channels = 1 if data.ndim == 2 else data.shape[2]
    color_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    raw = np.ascontiguousarray(data.astype(">u2") if depth == 16 else data)
    rows = raw.reshape(h, -1).view(np.uint8).reshape(h, -1)
    scan = np.concatenate([np.zeros((h, 1), np.uint8), rows], axis=1).tobytes()  # filter 0
    ihdr = struct.pack(">IIBBBBB", w, h, depth, color_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", ihdr)
            + _png_chunk(b"IDAT", zlib.compress(scan, 6)) + _png_chunk(b"IEND", b""))


def image_bytes(image: ImageInput) -> bytes:
    """Encoded image bytes for an upload.

    ``image`` may be a file path (sent as is: PNG, JPEG, TIFF or OpenEXR), encoded bytes
    (sent as is), a ``PIL.Image.Image`` (encoded as PNG) or a numpy array (see
    :func:`encode_png`).
    """
    if isinstance(image, (bytes, bytearray, memoryview)):
        return bytes(image)
    if isinstance(image, (str, os.PathLike)):
        with open(image, "rb") as f:
            return f.read()
    if isinstance(image, np.ndarray):
        return encode_png(image)
    try:
        from PIL import Image
    except ImportError:  # pragma: no cover - Pillow is a dependency
        Image = None  # type: ignore[assignment]
    if Image is not None and isinstance(image, Image.Image):
        img = image
        if img.mode not in ("1", "L", "LA", "I", "I;16", "P", "RGB", "RGBA"):
            img = img.convert("RGBA" if "A" in img.getbands() else "RGB")
        buf = io.BytesIO()
        img.save(buf, format="PNG")
        return buf.getvalue()
    raise TypeError(f"unsupported image type {type(image).__name__}: "
                    "give a path, bytes, a PIL image or a numpy array")


def _image_filename(part: str, data: bytes) -> Tuple[str, str]:
    if data.startswith(b"\x89PNG"):
        return part + ".png", "image/png"
    if data.startswith(b"\xff\xd8"):
        return part + ".jpg", "image/jpeg"
    if data[:4] in (b"II*\x00", b"MM\x00*"):
        return part + ".tif", "image/tiff"
    if data.startswith(b"\x76\x2f\x31\x01"):
        return part + ".exr", "image/x-exr"
    return part, "application/octet-stream"


# ----------------------------------------------------------------------------------------
# Query helpers


def _csv(values: Iterable[Any]) -> str:
    return ",".join(_num(v) for v in values)


def _num(v: Any) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        f = float(v)
        return str(int(f)) if f.is_integer() and abs(f) < 1e15 else repr(f)
    return str(v)


def _query_value(v: Any) -> str:
    if isinstance(v, (list, tuple, np.ndarray)):
        return _csv(v)
    return _num(v)


def _rows(values: Any, width: int, dtype: Any = np.float64) -> np.ndarray:
    """``values`` (nested sequences or an array) as an (N, ``width``) array of ``dtype``."""
    return np.asarray(values, dtype=np.float64).reshape(-1, width).astype(dtype, copy=False)


def _int_at_least(name: str, value: Any, minimum: int, kind: str) -> int:
    """``value`` checked as an integer (not a bool) >= ``minimum``; errors name ``name``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be a {kind} integer, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be a {kind} integer, got {int(value)}")
    return int(value)


def _scale(scale: Any) -> int:
    """``scale`` checked as a pyramid dataset index: a non-negative integer."""
    return _int_at_least("scale", scale, 0, "non-negative")


def _revision(revision: Any) -> int:
    """``revision`` checked as a field revision: a positive integer."""
    return _int_at_least("revision", revision, 1, "positive")


def _accept(formats: Mapping[str, str], fmt: str, what: str) -> str:
    """The Accept header for answer format ``fmt``; ``ValueError`` for a format not offered."""
    if fmt not in formats:
        raise ValueError(f"{what} must be one of {sorted(formats)}")
    return formats[fmt]


def _shape(response: requests.Response, fallback: Optional[Sequence[int]] = None) -> Tuple[int, ...]:
    header = response.headers.get("X-Shape")
    if header:
        return tuple(int(s) for s in header.split(","))
    if fallback is None:
        raise ValueError("raw answer without X-Shape header")
    return tuple(fallback)


def _binary_answer(response: requests.Response, fmt: str,
                   fallback: Optional[Sequence[int]] = None) -> Any:
    """A slice, cut, region or points answer decoded for ``fmt``: ``png_bytes`` and ``vdb``
    -> the bytes as sent; ``png`` -> a ``PIL.Image``; ``uint8`` (sRGB) and ``float32``
    (linear, little-endian on the wire) -> a numpy array shaped by the ``X-Shape`` header, or
    by ``fallback`` when the answer has none."""
    if fmt in ("png_bytes", "vdb"):
        return response.content
    if fmt == "png":
        from PIL import Image
        img = Image.open(io.BytesIO(response.content))
        img.load()
        return img
    shape = _shape(response, fallback)
    np_dtype = np.dtype("<f4") if fmt == "float32" else np.dtype(np.uint8)
    data = response.content
    expected = int(np.prod(shape)) * np_dtype.itemsize
    if len(data) != expected:
        raise ValueError(f"raw answer has {len(data)} bytes, X-Shape {shape} of {np_dtype} "
                         f"needs {expected}")
    arr = np.frombuffer(data, dtype=np_dtype).reshape(shape)
    return arr.astype(np.float32) if fmt == "float32" else arr.copy()


class Client:
    """A solidtex service at ``base_url``; ``timeout`` is the HTTP timeout in seconds.

    ``last_response`` holds the ``requests.Response`` of the latest call (headers such as
    ``X-Voxels-Synthesized`` live there). One client may be used from one thread at a time.
    """

    def __init__(self, base_url: str = "http://127.0.0.1:8080", timeout: float = 60,
                 session: Optional[requests.Session] = None) -> None:
        self.base_url = base_url.rstrip("/")
        self.timeout = timeout
        self.session = session if session is not None else requests.Session()
        self.last_response: Optional[requests.Response] = None

    def __repr__(self) -> str:
        return f"Client({self.base_url!r})"

    def close(self) -> None:
        self.session.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # -- transport ------------------------------------------------------------------------

    def request(self, method: str, path: str, *, params: Optional[Mapping[str, Any]] = None,
                headers: Optional[Mapping[str, str]] = None, json: Any = None,
                data: Any = None, files: Any = None,
                http_timeout: Optional[float] = None) -> requests.Response:
        """One HTTP request; raises the typed error for a status >= 400."""
        query = None
        if params:
            # Commas stay literal (they are legal in a query): size=32,24 rather than 32%2C24.
            query = urlencode({k: _query_value(v) for k, v in params.items() if v is not None},
                              quote_via=quote, safe=",") or None
        body = data
        hdrs = dict(headers or {})
        if json is not None:
            body = _json.dumps(json).encode()
            hdrs.setdefault("Content-Type", "application/json")
        response = self.session.request(method, self.base_url + path, params=query,
                                        headers=hdrs, data=body, files=files,
                                        timeout=http_timeout or self.timeout)
        self.last_response = response
        if response.status_code >= 400:
            raise error_from_response(response)
        return response

    def _timed(self, method: str, path: str, timeout: Optional[float], *,
               params: Optional[Mapping[str, Any]] = None, **kwargs: Any) -> requests.Response:
        """A request with the server-side deadline ``timeout`` (seconds; ``None``: the
        server's default) in its query. The HTTP timeout leaves the server time to answer
        504 itself before the socket gives up."""
        return self.request(method, path, params={**(params or {}), "timeout": timeout},
                            http_timeout=max(self.timeout, (timeout or 0) + 10), **kwargs)

    # -- service --------------------------------------------------------------------------

    def healthz(self) -> Dict[str, Any]:
        """GET /healthz: liveness JSON."""
        return self.request("GET", "/healthz").json()

    def metrics(self) -> str:
        """GET /metrics: Prometheus text."""
        return self.request("GET", "/metrics").text

    def openapi(self) -> Dict[str, Any]:
        """GET /v1/openapi.json: the API contract."""
        return self.request("GET", "/v1/openapi.json").json()

    # -- exemplars ------------------------------------------------------------------------

    def list_exemplars(self) -> List[Dict[str, Any]]:
        """GET /v1/exemplars: the exemplar objects."""
        return self.request("GET", "/v1/exemplars").json()["exemplars"]

    def upload_exemplar(self, image: ImageInput, yz: Optional[ImageInput] = None,
                        zx: Optional[ImageInput] = None, mask: Optional[ImageInput] = None,
                        mask_yz: Optional[ImageInput] = None, mask_zx: Optional[ImageInput] = None,
                        **analysis_params: Any) -> Dict[str, Any]:
        """POST /v1/exemplars: upload an exemplar; its analysis runs in the background.

        ``image`` (and ``yz``, ``zx``, ``mask``) is a path, encoded bytes, a PIL image or a
        numpy array (arrays are sent as PNG, see :func:`encode_png`). One image alone is
        sent as the raw body (``application/octet-stream``); with ``yz``/``zx``/``mask`` the
        body is multipart/form-data with parts ``xy``, ``yz``, ``zx``, ``mask``, ``mask_yz``,
        ``mask_zx`` (feature masks of the three planes).
        ``analysis_params`` go in the query: ``name``, ``levels`` (1-8, or ``"auto"``, the
        server's default, which follows the image size), ``neighborhood`` (odd
        template size in pixels), ``candidates``, ``pca_dims``, ``seed``, ``plane_weights``
        (a 3-sequence or ``"a,b,c"``), ``grain`` (``"auto"`` by default, ``"none"``, ``"x"``, ``"y"``), ``mask_weight``. Returns ``{"exemplar": ..., "job": ...}``.
        """
        params = {k: v for k, v in analysis_params.items() if v is not None}
        xy = image_bytes(image)
        extra = {"yz": yz, "zx": zx, "mask": mask, "mask_yz": mask_yz, "mask_zx": mask_zx}
        if all(v is None for v in extra.values()):
            r = self.request("POST", "/v1/exemplars", params=params, data=xy,
                             headers={"Content-Type": "application/octet-stream"})
            return r.json()
        files = []
        for part, value in (("xy", image), *extra.items()):
            if value is None:
                continue
            data = xy if part == "xy" else image_bytes(value)
            name, mime = _image_filename(part, data)
            files.append((part, (name, data, mime)))
        return self.request("POST", "/v1/exemplars", params=params, files=files).json()

    def get_exemplar(self, exemplar_id: str) -> Dict[str, Any]:
        """GET /v1/exemplars/{id}."""
        return self.request("GET", f"/v1/exemplars/{exemplar_id}").json()

    def delete_exemplar(self, exemplar_id: str) -> None:
        """DELETE /v1/exemplars/{id} (409 while a volume uses it)."""
        self.request("DELETE", f"/v1/exemplars/{exemplar_id}")

    def get_exemplar_table(self, exemplar_id: str) -> bytes:
        """GET /v1/exemplars/{id}/table: the .stx file bytes."""
        return self.request("GET", f"/v1/exemplars/{exemplar_id}/table").content

    # -- jobs -----------------------------------------------------------------------------

    def get_job(self, job_id: str) -> Dict[str, Any]:
        """GET /v1/jobs/{id}: state (queued, running, succeeded, failed) and percent."""
        return self.request("GET", f"/v1/jobs/{job_id}").json()

    def wait_for_job(self, job_id: str, timeout: float = 120, poll: float = 0.2) -> Dict[str, Any]:
        """Poll a job every ``poll`` seconds until it succeeds; returns the final job.

        Raises :class:`~solidtex_client.errors.JobFailed` if it fails and ``TimeoutError``
        if it has not finished after ``timeout`` seconds.
        """
        end = time.monotonic() + timeout
        while True:
            job = self.get_job(job_id)
            if job.get("state") == "succeeded":
                return job
            if job.get("state") == "failed":
                raise JobFailed(job)
            if time.monotonic() >= end:
                raise TimeoutError(f"job {job_id} still {job.get('state')} "
                                   f"({job.get('percent')}%) after {timeout} s")
            time.sleep(poll)

    # -- fields ---------------------------------------------------------------------------

    def list_fields(self) -> List[Dict[str, Any]]:
        """GET /v1/fields: the field objects."""
        return self.request("GET", "/v1/fields").json()["fields"]

    def create_field(self, sketch: Mapping[str, Any], timeout: Optional[float] = None) -> Dict[str, Any]:
        """POST /v1/fields: solve a frame field from a sketch (sketch.schema.json).

        ``timeout`` is the server-side deadline in seconds.
        """
        return self._timed("POST", "/v1/fields", timeout, json=dict(sketch)).json()

    def get_field(self, field_id: str) -> Dict[str, Any]:
        """GET /v1/fields/{id}."""
        return self.request("GET", f"/v1/fields/{field_id}").json()

    def delete_field(self, field_id: str) -> None:
        """DELETE /v1/fields/{id} (volumes keep their own copies)."""
        self.request("DELETE", f"/v1/fields/{field_id}")

    def get_field_file(self, field_id: str) -> bytes:
        """GET /v1/fields/{id}/file: the .stf bytes of the current revision."""
        return self.request("GET", f"/v1/fields/{field_id}/file").content

    def add_curve(self, field_id: str, curve: Mapping[str, Any],
                  timeout: Optional[float] = None, *,
                  revision: Optional[int] = None) -> Dict[str, Any]:
        """POST /v1/fields/{id}/curves: add one sketch curve and re-solve (revision + 1).

        ``revision``: the revision the curve is meant for (sent only when given); when the
        field is at another one the server changes nothing and
        :class:`~solidtex_client.errors.Conflict` (409, ``field == "revision"``) is raised.
        """
        params = {} if revision is None else {"revision": _revision(revision)}
        return self._timed("POST", f"/v1/fields/{field_id}/curves", timeout, params=params,
                           json=dict(curve)).json()

    def undo_curve(self, field_id: str, timeout: Optional[float] = None, *,
                   revision: Optional[int] = None) -> Dict[str, Any]:
        """DELETE /v1/fields/{id}/curves/last: remove the sketch's last curve (revision + 1).

        The new revision is bit for bit the newest earlier one with the same curves, else
        solved afresh; volumes keep the revision they copied. Returns the Field. A sketch
        the removal would leave empty raises
        :class:`~solidtex_client.errors.Conflict` (409). ``timeout`` is the server-side
        deadline in seconds. ``revision`` (sent only when given): the revision whose last
        curve is meant, e.g. the one :meth:`add_curve` returned; when the field is at another
        one (someone else's curve is last, or a retry already undid it) nothing is removed
        and :class:`~solidtex_client.errors.Conflict` is raised with ``field == "revision"``.
        """
        params = {} if revision is None else {"revision": _revision(revision)}
        return self._timed("DELETE", f"/v1/fields/{field_id}/curves/last", timeout,
                           params=params).json()

    def sample_frames(self, field_id: str, min: Sequence[float], size: Sequence[int],
                      step: float = 1.0) -> Dict[str, Any]:
        """GET /v1/fields/{id}/frames: frames on a grid of ``size`` = (NX, NY, NZ) points
        starting at world point ``min`` and ``step`` world units apart.

        Returns the answer with ``points`` (N, 3), ``quaternions`` (N, 4; w, x, y, z) and
        ``scales`` (N, 3) as float64 numpy arrays.
        """
        out = self.request("GET", f"/v1/fields/{field_id}/frames",
                           params={"min": list(min), "size": list(size), "step": step}).json()
        for key, width in (("points", 3), ("quaternions", 4), ("scales", 3)):
            if key in out:
                out[key] = _rows(out[key], width)
        return out

    def field_from_mesh(self, mesh_id: str, kind: str, *,
                        placement: Optional[Mapping[str, Any]] = None,
                        shortest_side_cells: Optional[int] = None,
                        max_constraints: Optional[int] = None,
                        feature_angle_degrees: Optional[float] = None,
                        curves: Optional[Sequence[Sequence[Sequence[float]]]] = None,
                        timeout: Optional[float] = None) -> Dict[str, Any]:
        """POST /v1/fields/from-mesh: solve a frame field from a stored mesh's geometry.

        ``kind``: ``"curvature"`` (principal-curvature frames at vertices, at most
        ``max_constraints`` of them) or ``"features"`` (crest lines sharper than
        ``feature_angle_degrees`` plus the user ``curves``, polylines in mesh coordinates).
        ``placement`` as for :meth:`surface`; the field's domain is the placed mesh's box in
        world units, so a volume using the field should texture the mesh with the same
        placement. ``timeout`` is the server-side deadline in seconds. Returns the Field.
        """
        body: Dict[str, Any] = {"mesh": mesh_id, "kind": kind}
        if placement is not None:
            body["placement"] = dict(placement)
        for key, value in (("shortest_side_cells", shortest_side_cells),
                           ("max_constraints", max_constraints),
                           ("feature_angle_degrees", feature_angle_degrees)):
            if value is not None:
                body[key] = value
        if curves is not None:
            body["curves"] = [_rows(c, 3).tolist() for c in curves]
        return self._timed("POST", "/v1/fields/from-mesh", timeout, json=body).json()

    # -- meshes ---------------------------------------------------------------------------

    def list_meshes(self) -> List[Dict[str, Any]]:
        """GET /v1/meshes: the mesh objects."""
        return self.request("GET", "/v1/meshes").json()["meshes"]

    def upload_mesh(self, mesh: MeshInput, name: Optional[str] = None) -> Dict[str, Any]:
        """POST /v1/meshes: store a mesh (OBJ, PLY ASCII/binary or OFF; the server detects
        the format from the bytes). ``mesh`` is a path or the file's bytes; ``name`` defaults
        to the file name for a path. Returns the Mesh (counts, bounds, defects)."""
        if name is None and isinstance(mesh, (str, os.PathLike)):
            name = os.path.basename(os.fspath(mesh))
        r = self.request("POST", "/v1/meshes", params={"name": name}, data=mesh_bytes(mesh),
                         headers={"Content-Type": "application/octet-stream"})
        return r.json()

    def get_mesh(self, mesh_id: str) -> Dict[str, Any]:
        """GET /v1/meshes/{id}."""
        return self.request("GET", f"/v1/meshes/{mesh_id}").json()

    def delete_mesh(self, mesh_id: str) -> None:
        """DELETE /v1/meshes/{id}."""
        self.request("DELETE", f"/v1/meshes/{mesh_id}")

    def get_mesh_file(self, mesh_id: str) -> bytes:
        """GET /v1/meshes/{id}/file: binary PLY of the cleaned triangles (mesh coordinates)."""
        return self.request("GET", f"/v1/meshes/{mesh_id}/file").content

    def surface(self, volume_id: str, mesh_id: Optional[str] = None,
                mesh: Optional[MeshInput] = None,
                placement: Optional[Mapping[str, Any]] = None, fmt: str = "ply",
                points: Any = None, timeout: Optional[float] = None) -> Any:
        """POST /v1/volumes/{id}/surface: color a mesh's vertices from the volume.

        Name a stored mesh (``mesh_id``) or send one (``mesh``: a path or bytes). Each
        vertex gets the color of the finest voxel nearest its placed position
        ``world = scale * mesh + translate``. ``placement``: ``{"resolution": R, "margin":
        M}`` (fit the bounding box, enlarged by M of its longest side on every side, to R
        voxels along the longest side, min corner at the origin; default 512 and 0.25) or
        ``{"scale": s, "translate": [x, y, z]}`` (stored meshes only: a sent mesh takes
        resolution and margin in the query).

        ``fmt="ply"`` -> :class:`~solidtex_client.mesh.ColoredMesh` (sRGB8 colors; its
        ``headers`` hold X-Target-Voxels, X-Bounding-Voxels, X-Voxels-Synthesized).
        ``fmt="json"`` -> the answer dict with ``colors`` (and ``point_colors``, the colors of
        the extra mesh-coordinate ``points``, stored meshes only) as linear float32 (N, 3)
        arrays, ``placement`` and ``stats``. ``timeout`` is the server-side deadline, seconds.
        """
        accept = _accept(_SURFACE_ACCEPT, fmt, "fmt")
        if (mesh_id is None) == (mesh is None):
            raise ValueError("give exactly one of mesh_id and mesh")
        path = f"/v1/volumes/{volume_id}/surface"
        if mesh_id is not None:
            body: Dict[str, Any] = {"mesh": mesh_id, "format": fmt}
            if placement is not None:
                body["placement"] = dict(placement)
            if points is not None:
                body["points"] = _rows(points, 3).tolist()
            r = self._timed("POST", path, timeout, json=body, headers={"Accept": accept})
        else:
            if points is not None:
                raise ValueError("points need a stored mesh (mesh_id)")
            pl = dict(placement or {})
            unknown = set(pl) - {"resolution", "margin"}
            if unknown:
                raise ValueError(f"a sent mesh takes only resolution and margin as placement, "
                                 f"not {sorted(unknown)}; upload it to use scale/translate")
            params = {"resolution": pl.get("resolution"), "margin": pl.get("margin"),
                      "format": fmt}
            r = self._timed("POST", path, timeout, params=params, data=mesh_bytes(mesh),
                            headers={"Content-Type": "application/octet-stream",
                                     "Accept": accept})
        if fmt == "ply":
            out = parse_colored_ply(r.content)
            out.headers = {k: v for k, v in r.headers.items() if k.lower().startswith("x-")}
            return out
        answer = r.json()
        for key in ("colors", "point_colors"):
            if key in answer:
                answer[key] = _rows(answer[key], 3, np.float32)
        return answer

    def render_pixels(self, volume_id: str, mesh_id: Optional[str] = None,
                      mesh: Optional[MeshInput] = None, **options: Any) -> Any:
        """Render a mesh with one colour per pixel from the volume (one ``points`` batch for
        the surface points under the pixels, in pieces if the service refuses it as too large;
        only their voxels are synthesized). Give a stored
        mesh's ``mesh_id`` or a ``mesh`` file (uploaded for the call, then deleted).
        ``options``: ``placement``, ``azimuth``, ``elevation``, ``size``, ``light``, ``up``,
        ``border``, ``timeout``. Returns a
        :class:`~solidtex_client.pixel_render.PixelRender` (see
        :func:`~solidtex_client.pixel_render.render_pixels`)."""
        from .pixel_render import render_pixels
        return render_pixels(self, volume_id, mesh_id=mesh_id, mesh=mesh, **options)

    def bake(self, volume_id: str, mesh_id: Optional[str] = None,
             mesh: Optional[MeshInput] = None, **options: Any) -> Any:
        """Bake the volume's colours on a mesh into a UV-atlas texture (needs ``xatlas``).
        Give a stored mesh's ``mesh_id`` or a ``mesh`` file (uploaded for the call, then
        deleted). ``options``: ``placement``, ``atlas_size`` or ``texels_per_voxel``,
        ``padding``, ``dilate_texels``, ``timeout``. Returns a
        :class:`~solidtex_client.bake.Bake`; ``.glb()`` gives the textured glTF bytes (see
        :func:`~solidtex_client.bake.bake`)."""
        from .bake import bake
        return bake(self, volume_id, mesh_id=mesh_id, mesh=mesh, **options)

    # -- volumes --------------------------------------------------------------------------

    def list_volumes(self) -> List[Dict[str, Any]]:
        """GET /v1/volumes: the volume objects."""
        return self.request("GET", "/v1/volumes").json()["volumes"]

    def create_volume(self, spec: Optional[Mapping[str, Any]] = None, *,
                      exemplar: Optional[str] = None,
                      field: Union[None, str, Mapping[str, Any]] = None,
                      params: Optional[Mapping[str, Any]] = None, seed: Optional[int] = None,
                      regions: Union[None, Mapping[str, Any], Tuple[Sequence[str], str]] = None,
                      name: Optional[str] = None) -> Dict[str, Any]:
        """POST /v1/volumes with a volume.schema.json body.

        Give the whole ``spec`` dict, or build it from keywords: ``exemplar`` (id),
        ``regions`` (a dict, or ``((id0, id1), label)``), ``field`` (a dict ``{"id": ...}``
        / ``{"spec": ...}``, or a string: ``identity``, ``quat:...`` and ``axis:...``
        strings are specs, anything else is a stored field id), ``params`` (synthesis
        parameters), ``seed``, ``name``. Keywords override keys of ``spec``.
        """
        body: Dict[str, Any] = dict(spec or {})
        if exemplar is not None:
            body["exemplar"] = exemplar
        if regions is not None:
            if isinstance(regions, Mapping):
                body["regions"] = dict(regions)
            else:
                ids, label = regions
                body["regions"] = {"exemplars": list(ids), "label": label}
        if field is not None:
            if isinstance(field, str):
                is_spec = field.split(";")[0] == "identity" or field.startswith(("quat:", "axis:"))
                body["field"] = {"spec": field} if is_spec else {"id": field}
            else:
                body["field"] = dict(field)
        if params is not None:
            body["params"] = dict(params)
        if seed is not None:
            body["seed"] = int(seed)
        if name is not None:
            body["name"] = name
        return self.request("POST", "/v1/volumes", json=body).json()

    def get_volume(self, volume_id: str) -> Dict[str, Any]:
        """GET /v1/volumes/{id}."""
        return self.request("GET", f"/v1/volumes/{volume_id}").json()

    def delete_volume(self, volume_id: str) -> None:
        """DELETE /v1/volumes/{id}."""
        self.request("DELETE", f"/v1/volumes/{volume_id}")

    def volume_stats(self, volume_id: str) -> Dict[str, Any]:
        """GET /v1/volumes/{id}/stats: voxels per level, cache bytes and hits, recent requests."""
        return self.request("GET", f"/v1/volumes/{volume_id}/stats").json()

    def slice(self, volume_id: str, axis: str, at: int, size: Sequence[int],
              origin: Sequence[int] = (0, 0), dtype: str = "uint8",
              timeout: Optional[float] = None, scale: int = 0) -> Any:
        """GET /v1/volumes/{id}/slice: an axis-aligned cut of ``size`` = (W, H) pixels.

        Pixel (i, j) is voxel (U+i, V+j, at) for axis z, (at, U+i, V+j) for x,
        (U+i, at, V+j) for y, with ``origin`` = (U, V). ``dtype``: ``"uint8"`` -> sRGB
        uint8 array (H, W, 3); ``"float32"`` -> linear float32 array (H, W, 3); ``"png"`` ->
        ``PIL.Image``; ``"png_bytes"`` -> the PNG bytes as sent. ``timeout`` is the
        server-side deadline in seconds (504 past it).

        ``scale``: dataset s of the volume's pyramid, as in the zarr views: 0 (default) the
        finest voxels; s > 0 a coarser synthesis level whose voxels are 2^s finest voxels
        wide, and ``at``, ``origin`` and ``size`` count that level's voxels (a fast preview:
        nothing finer is synthesized). A non-negative integer (else ``TypeError`` or
        ``ValueError``); past the volume's coarsest dataset the server answers 404
        (:class:`~solidtex_client.errors.NotFound`).
        """
        accept = _accept(_CUT_ACCEPT, dtype, "dtype")
        params = {"axis": axis, "at": int(at), "origin": list(origin), "size": list(size)}
        scale = _scale(scale)
        if scale:
            params["scale"] = scale
        r = self._timed("GET", f"/v1/volumes/{volume_id}/slice", timeout, params=params,
                        headers={"Accept": accept})
        return _binary_answer(r, dtype)

    def cut(self, volume_id: str, origin: Sequence[float], u: Sequence[float],
            v: Sequence[float], size: Sequence[int], dtype: str = "uint8",
            timeout: Optional[float] = None, scale: int = 0, resample: Optional[str] = None) -> Any:
        """POST /v1/volumes/{id}/cut: a planar cut; pixel (i, j) samples the voxels at
        ``origin + i*u + j*v`` (in voxels of dataset ``scale``: finest voxels for the
        default 0), ``size`` = (W, H). ``resample``: ``"nearest"`` (the voxel nearest that
        position), ``"cubic"`` (the Catmull-Rom resampling of the voxels around it: no jaggies
        on tilted planes, softer detail), or ``None``/``"auto"`` (the server picks per volume:
        cubic when its exemplars carry little 1-pixel detail; the answer's ``X-Resample``
        header says which).

        ``dtype``, ``timeout`` and ``scale`` as for :meth:`slice`.
        """
        accept = _accept(_CUT_ACCEPT, dtype, "dtype")
        scale = _scale(scale)
        body = {"origin": [float(x) for x in origin], "u": [float(x) for x in u],
                "v": [float(x) for x in v], "size": [int(x) for x in size]}
        if resample is not None:
            body["resample"] = resample
        r = self._timed("POST", f"/v1/volumes/{volume_id}/cut", timeout, json=body,
                        params={"scale": scale or None}, headers={"Accept": accept})
        return _binary_answer(r, dtype)

    def region(self, volume_id: str, min: Sequence[int], size: Sequence[int],
               fmt: str = "vdb", timeout: Optional[float] = None) -> Any:
        """GET /v1/volumes/{id}/region: the box of ``size`` = (W, H, D) voxels at ``min`` =
        (X, Y, Z).

        ``fmt``: ``"vdb"`` -> bytes of an OpenVDB file (Vec3s grid 'color', linear RGB);
        ``"uint8"`` -> sRGB uint8 array (D, H, W, 3); ``"float32"`` -> linear float32 array
        (D, H, W, 3). Index ``[z, y, x]`` is voxel ``min + (x, y, z)``.
        """
        accept = _accept(_REGION_ACCEPT, fmt, "fmt")
        r = self._timed("GET", f"/v1/volumes/{volume_id}/region", timeout,
                        params={"min": list(min), "size": list(size)}, headers={"Accept": accept})
        w, h, d = (int(s) for s in size)
        return _binary_answer(r, fmt, fallback=(d, h, w, 3))

    def points(self, volume_id: str, xyz: Any, timeout: Optional[float] = None,
               resample: Optional[str] = None) -> np.ndarray:
        """POST /v1/volumes/{id}/points: linear RGB float32 (N, 3) at world points ``xyz``
        (N, 3), each rounded to its nearest finest voxel (voxel (i, j, k) is at (i, j, k)).
        ``resample``: ``None`` or ``"nearest"`` (that), ``"cubic"`` (the Catmull-Rom
        resampling of the voxels around each point, as cuts resample; dense points share their
        voxels, scattered ones read up to 64 each) or ``"auto"`` (what the volume's cuts use);
        the answer's ``X-Resample`` header says which.
        """
        pts = _rows(xyz, 3)
        r = self._timed("POST", f"/v1/volumes/{volume_id}/points", timeout,
                        params={"resample": resample},
                        data=pts.astype("<f4").tobytes(),
                        headers={"Content-Type": "application/octet-stream",
                                 "Accept": "application/octet-stream"})
        return _binary_answer(r, "float32", fallback=(len(pts), 3))
