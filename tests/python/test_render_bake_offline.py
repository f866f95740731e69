"""Per-pixel rendering and baking without a server: the sRGB8 encoder, placements, the
rasteriser, dilation, the .glb writer and the whole client pipeline against a fake service."""
import io
import json
import struct
from urllib.parse import urlsplit

import numpy as np
import pytest
import requests
import trimesh
from PIL import Image

from mesh_shapes import obj_bytes, torus
from support import fake_response  # (support also puts <repo>/client on sys.path)
from solidtex_client import BadRequest, Client, Unprocessable
from solidtex_client import bake as bake_module
from solidtex_client.cli import main as cli_main
from solidtex_client.gltf import write_glb
from solidtex_client.placement import fit_placement, lround, nearest_voxels, placement_from
from solidtex_client.raster import coverage, rasterize
from solidtex_client.render import MAX_IMAGE_SIDE
from solidtex_client.srgb import encode_srgb8, srgb8_code, thresholds

# -- sRGB8 --------------------------------------------------------------------------------


def test_srgb8_table_equals_the_formula():
    th = thresholds()
    assert th.dtype == np.float32 and th.shape == (255,)
    assert np.all(np.diff(th.astype(np.float64)) > 0)
    # on both sides of every step, and at random values, the table gives the formula's code
    below = np.nextafter(th, np.float32(-1))
    probe = np.concatenate([th, below, np.random.default_rng(2).random(3000).astype(np.float32),
                            np.float32([0, 1e-30, 0.0031308, 0.5, 1 - 2 ** -24, 1])])
    want = np.array([srgb8_code(v) for v in probe])
    assert np.array_equal(encode_srgb8(probe), want)
    assert np.array_equal(encode_srgb8(th), np.arange(1, 256))
    assert np.array_equal(encode_srgb8(below), np.arange(0, 255))
    assert encode_srgb8(np.float32([-3, 0, 1, 7, np.inf, -np.inf, np.nan])).tolist() == \
        [0, 0, 255, 255, 255, 0, 0]
    # the float64 textbook formula disagrees now and then: the encoder is not that one
    v = np.random.default_rng(3).random(200000).astype(np.float32)
    c = v.astype(np.float64)
    textbook = np.rint(255 * np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055))
    assert np.abs(encode_srgb8(v) - textbook).max() <= 1


# -- placement ----------------------------------------------------------------------------


def test_fit_placement_follows_the_contract():
    bounds = {"min": [-2.0, -1.0, 1.0], "max": [2.0, 0.5, 1.5]}
    p = fit_placement(bounds, 60, 0.25)
    assert p.scale == 10.0                       # longest side 4 + 2 * 1 -> 60 voxels
    assert np.allclose(p.apply([-2, -1, 1]), [10, 10, 10])   # min corner one margin in
    lo = p.apply(np.array(bounds["min"]) - 1.0)
    assert np.allclose(lo, 0, atol=1e-12)
    assert placement_from(None, bounds) == fit_placement(bounds, 512, 0.25)
    assert placement_from({"resolution": 60}, bounds) == fit_placement(bounds, 60)
    explicit = placement_from({"scale": 2, "translate": [1, 2, 3]}, bounds)
    assert explicit.scale == 2 and explicit.translate == (1, 2, 3)
    assert explicit.to_json() == {"scale": 2.0, "translate": [1.0, 2.0, 3.0]}


@pytest.mark.parametrize("spec,word", [
    ({"resolution": 4}, "resolution"), ({"resolution": 4097}, "resolution"),
    ({"resolution": 64.5}, "resolution"), ({"margin": 1.5}, "margin"),
    ({"scale": 0, "translate": [0, 0, 0]}, "scale"), ({"scale": 1}, "translate"),
    ({"scale": 1, "translate": [0, 0]}, "translate"), ({"colour": 1}, "colour"),
])
def test_placement_errors_name_the_parameter(spec, word):
    with pytest.raises(ValueError, match=word):
        placement_from(spec, {"min": [0, 0, 0], "max": [1, 1, 1]})
    with pytest.raises(ValueError, match="extent"):
        fit_placement({"min": [1, 1, 1], "max": [1, 1, 1]})


