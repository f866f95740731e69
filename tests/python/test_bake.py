"""Textured glTF export (`solidtex-client bake`) against a server.

The .glb is read back with trimesh, an independent reader; the test rasterises its UVs itself
and checks every texel whose centre lies inside a triangle against a `points` request at the
texel's surface point (placed in double precision, JSON body). Texel density is a parameter:
measured from the file, it follows `texels_per_voxel`, and `atlas_size` sets the texture's
side. A procedural torus keeps the file fast and free of shared data.
"""
import io
import json

import numpy as np
import pytest
import requests
import trimesh

from mesh_shapes import obj_bytes, torus
from support import client_cli, server_with_volume
from solidtex_client.placement import lround, placement_from
from solidtex_client.srgb import encode_srgb8

SEED = 9
RES = 48          # placement resolution: the torus is 48 / 1.5 = 32 voxels across


@pytest.fixture(scope="module")
def env(binary, exemplars, tmp_path_factory):
    with server_with_volume(tmp_path_factory.mktemp("bake"), exemplars["wood"], seed=SEED,
                            name="wood") as ns:
        ns.verts, ns.faces = torus(40, 20)
        ns.mesh = ns.client.upload_mesh(obj_bytes(ns.verts, ns.faces), name="torus.obj")
        yield ns


def fresh_volume(env) -> str:
    return env.client.create_volume(exemplar=env.exemplar_id, seed=SEED)["id"]


def load_glb(data: bytes):
    """(positions, faces, uv in glTF's convention, texture (H, W, 3) uint8, node extras)."""
    scene = trimesh.load(io.BytesIO(data), file_type="glb", process=False)
    (geom,) = scene.geometry.values()
    uv = np.array(geom.visual.uv, np.float64)
    uv[:, 1] = 1 - uv[:, 1]           # trimesh gives OpenGL's v, up from the bottom row
    tex = np.asarray(geom.visual.material.baseColorTexture.convert("RGB"))
    n = struct_json(data)
    return (np.asarray(geom.vertices, np.float64), np.asarray(geom.faces, np.int64), uv, tex,
            n["nodes"][0].get("extras", {}))


def struct_json(data: bytes) -> dict:
    length = int.from_bytes(data[12:16], "little")
    return json.loads(data[20:20 + length])


def texels_inside(uv_px, faces, width, height):
    """Texel centres strictly inside one triangle's UV image (1e-6 of slack kept from the
    edges): (row, column, face, barycentric weights). Written independently of the client's
    rasteriser: one triangle at a time."""
    rows, cols, fids, weights = [], [], [], []
    for f, (a, b, c) in enumerate(uv_px[faces]):
        lo = np.maximum(np.floor(np.minimum(np.minimum(a, b), c) - 0.5), 0).astype(int)
        hi = np.minimum(np.ceil(np.maximum(np.maximum(a, b), c)), [width - 1, height - 1]).astype(int)
        if (hi < lo).any():
            continue
        i, j = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1))
        p = np.stack([i.ravel() + 0.5, j.ravel() + 0.5], 1)
        m = np.array([b - a, c - a]).T
        if abs(np.linalg.det(m)) < 1e-12:
            continue
        w12 = np.linalg.solve(m, (p - a).T).T
        w = np.column_stack([1 - w12.sum(1), w12])
        ok = (w > 1e-6).all(1)
        rows.append(j.ravel()[ok])
        cols.append(i.ravel()[ok])
        fids.append(np.full(ok.sum(), f))
        weights.append(w[ok])
    return (np.concatenate(rows), np.concatenate(cols), np.concatenate(fids),
            np.concatenate(weights))


def dilate_reference(linear, filled, rings):
    """bake.py's dilation rule written out texel by texel, in float64: in each of ``rings``
    rings, every texel not yet filled with a filled 8-neighbour takes the mean linear colour of
    its filled 8-neighbours (those filled before that ring). Returns (linear, filled)."""
    linear = np.asarray(linear, np.float64).copy()
    filled = filled.copy()
    h, w = filled.shape
    for _ in range(rings):
        ring = {}
        for j, i in zip(*np.nonzero(~filled)):
            near = [linear[j + dy, i + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)
                    if (dy or dx) and 0 <= j + dy < h and 0 <= i + dx < w and filled[j + dy, i + dx]]
            if near:
                ring[j, i] = np.mean(near, axis=0)
        if not ring:
            break
        for (j, i), colour in ring.items():
            linear[j, i] = colour
            filled[j, i] = True
    return linear, filled


