"""Bake a volume's colours into a UV-atlas texture and a textured glTF (.glb).

1. **Atlas**: xatlas (PyPI ``xatlas``) cuts the mesh into charts and packs them into one
   square texture of ``atlas_size`` texels per side (default 1024, at most 4096), at the
   highest texel density that fits; or at a given density, ``texels_per_voxel`` texels per
   finest voxel along the surface (world units are voxels, so the density is independent of
   the mesh's own units), the side then being what the packing needs. Charts are ``padding``
   texels apart.
2. **Texels**: every texel whose centre lies in a triangle's UV image gets that centre's
   *surface point* (the triangle's barycentric weights of the centre applied to its
   mesh-coordinate corners); all of them go to the service in one ``points`` batch, each
   distinct voxel once (:mod:`solidtex_client.surface_colors`; in compact pieces if the
   service refuses one request as too large). Such a texel is exactly the
   service's sRGB8 encoding (:func:`~solidtex_client.srgb.encode_srgb8`) of the ``points``
   answer at its surface point, so only voxels the texture shows are synthesized.
3. **Dilation**: ``dilate`` rings of texels around the charts take the mean linear colour of
   their already-filled 8-neighbours, so bilinear and mip-mapped sampling at chart borders does
   not pull in background; texels farther out take the mean colour of the baked texels.
4. **glTF**: :func:`~solidtex_client.gltf.write_glb` with mesh-coordinate positions, smooth
   normals and the texture as ``baseColorTexture`` (sRGB PNG).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Dict, Mapping, Optional, Tuple

import numpy as np

from .gltf import write_glb
from .mesh import MeshInput, TriangleMesh
from .pixel_render import surface_points
from .placement import Placement, placement_from
from .raster import coverage
from .srgb import encode_srgb8
from .surface_colors import mesh_on_server, surface_colors

if TYPE_CHECKING:  # pragma: no cover
    from .client import Client

DEFAULT_ATLAS_SIZE = 1024
# The largest texture side. The client's memory grows with the texel count: a bake peaked at
# ~175 bytes per texel with ~55 % of the atlas in charts (tracemalloc, 2048² atlas: 731 MB; the
# per-texel face, surface, linear and coverage arrays plus the baked texels' points and voxels),
# so 4096² takes ~3 GB and 8192² would take ~12 GB: too much for the machines this runs on.
MAX_ATLAS_SIZE = 4096
_MIN_ATLAS_SIZE = 16
_FIT_TRIES = 6           # packings tried to find the density that fills atlas_size
_FILL_GUESS = 0.6        # expected share of the atlas covered by charts, for the first guess


@dataclass
class Bake:
    """A baked mesh. ``positions`` float32 (V, 3) mesh coordinates, ``normals`` float32 (V, 3),
    ``uvs`` float32 (V, 2) (glTF convention, :mod:`solidtex_client.gltf`), ``indices`` int64
    (M, 3): the mesh split along chart seams (``source_vertex`` int64 (V,): the stored mesh's
    vertex each comes from). ``texture`` uint8 (S, S, 3) sRGB. ``face`` int64 (S, S): the
    triangle whose UV image holds each texel centre, -1 for texels outside every chart;
    ``surface`` float64 (S, S, 3) the texel's surface point in mesh coordinates (NaN outside);
    ``linear`` float32 (S, S, 3) the texel's linear colour (from the service inside charts,
    dilated or the mean outside). ``placement`` the mesh's placement in the volume. ``stats``:
    ``atlas_size``, ``texels_per_voxel``, ``charts``, ``utilization``, ``texels_baked``,
    ``distinct_voxels``, ``voxels_synthesized``, ``points_requests``, seconds per stage,
    ``packings``.
    """

    positions: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    indices: np.ndarray
    source_vertex: np.ndarray
    texture: np.ndarray
    face: np.ndarray
    surface: np.ndarray
    linear: np.ndarray
    placement: Placement
    stats: Dict[str, Any] = field(default_factory=dict)
    extras: Dict[str, Any] = field(default_factory=dict)

    def png(self) -> bytes:
        """The texture as PNG bytes (8-bit sRGB)."""
        from .client import encode_png
        return encode_png(self.texture)

    def glb(self) -> bytes:
        """The textured mesh as .glb bytes; the node's ``extras.solidtex`` records the volume,
        placement, density and atlas size."""
        return write_glb(self.positions, self.indices, self.uvs, self.png(),
                         normals=self.normals, extras={"solidtex": self.extras})


def _check_int(name: str, value: Any, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise ValueError(f"{name} must be an integer in [{lo}, {hi}], got {value!r}")
    return int(value)


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit area-weighted vertex normals, float64 (N, 3); (0, 0, 1) where they vanish."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])   # length: twice the area
    acc = np.zeros_like(v)
    for c in range(3):
        np.add.at(acc, f[:, c], n)
    length = np.linalg.norm(acc, axis=1)
    out = np.tile([0.0, 0.0, 1.0], (len(v), 1))
    ok = length > 0
    out[ok] = acc[ok] / length[ok, None]
    return out


def surface_area(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The mesh's area in squared mesh units."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    return float(np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]),
                                axis=1).sum() / 2)


def pack_atlas(vertices: np.ndarray, faces: np.ndarray, texels_per_unit: float,
               padding: int) -> Tuple[np.ndarray, np.ndarray, np.ndarray, int, int, Any]:
    """One xatlas packing into a single atlas at ``texels_per_unit`` texels per mesh unit.

    Returns ``(source_vertex, indices, uv_texels, width, height, atlas)``: ``uv_texels`` float64
    (V, 2) are texel coordinates in the width x height atlas (texel (i, j) covers [i, i+1) x
    [j, j+1))."""
    try:
        import xatlas
    except ImportError as e:  # pragma: no cover - depends on the installation
        raise ImportError("baking needs the xatlas package: pip install 'solidtex-client[bake]'"
                          " (or pip install xatlas)") from e
    atlas = xatlas.Atlas()
    atlas.add_mesh(np.ascontiguousarray(vertices, dtype=np.float32),
                   np.ascontiguousarray(faces, dtype=np.uint32))
    pack = xatlas.PackOptions()
    pack.resolution = 0                     # one atlas, sized by the density
    pack.texels_per_unit = float(texels_per_unit)
    pack.padding = int(padding)
    pack.bilinear = True                    # keep bilinear footprints of charts apart
    atlas.generate(xatlas.ChartOptions(), pack)
    if atlas.atlas_count != 1:
        raise RuntimeError(f"xatlas made {atlas.atlas_count} atlases; expected one")
    vmap, idx, uv = atlas[0]
    uv_texels = np.asarray(uv, dtype=np.float64) * np.array([atlas.width, atlas.height], float)
    return (np.asarray(vmap, np.int64), np.asarray(idx, np.int64).reshape(-1, 3), uv_texels,
            int(atlas.width), int(atlas.height), atlas)


def dilate(linear: np.ndarray, filled: np.ndarray, rings: int) -> np.ndarray:
    """Grow the filled region of ``linear`` (H, W, 3) by ``rings`` texels in place: each ring's
    texels take the mean of their filled 8-neighbours. Returns the new filled mask."""
    filled = filled.copy()
    h, w = filled.shape
    for _ in range(rings):
        f = np.pad(filled, 1).astype(np.float32)
        c = np.pad(linear * filled[:, :, None], ((1, 1), (1, 1), (0, 0)))
        count = np.zeros((h, w), np.float32)
        acc = np.zeros((h, w, 3), np.float32)
        for dy in (0, 1, 2):
            for dx in (0, 1, 2):
                if dy == 1 and dx == 1:
                    continue
                count += f[dy:dy + h, dx:dx + w]
                acc += c[dy:dy + h, dx:dx + w]
        ring = ~filled & (count > 0)
        if not ring.any():
            break
        linear[ring] = acc[ring] / count[ring][:, None]
        filled |= ring
    return filled


def bake(client: "Client", volume_id: str, mesh_id: Optional[str] = None,
         mesh: Optional[MeshInput] = None, placement: Optional[Mapping[str, Any]] = None, atlas_size: Optional[int] = None,
         texels_per_voxel: Optional[float] = None, padding: int = 4, dilate_texels: int = 8,
         timeout: Optional[float] = None) -> Bake:
    """Bake volume ``volume_id``'s colours on ``mesh`` into a texture atlas (module doc).

    Give a stored mesh's ``mesh_id`` or a ``mesh`` file (path or bytes; uploaded for the call
    and deleted after). ``placement`` as for :meth:`~solidtex_client.client.Client.surface`
    (default: resolution 512, margin 0.25). Texel density: ``atlas_size`` (texels per side of
    the square texture, an integer in [16, 4096]; default 1024) or ``texels_per_voxel`` (texels
    per finest voxel along the surface, > 0; the texture's side is then what the packing needs,
    at most 4096), not both; memory grows with the texels, ~3 GB at 4096² (``MAX_ATLAS_SIZE``). ``padding``: texels between charts, [0, 64]; ``dilate_texels``:
    rings of texels filled past chart borders, [0, 256]. ``timeout``: the ``points`` request's
    server-side deadline, seconds.
    """
    if atlas_size is not None and texels_per_voxel is not None:
        raise ValueError("give atlas_size or texels_per_voxel, not both")
    if texels_per_voxel is None:
        atlas_size = _check_int("atlas_size", DEFAULT_ATLAS_SIZE if atlas_size is None
                                else atlas_size, _MIN_ATLAS_SIZE, MAX_ATLAS_SIZE)
    else:
        if isinstance(texels_per_voxel, bool) or not isinstance(texels_per_voxel, (int, float, np.number)) \
                or not math.isfinite(float(texels_per_voxel)) or not float(texels_per_voxel) > 0:
            raise ValueError(f"texels_per_voxel must be a positive finite number, got "
                             f"{texels_per_voxel!r}")
        texels_per_voxel = float(texels_per_voxel)
    padding = _check_int("padding", padding, 0, 64)
    dilate_texels = _check_int("dilate_texels", dilate_texels, 0, 256)

    with mesh_on_server(client, mesh_id, mesh) as (info, tri):
        place = placement_from(placement, info["bounds"])
        t0 = time.monotonic()
        area_vox = surface_area(tri.vertices, tri.faces) * place.scale ** 2
        if not area_vox > 0:
            raise ValueError("the mesh has no area to bake")
        side, density, packings, packed = _fit_atlas(tri, place, area_vox, atlas_size,
                                                     texels_per_voxel, padding)
        vmap, idx, uv_texels, width, height, atlas = packed
        # The packing's texel grid scaled by side / max(width, height) >= 1 onto the square.
        # Texels are baked from the float32 UVs the file will hold, so a reader that
        # interpolates the file's UVs finds the same surface points.
        stretch = side / max(width, height)
        uvs = (uv_texels * (stretch / side)).astype(np.float32)
        uv_px = uvs.astype(np.float64) * side
        t1 = time.monotonic()
        xs, ys = uv_px[:, 0][idx], uv_px[:, 1][idx]
        face, bary = coverage(xs, ys, side, side)
        positions = tri.vertices[vmap]
        surface = surface_points(positions, idx, face, bary)
        inside = face >= 0
        t2 = time.monotonic()
        colors = surface_colors(client, volume_id, surface[inside], place, timeout=timeout)
        t3 = time.monotonic()
    linear = np.zeros((side, side, 3), np.float32)
    linear[inside] = colors.linear
    filled = dilate(linear, inside, dilate_texels)
    if inside.any():
        linear[~filled] = colors.linear.mean(0)
    texture = encode_srgb8(linear)
    t4 = time.monotonic()
    normals = vertex_normals(tri.vertices, tri.faces)[vmap]
    stats = {
        "atlas_size": side, "texels_per_voxel": density * stretch,
        "charts": int(atlas.chart_count), "utilization": float(atlas.utilization),
        "packings": packings, "texels_baked": int(inside.sum()),
        "distinct_voxels": colors.distinct_voxels,
        "voxels_synthesized": colors.voxels_synthesized, "points_requests": colors.requests,
        "vertices": int(len(positions)), "triangles": int(len(idx)),
        "atlas_seconds": round(t1 - t0, 3), "texel_seconds": round(t2 - t1, 3),
        "points_seconds": round(t3 - t2, 3), "texture_seconds": round(t4 - t3, 3),
    }
    extras = {"volume": volume_id, "mesh": info["id"], "placement": place.to_json(),
              "atlas_size": side, "texels_per_voxel": stats["texels_per_voxel"]}
    return Bake(positions.astype(np.float32), normals.astype(np.float32), uvs, idx, vmap,
                texture, face, surface, linear, place, stats, extras)


def _fit_atlas(tri: TriangleMesh, place: Placement, area_vox: float,
               atlas_size: Optional[int], texels_per_voxel: Optional[float],
               padding: int) -> Tuple[int, float, int, tuple]:
    """``(side, texels_per_voxel, packings, packing)``: the square texture's side and the
    density of the packing (before stretching it to the side)."""
    if texels_per_voxel is not None:
        # Refuse before xatlas allocates a huge atlas: charts cover at most the whole square.
        least = math.sqrt(area_vox) * texels_per_voxel
        if least > MAX_ATLAS_SIZE:
            raise ValueError(f"texels_per_voxel {texels_per_voxel:g} needs an atlas of at least "
                             f"{least:.0f} texels per side (the mesh's surface is "
                             f"{area_vox:.0f} square voxels); the limit is {MAX_ATLAS_SIZE}")
        packed = pack_atlas(tri.vertices, tri.faces, texels_per_voxel * place.scale, padding)
        side = max(packed[3], packed[4])
        if side > MAX_ATLAS_SIZE:
            raise ValueError(f"texels_per_voxel {texels_per_voxel:g} gives an atlas of {side} "
                             f"texels per side; the limit is {MAX_ATLAS_SIZE}")
        return side, texels_per_voxel, 1, packed
    assert atlas_size is not None
    density = atlas_size * math.sqrt(_FILL_GUESS / area_vox)
    fits: Optional[tuple] = None        # (density, packing, side) of the best that fits
    too_big: Optional[float] = None     # the smallest density found too big
    for tries in range(1, _FIT_TRIES + 1):
        packed = pack_atlas(tri.vertices, tri.faces, density * place.scale, padding)
        got = max(packed[3], packed[4])
        if got <= atlas_size:
            if fits is None or got > fits[2]:
                fits = (density, packed, got)
            # Within 3% below the side is as good as it gets: the packing's side is not
            # continuous in the density.
            if got >= atlas_size * 0.97:
                break
        else:
            too_big = density if too_big is None else min(too_big, density)
        if fits is not None and too_big is not None:
            density = math.sqrt(fits[0] * too_big)       # bisect (geometrically)
        else:
            # the side grows about linearly with the density (plus the padding)
            density *= atlas_size / got * (0.98 if got > atlas_size else 1.0)
    if fits is None:
        raise ValueError(f"atlas_size {atlas_size}: no packing of the mesh fit in "
                         f"{_FIT_TRIES} tries (padding {padding} too large for it?)")
    return atlas_size, fits[0], tries, fits[1]