def test_rounding_is_lround():
    x = np.array([-2.5, -1.5, -0.5, 0.5, 1.5, 2.5, 0.49999999999999994, -0.49999999999999994,
                  2.4999999, 1e6 + 0.5])
    assert lround(x).tolist() == [-3, -2, -1, 1, 2, 3, 0, 0, 2, 1e6 + 1]
    assert nearest_voxels([[0.5, -0.5, 3.2]]).tolist() == [[1, -1, 3]]
    with pytest.raises(ValueError, match="2\\^24"):
        nearest_voxels([[2.0 ** 24, 0, 0]])
    with pytest.raises(ValueError, match="finite"):
        nearest_voxels([[np.nan, 0, 0]])


# -- rasteriser ---------------------------------------------------------------------------


def test_coverage_of_a_square_counts_every_pixel_once():
    # two triangles sharing the diagonal, covering [0, 8] x [0, 8] exactly
    x = np.array([[0, 8, 8], [0, 8, 0]], float)
    y = np.array([[0, 0, 8], [0, 8, 8]], float)
    face, bary = coverage(x, y, 10, 10)
    assert (face[:8, :8] >= 0).all() and (face[8:, :] == -1).all() and (face[:, 8:] == -1).all()
    # barycentrics reproduce the pixel centres
    jj, ii = np.nonzero(face >= 0)
    f = face[jj, ii]
    b = bary[jj, ii]
    assert np.allclose(b.sum(1), 1) and (b >= -1e-9).all()
    assert np.allclose((b * x[f]).sum(1), ii + 0.5) and np.allclose((b * y[f]).sum(1), jj + 0.5)
    # a centre on the shared diagonal goes to the larger index
    assert face[3, 3] == 1 and face[3, 4] == 0 and face[4, 3] == 1


def test_rasterize_keeps_the_nearest_and_splats_tiny_triangles():
    x = np.array([[0, 10, 0], [0, 10, 0], [5.1, 5.2, 5.1]], float)
    y = np.array([[0, 0, 10], [0, 0, 10], [7.1, 7.1, 7.2]], float)
    z = np.array([[0, 0, 0], [1, 1, 1], [5, 5, 5]], float)
    face, bary = rasterize(x, y, z, 12, 12)
    assert (face[face >= 0] != 0).all(), "the farther triangle showed through"
    assert face[2, 2] == 1
    assert face[7, 5] == 2 and np.allclose(bary[7, 5], 1 / 3)      # centroid's pixel
    face2, _ = rasterize(x, y, z, 12, 12, splat=False)
    assert face2[7, 5] == -1


# -- dilation and glb ---------------------------------------------------------------------


def test_dilate_fills_rings_with_neighbour_means():
    lin = np.zeros((7, 7, 3), np.float32)
    filled = np.zeros((7, 7), bool)
    lin[3, 3] = [0.8, 0.4, 0.2]
    lin[3, 4] = [0.2, 0.4, 0.8]
    filled[3, 3] = filled[3, 4] = True
    out = bake_module.dilate(lin, filled, 1)
    ring = out & ~filled
    assert ring.sum() == 3 * 4 - 2                     # the 3x4 box around the pair
    assert np.allclose(lin[2, 3], [0.5, 0.4, 0.5]) and np.allclose(lin[2, 2], [0.8, 0.4, 0.2])
    assert not out[0].any()
    assert bake_module.dilate(lin.copy(), filled, 3).all()


def test_write_glb_reads_back_with_trimesh():
    verts, faces = torus(12, 6)
    uv = np.random.default_rng(1).random((len(verts), 2))
    tex = np.random.default_rng(2).integers(0, 256, (16, 32, 3), dtype=np.uint8)
    buf = io.BytesIO()
    Image.fromarray(tex).save(buf, format="PNG")
    glb = write_glb(verts, faces, uv, buf.getvalue(), normals=bake_module.vertex_normals(verts, faces),
                    extras={"solidtex": {"volume": "vol_x"}})
    magic, version, length = struct.unpack("<III", glb[:12])
    assert (magic, version, length) == (0x46546C67, 2, len(glb)) and len(glb) % 4 == 0
    doc = json.loads(glb[20:20 + struct.unpack("<I", glb[12:16])[0]])
    assert doc["nodes"][0]["extras"] == {"solidtex": {"volume": "vol_x"}}
    scene = trimesh.load(io.BytesIO(glb), file_type="glb", process=False)
    (geom,) = scene.geometry.values()
    assert np.allclose(geom.vertices, verts, atol=1e-6) and np.array_equal(geom.faces, faces)
    # trimesh turns glTF's v (down from the top row) into OpenGL's v (up from the bottom)
    assert np.allclose(1 - geom.visual.uv[:, 1], uv[:, 1], atol=1e-6)
    assert np.array_equal(np.asarray(geom.visual.material.baseColorTexture.convert("RGB")), tex)
    with pytest.raises(ValueError, match="PNG"):
        write_glb(verts, faces, uv, b"not a png")
    with pytest.raises(ValueError, match="range"):
        write_glb(verts, faces + len(verts), uv, buf.getvalue())