def density_of(positions, faces, uv, side, scale):
    """Texels per voxel: sqrt(texel area of the UV images / voxel area of the triangles)."""
    t = uv[faces] * side
    e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    uv_area = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum() / 2
    p = positions[faces] * scale
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum() / 2
    return float(np.sqrt(uv_area / area))


def test_baked_texels_are_points_answers(env):
    c = env.client
    vol = fresh_volume(env)
    out = c.bake(vol, mesh_id=env.mesh["id"], placement={"resolution": RES}, atlas_size=128)
    print(f"bake: {out.stats}")
    positions, faces, uv, tex, extras = load_glb(out.glb())
    assert tex.shape == (128, 128, 3)
    # the file's mesh is the torus, split along seams
    assert len(faces) == len(env.faces)
    assert np.allclose(np.sort(np.unique(positions.round(5), axis=0), axis=0),
                       np.sort(np.unique(env.verts.round(5), axis=0), axis=0), atol=2e-5)
    # the recorded placement is the service's
    place = placement_from({"resolution": RES}, env.mesh["bounds"])
    served = c.surface(env.volume_id, mesh_id=env.mesh["id"], placement={"resolution": RES},
                       fmt="json")["placement"]
    assert extras["solidtex"]["placement"] == served == place.to_json()

    rows, cols, fids, w = texels_inside(uv * 128, faces, 128, 128)
    assert len(rows) > 0.15 * 128 ** 2
    surface = (w[:, :, None] * positions[faces[fids]]).sum(1)
    world = place.apply(surface)
    clear = (np.abs(world - np.floor(world) - 0.5) >= 1e-6).all(1)
    assert clear.mean() > 0.99
    r = requests.post(f"{env.url}/v1/volumes/{vol}/points",
                      json={"points": world[clear].tolist()},
                      headers={"Accept": "application/octet-stream"}, timeout=120)
    assert r.status_code == 200, r.text[:300]
    assert int(r.headers["X-Voxels-Synthesized"]) == 0, "the bake did not synthesize them all"
    want = np.frombuffer(r.content, "<f4").reshape(-1, 3)
    got = tex[rows[clear], cols[clear]]
    bad = np.flatnonzero((got != encode_srgb8(want)).any(1))
    assert len(bad) == 0, (f"{len(bad)} of {len(got)} texels differ, e.g. texel "
                           f"{rows[clear][bad[0]]},{cols[clear][bad[0]]}: {got[bad[0]]} vs "
                           f"{encode_srgb8(want[bad[0]])}")
    assert len(np.unique(got, axis=0)) >= 50
    # the client baked exactly those texels and voxels: its texels are the ones whose centres
    # lie in a triangle's UV image, and its distinct voxels (each asked for once) are theirs
    inside = np.zeros((128, 128), bool)
    inside[rows, cols] = True
    assert np.array_equal(out.face >= 0, inside)
    voxels = np.unique(lround(world), axis=0)
    assert np.array_equal(np.unique(lround(out.placement.apply(out.surface[inside])), axis=0), voxels)
    assert out.stats["distinct_voxels"] == len(voxels)
    assert out.stats["voxels_synthesized"] > 0

    # Dilation (default 8 rings) against the same bake without it: there every texel outside the
    # charts is the mean colour of the baked texels; dilated, the rings around the charts follow
    # bake.py's rule instead (each ring's texels take the mean linear colour of their filled
    # 8-neighbours), written out here texel by texel, and only texels past them keep the mean.
    flat = c.bake(vol, mesh_id=env.mesh["id"], placement={"resolution": RES}, atlas_size=128,
                  dilate_texels=0)
    assert np.array_equal(flat.face >= 0, inside)
    assert np.array_equal(flat.texture[inside], tex[inside])
    mean = flat.linear[inside].mean(0)      # what bake.py fills with: the baked texels' mean
    assert np.array_equal(flat.linear[~inside], np.broadcast_to(mean, flat.linear[~inside].shape))
    want, reached = dilate_reference(flat.linear, inside, 8)
    ring = reached & ~inside
    assert ring.sum() > 0.1 * (~inside).sum(), ring.sum()
    assert np.allclose(out.linear[ring], want[ring], rtol=0, atol=1e-5)
    assert np.array_equal(out.linear[~reached], np.broadcast_to(mean, out.linear[~reached].shape))
    assert np.array_equal(tex, encode_srgb8(out.linear))
    # the rings are not the mean fill: a bake whose dilation did nothing fails the checks above
    assert (np.abs(want[ring] - mean) > 1e-3).any(1).mean() > 0.9
    assert (tex[ring] != flat.texture[ring]).any(1).mean() > 0.9