def test_atlas_density_follows_texels_per_unit():
    verts, faces = torus(24, 12)
    for tpu in (40.0, 80.0):
        vmap, idx, uvt, w, h, atlas = bake_module.pack_atlas(verts, faces, tpu, 2)
        assert np.array_equal(verts[vmap][idx].round(12), verts[faces].round(12)), \
            "xatlas changed the triangles"
        a2 = uvt[idx]
        e1, e2 = a2[:, 1] - a2[:, 0], a2[:, 2] - a2[:, 0]
        uv_area = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum() / 2
        density = np.sqrt(uv_area / bake_module.surface_area(verts, faces))
        print(f"texels_per_unit {tpu}: atlas {w}x{h}, {atlas.chart_count} charts, "
              f"measured {density:.2f}")
        assert abs(density / tpu - 1) < 0.1
        assert 0 <= uvt.min() and uvt[:, 0].max() <= w and uvt[:, 1].max() <= h


# -- the client pipeline against a fake service --------------------------------------------


def ply_file(verts, faces) -> bytes:
    """The service's stored-mesh file layout: binary PLY, float xyz, int triangles."""
    head = (f"ply\nformat binary_little_endian 1.0\ncomment solidtex\nelement vertex {len(verts)}\n"
            "property float x\nproperty float y\nproperty float z\n"
            f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    f = np.zeros(len(faces), np.dtype([("n", "u1"), ("i", "<i4", (3,))]))
    f["n"], f["i"] = 3, faces
    return head.encode() + np.asarray(verts, "<f4").tobytes() + f.tobytes()


def voxel_color(v: np.ndarray) -> np.ndarray:
    """A colour that differs between neighbouring voxels (linear float32)."""
    v = np.asarray(v, np.float64)
    return (np.abs(np.sin(v @ np.array([[1.3, 0.7, 2.1], [0.4, 1.9, 0.8], [2.2, 0.3, 1.1]])))
            .astype(np.float32))


class FakeService(requests.Session):
    """Just enough of the service for render_pixels and bake: meshes and points."""

    def __init__(self, verts, faces):
        super().__init__()
        v32 = np.asarray(verts, np.float32).astype(np.float64)
        self.mesh = {"id": "mesh_1", "bounds": {"min": v32.min(0).tolist(), "max": v32.max(0).tolist()}}
        self.file = ply_file(verts, faces)
        self.log, self.points_bodies = [], []

    def send(self, request, **kwargs):
        path = urlsplit(request.url).path
        self.log.append((request.method, path))
        if request.method == "POST" and path == "/v1/meshes":
            r = fake_response(201, self.mesh)
        elif request.method == "GET" and path == "/v1/meshes/mesh_1":
            r = fake_response(200, self.mesh)
        elif path == "/v1/meshes/mesh_1/file":
            r = fake_response(200, self.file)
        elif request.method == "DELETE":
            r = fake_response(204)
        elif path.endswith("/points"):
            pts = np.frombuffer(request.body, "<f4").reshape(-1, 3)
            self.points_bodies.append(pts)
            r = fake_response(200, voxel_color(pts).astype("<f4").tobytes(),
                              {"X-Shape": f"{len(pts)},3", "X-Voxels-Synthesized": str(7 * len(pts))})
        else:
            raise AssertionError(f"unexpected {request.method} {path}")
        r.request = request
        return r


def test_render_pixels_pipeline_offline():
    verts, faces = torus(30, 14)
    fake = FakeService(verts, faces)
    c = Client("http://fake", session=fake)
    out = c.render_pixels("vol_1", mesh=obj_bytes(verts, faces), placement={"resolution": 48},
                          size=(64, 48), light=False)
    assert [m for m, _ in fake.log] == ["POST", "GET", "POST", "DELETE"], fake.log
    (sent,) = fake.points_bodies
    assert np.array_equal(sent, np.round(sent)) and len(np.unique(sent, axis=0)) == len(sent)
    hit = out.face >= 0
    assert out.image.shape == (48, 64, 3) and 0.2 < hit.mean() < 0.9
    assert (out.image[~hit] == 255).all()
    world = out.placement.apply(out.surface[hit])
    want = encode_srgb8(voxel_color(nearest_voxels(world)))
    assert np.array_equal(out.image[hit], want)
    assert out.stats["distinct_voxels"] == len(sent)
    assert out.stats["voxels_synthesized"] == 7 * len(sent)
    assert out.stats["object_pixels"] == hit.sum() >= len(sent)
    # a stored mesh is fetched, not uploaded nor deleted; lit pixels are never brighter
    fake.log.clear()
    lit = c.render_pixels("vol_1", mesh_id="mesh_1", placement={"resolution": 48}, size=(64, 48))
    assert [m for m, _ in fake.log] == ["GET", "GET", "POST"], fake.log
    assert np.array_equal(lit.face, out.face)
    assert (lit.image[hit] <= out.image[hit]).all() and (lit.image[hit] < out.image[hit]).any()


def test_bake_pipeline_offline():
    verts, faces = torus(30, 14)
    fake = FakeService(verts, faces)
    c = Client("http://fake", session=fake)
    out = c.bake("vol_1", mesh_id="mesh_1", placement={"resolution": 48}, atlas_size=128)
    assert out.texture.shape == (128, 128, 3)
    inside = out.face >= 0
    world = out.placement.apply(out.surface[inside])
    assert np.array_equal(out.texture[inside], encode_srgb8(voxel_color(nearest_voxels(world))))
    # every baked texel's centre lies in its triangle's UV image: within the triangle's u range
    # (columns) and v range (rows)
    jj, ii = np.nonzero(inside)
    uv = out.uvs[out.indices[out.face[inside]]].astype(np.float64) * 128
    assert np.all(uv[:, :, 0].min(1) <= ii + 0.5) and np.all(uv[:, :, 0].max(1) >= ii + 0.5)
    assert np.all(uv[:, :, 1].min(1) <= jj + 0.5) and np.all(uv[:, :, 1].max(1) >= jj + 0.5)
    assert out.stats["texels_baked"] == inside.sum()
    # at 128 texels the charts' padding takes much of the square
    assert 0.2 < out.stats["texels_baked"] / 128 ** 2 < 0.9, out.stats
    assert out.stats["distinct_voxels"] == len(fake.points_bodies[0])
    glb = out.glb()
    scene = trimesh.load(io.BytesIO(glb), file_type="glb", process=False)
    (geom,) = scene.geometry.values()
    assert np.array_equal(np.asarray(geom.visual.material.baseColorTexture.convert("RGB")),
                          out.texture)


class RefusingService(FakeService):
    """Refuses points requests of more than ``limit`` voxels, or spanning more than ``span``
    voxels along an axis, as the service does over its working-memory limit (422, field
    ``size``; ``status`` changes the status)."""

    def __init__(self, verts, faces, limit, span):
        super().__init__(verts, faces)
        self.limit, self.span, self.refused, self.status = limit, span, 0, 422

    def send(self, request, **kwargs):
        if urlsplit(request.url).path.endswith("/points"):
            pts = np.frombuffer(request.body, "<f4").reshape(-1, 3)
            if len(pts) > self.limit or (pts.max(0) - pts.min(0)).max() > self.span:
                self.refused += 1
                r = fake_response(self.status, {"error": {
                    "code": "unprocessable", "field": "size", "message": "needs up to 3417 MB"}})
                r.request = request
                return r
        return super().send(request, **kwargs)


def test_refused_batches_are_split_into_compact_pieces():
    verts, faces = torus(30, 14)
    whole = FakeService(verts, faces)
    want = Client("http://fake", session=whole).render_pixels(
        "vol_1", mesh_id="mesh_1", placement={"resolution": 64}, size=(80, 80), light=False)
    fake = RefusingService(verts, faces, limit=700, span=30)
    c = Client("http://fake", session=fake)
    got = c.render_pixels("vol_1", mesh_id="mesh_1", placement={"resolution": 64},
                          size=(80, 80), light=False)
    print(got.stats, fake.refused)
    assert np.array_equal(got.image, want.image)
    pieces = fake.points_bodies
    assert got.stats["points_requests"] == len(pieces) > 1 and fake.refused >= 1
    sent = np.concatenate(pieces)
    assert len(sent) == len(np.unique(sent, axis=0)) == got.stats["distinct_voxels"]
    assert got.stats["voxels_synthesized"] == 7 * len(sent)
    assert all(len(p) <= 700 and (p.max(0) - p.min(0)).max() <= 30 for p in pieces)
    # a single voxel refused is raised; so is any other error, at once
    nothing = RefusingService(verts, faces, limit=0, span=0)
    with pytest.raises(Unprocessable):
        Client("http://fake", session=nothing).render_pixels(
            "vol_1", mesh_id="mesh_1", placement={"resolution": 64}, size=(8, 8))
    bad = RefusingService(verts, faces, limit=0, span=0)
    bad.status = 400
    with pytest.raises(BadRequest):
        Client("http://fake", session=bad).render_pixels(
            "vol_1", mesh_id="mesh_1", placement={"resolution": 64}, size=(8, 8))
    assert bad.refused == 1


@pytest.mark.parametrize("kwargs,word", [
    ({"atlas_size": 8}, "atlas_size"), ({"atlas_size": 10000}, "atlas_size"),
    ({"atlas_size": bake_module.MAX_ATLAS_SIZE + 1}, "atlas_size"),
    ({"atlas_size": 64.0}, "atlas_size"), ({"texels_per_voxel": 0}, "texels_per_voxel"),
    ({"texels_per_voxel": float("nan")}, "texels_per_voxel"),
    ({"texels_per_voxel": 1e4}, "texels_per_voxel"),
    ({"atlas_size": 64, "texels_per_voxel": 1.0}, "not both"),
    ({"padding": -1}, "padding"), ({"dilate_texels": 1000}, "dilate_texels"),
])
def test_bake_errors_name_the_parameter(kwargs, word):
    verts, faces = torus(8, 4)
    c = Client("http://fake", session=FakeService(verts, faces))
    with pytest.raises(ValueError, match=word):
        c.bake("vol_1", mesh_id="mesh_1", placement={"resolution": 48}, **kwargs)


def test_render_size_is_capped_before_any_request(capsys, tmp_path):
    verts, faces = torus(8, 4)
    fake = FakeService(verts, faces)
    c = Client("http://fake", session=fake)
    for size in ((MAX_IMAGE_SIDE + 1, 8), (8, 10 ** 6), (0, 8), (8,)):
        with pytest.raises(ValueError, match=r"^size must be"):
            c.render_pixels("vol_1", mesh_id="mesh_1", size=size)
    assert fake.log == []
    mesh = tmp_path / "t.obj"
    mesh.write_bytes(obj_bytes(verts, faces))
    for colors in ("pixel", "vertex"):
        assert cli_main(["render", str(mesh), "--volume", "v", "-o", str(tmp_path / "x.png"),
                         "--colors", colors, "--size", "100000,100000"]) == 1
        err = capsys.readouterr().err
        assert "--size must be at most 4096" in err and "Traceback" not in err, err


def test_cli_render_and_bake_argument_errors(capsys, tmp_path):
    assert cli_main(["render", str(tmp_path / "none.obj"), "--volume", "v", "-o",
                     str(tmp_path / "x.png")]) == 1
    assert "no mesh file" in capsys.readouterr().err
    mesh = tmp_path / "t.obj"
    mesh.write_bytes(obj_bytes(*torus(8, 4)))
    assert cli_main(["render", str(mesh), "--volume", "v", "-o", str(tmp_path / "x.png"),
                     "--colors", "pixel", "--ply", str(tmp_path / "x.ply")]) == 1
    assert "--colors vertex" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli_main(["bake", str(mesh), "--volume", "v", "-o", "x.glb", "--atlas-size", "64",
                  "--texels-per-voxel", "1"])
    assert "not allowed with" in capsys.readouterr().err