def test_texel_density_is_a_parameter(env):
    c = env.client
    scale = placement_from({"resolution": RES}, env.mesh["bounds"]).scale
    sides, baked = {}, {}
    for tpv in (0.75, 1.5):
        out = c.bake(env.volume_id, mesh_id=env.mesh["id"], placement={"resolution": RES},
                     texels_per_voxel=tpv)
        positions, faces, uv, tex, extras = load_glb(out.glb())
        measured = density_of(positions, faces, uv, tex.shape[0], scale)
        sides[tpv], baked[tpv] = tex.shape[0], out.stats["texels_baked"]
        print(f"texels_per_voxel {tpv}: atlas {tex.shape[:2]}, measured {measured:.3f}, "
              f"{out.stats}")
        assert tex.shape[0] == tex.shape[1] == out.stats["atlas_size"]
        assert extras["solidtex"]["texels_per_voxel"] == tpv
        assert abs(measured / tpv - 1) < 0.1, (tpv, measured)
    # twice the density: four times the texels; the side grows less (the padding is fixed)
    assert 3.2 < baked[1.5] / baked[0.75] < 4.8, baked
    assert 1.3 < sides[1.5] / sides[0.75] < 2.2, sides
    out = c.bake(env.volume_id, mesh_id=env.mesh["id"], placement={"resolution": RES},
                 atlas_size=96)
    positions, faces, uv, tex, _ = load_glb(out.glb())
    measured = density_of(positions, faces, uv, 96, scale)
    print(f"atlas_size 96: measured {measured:.3f}, {out.stats}")
    assert tex.shape == (96, 96, 3)
    assert abs(measured / out.stats["texels_per_voxel"] - 1) < 0.1
    for bad, word in (({"atlas_size": 4}, "atlas_size"), ({"texels_per_voxel": -1}, "texels_per_voxel")):
        with pytest.raises(ValueError, match=word):
            c.bake(env.volume_id, mesh_id=env.mesh["id"], **bad)


def test_bake_command(env, tmp_path):
    c = env.client
    path = tmp_path / "torus.obj"
    path.write_bytes(obj_bytes(env.verts, env.faces))
    glb, png = tmp_path / "torus.glb", tmp_path / "torus.png"
    before = sorted(m["id"] for m in c.list_meshes())
    proc = client_cli(env.url, "bake", path, "--volume", env.volume_id, "-o", glb,
                      "--atlas-size", 64, "--resolution", RES, "--texture", png)
    summary = json.loads(proc.stdout)
    print(summary)
    assert summary["atlas_size"] == 64 and summary["bytes"] == glb.stat().st_size
    assert sorted(m["id"] for m in c.list_meshes()) == before, "the uploaded mesh was kept"
    _, faces, _, tex, _ = load_glb(glb.read_bytes())
    from PIL import Image
    assert np.array_equal(np.asarray(Image.open(png).convert("RGB")), tex)
    assert tex.shape == (64, 64, 3) and len(faces) == len(env.faces)
    bad = client_cli(env.url, "bake", path, "--volume", env.volume_id, "-o", glb,
                     "--texels-per-voxel", "0", check=False)
    assert bad.returncode == 1 and "texels_per_voxel" in bad.stderr, bad.stderr
