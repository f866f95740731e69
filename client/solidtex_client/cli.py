"""``solidtex-client``: command-line access to a solidtex service.

    solidtex-client [--url URL] upload IMAGE [--yz IMG --zx IMG --mask IMG] [--levels L ...] [--wait]
    solidtex-client field SKETCH.json
    solidtex-client volume --exemplar ID [--field-id ID | --field-spec SPEC] [--seed S] [--scheme S]
    solidtex-client slice VOLUME --axis z --at K --size W,H [--origin U,V] [--scale S] -o OUT.png
    solidtex-client region VOLUME --min X,Y,Z --size W,H,D -o OUT.vdb|OUT.npy
    solidtex-client points VOLUME POINTS.npy|POINTS.txt [--resample auto|nearest|cubic] -o OUT.npy|OUT.txt
    solidtex-client mesh MESH.obj|.ply|.off [--name N]
    solidtex-client render MESH --volume ID -o VIEW.png [--colors pixel|vertex --azimuth A
                    --elevation E --size W,H --resolution R --margin M --no-light --up y|z
                    --ply OUT.ply (implies --colors vertex)]
    solidtex-client bake MESH --volume ID -o OUT.glb [--atlas-size N | --texels-per-voxel T]
                    [--resolution R --margin M --padding P --dilate D --texture OUT.png]

MESH is a mesh file (OBJ, PLY or OFF) or the id of a stored mesh (mesh_...).

JSON answers go to stdout. Errors print ``error: <code>: <message> (field)`` on stderr and
exit with status 1. Coordinates and sizes are finest voxels, timeouts seconds.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import sys
from typing import Any, Callable, List, Optional, Sequence, Union

import numpy as np
import requests

from .bake import MAX_ATLAS_SIZE
from .client import Client
from .errors import SolidtexError
from .render import MAX_IMAGE_SIDE


def _numbers(n: int, convert: Callable[[str], Any], noun: str):
    """An argparse type: exactly ``n`` comma-separated values, each read by ``convert``."""
    def parse(text: str) -> List[Any]:
        try:
            values = [convert(s) for s in text.split(",")]
        except ValueError:
            values = None
        if values is None or len(values) != n:
            raise argparse.ArgumentTypeError(f"expected {n} comma-separated {noun}, got {text!r}")
        return values
    return parse


def _ints(n: int):
    return _numbers(n, int, "integers")


def _levels(text: str) -> Union[str, int]:
    """--levels: 'auto' or an integer (the server checks its range and names `levels`)."""
    if text == "auto":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is neither auto nor an integer") from None


def _floats(n: int):
    return _numbers(n, float, "numbers")


def _print_json(value: Any) -> None:
    print(json.dumps(value, indent=2, sort_keys=True))


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="solidtex-client", description=__doc__.split("\n")[0])
    p.add_argument("--url", default=os.environ.get("SOLIDTEX_URL", "http://127.0.0.1:8080"),
                   help="service base URL (default $SOLIDTEX_URL or http://127.0.0.1:8080)")
    p.add_argument("--http-timeout", type=float, default=120.0, help="HTTP timeout, seconds")
    sub = p.add_subparsers(dest="command", required=True)

    up = sub.add_parser("upload", help="upload an exemplar and start its analysis")
    up.add_argument("image")
    up.add_argument("--yz")
    up.add_argument("--zx")
    up.add_argument("--mask")
    up.add_argument("--name")
    up.add_argument("--levels", type=_levels, metavar="auto|L", help="pyramid levels, 1-8; auto (the server's default) follows the image size")
    up.add_argument("--neighborhood", type=int)
    up.add_argument("--candidates", type=int)
    up.add_argument("--pca-dims", type=int)
    up.add_argument("--seed", type=int)
    up.add_argument("--plane-weights", type=_floats(3), metavar="A,B,C")
    up.add_argument("--wait", action="store_true", help="wait for the analysis to finish")
    up.add_argument("--wait-timeout", type=float, default=600.0, help="seconds")

    fi = sub.add_parser("field", help="solve a frame field from a sketch JSON file")
    fi.add_argument("sketch")
    fi.add_argument("--timeout", type=float, help="server deadline, seconds")

    vo = sub.add_parser("volume", help="create a volume")
    vo.add_argument("--exemplar", required=True)
    group = vo.add_mutually_exclusive_group()
    group.add_argument("--field-id")
    group.add_argument("--field-spec", help="identity | quat:W,X,Y,Z | axis:X,Y,Z,DEG [;scale:SX,SY,SZ]")
    vo.add_argument("--seed", type=int)
    vo.add_argument("--name")
    vo.add_argument("--scheme", choices=["plain", "subpass", "grid", "dual-grid"])
    vo.add_argument("--matcher", choices=["paper", "coherent"])

    sl = sub.add_parser("slice", help="axis-aligned cut to a PNG")
    sl.add_argument("volume")
    sl.add_argument("--axis", required=True, choices=["x", "y", "z"])
    sl.add_argument("--at", required=True, type=int)
    sl.add_argument("--size", required=True, type=_ints(2), metavar="W,H")
    sl.add_argument("--origin", type=_ints(2), default=[0, 0], metavar="U,V")
    sl.add_argument("--scale", type=int, default=0, metavar="S",
                    help="pyramid dataset (as the zarr views'): 0 (default) the finest voxels, "
                         "S > 0 a coarser level whose voxels are 2^S finest wide; --at, "
                         "--origin and --size then count its voxels")
    sl.add_argument("--timeout", type=float, help="server deadline, seconds")
    sl.add_argument("-o", "--output", required=True)

    rg = sub.add_parser("region", help="a box of voxels to .vdb (or .npy, D x H x W x 3)")
    rg.add_argument("volume")
    rg.add_argument("--min", required=True, type=_ints(3), metavar="X,Y,Z")
    rg.add_argument("--size", required=True, type=_ints(3), metavar="W,H,D")
    rg.add_argument("--dtype", choices=["float32", "uint8"], default="float32",
                    help=".npy output: linear float32 (default) or sRGB uint8")
    rg.add_argument("--timeout", type=float, help="server deadline, seconds")
    rg.add_argument("-o", "--output", required=True)

    pt = sub.add_parser("points", help="linear RGB at world points")
    pt.add_argument("volume")
    pt.add_argument("points", help=".npy (N x 3) or text, one 'x y z' (or x,y,z) per line")
    pt.add_argument("--timeout", type=float, help="server deadline, seconds")
    pt.add_argument("--resample", choices=["auto", "nearest", "cubic"],
                    help="nearest voxel (the server's default), Catmull-Rom resampling, or what the volume's cuts use")
    pt.add_argument("-o", "--output", required=True, help=".npy or .txt")

    me = sub.add_parser("mesh", help="store a mesh (OBJ, PLY or OFF) and print its summary")
    me.add_argument("mesh")
    me.add_argument("--name")

    rd = sub.add_parser("render", help="texture a mesh with a volume and render it to a PNG")
    rd.add_argument("mesh", help="OBJ, PLY or OFF file, or a stored mesh's id")
    rd.add_argument("--volume", required=True)
    rd.add_argument("-o", "--output", required=True, help="PNG file")
    rd.add_argument("--colors", choices=["pixel", "vertex"],
                    help="pixel (default): each pixel's color from the volume at its surface "
                         "point, one points batch; vertex (the default with --ply): the "
                         "surface endpoint's vertex colors, interpolated")
    rd.add_argument("--azimuth", type=float, default=30.0, help="degrees (default 30)")
    rd.add_argument("--elevation", type=float, default=20.0, help="degrees (default 20)")
    rd.add_argument("--size", type=_ints(2), default=[512, 512], metavar="W,H",
                    help=f"image size in pixels (default 512,512; at most {MAX_IMAGE_SIDE} per side)")
    rd.add_argument("--resolution", type=int,
                    help="voxels along the mesh's longest side (server default 512)")
    rd.add_argument("--margin", type=float,
                    help="fraction of the longest side added on every side (server default 0.25)")
    rd.add_argument("--no-light", action="store_true", help="unshaded vertex colors")
    rd.add_argument("--up", choices=["y", "z"], default="y", help="the mesh's up axis (default y)")
    rd.add_argument("--ply", help="also write the vertex-colored mesh to this PLY file "
                    "(implies --colors vertex)")
    rd.add_argument("--timeout", type=float, help="server deadline, seconds")

    bk = sub.add_parser("bake", help="bake a volume's colors into a UV atlas: textured glTF "
                        "(.glb)")
    bk.add_argument("mesh", help="OBJ, PLY or OFF file, or a stored mesh's id")
    bk.add_argument("--volume", required=True)
    bk.add_argument("-o", "--output", required=True, help=".glb file")
    density = bk.add_mutually_exclusive_group()
    density.add_argument("--atlas-size", type=int,
                         help=f"texels per side of the square texture (default 1024, at most "
                              f"{MAX_ATLAS_SIZE}); the density is the highest that fits")
    density.add_argument("--texels-per-voxel", type=float,
                         help="texel density along the surface, texels per finest voxel; the "
                              "atlas is as large as that needs")
    bk.add_argument("--resolution", type=int,
                    help="voxels along the mesh's longest side (default 512)")
    bk.add_argument("--margin", type=float,
                    help="fraction of the longest side added on every side (default 0.25)")
    bk.add_argument("--padding", type=int, default=4, help="texels between charts (default 4)")
    bk.add_argument("--dilate", type=int, default=8,
                    help="rings of texels filled past chart borders (default 8)")
    bk.add_argument("--texture", help="also write the texture to this PNG file")
    bk.add_argument("--timeout", type=float, help="server deadline, seconds")
    return p


def _mesh_arg(text: str) -> dict:
    """``{"mesh": path}`` for an existing file, ``{"mesh_id": id}`` for a stored mesh's id."""
    if os.path.exists(text):
        return {"mesh": text}
    if text.startswith("mesh_"):
        return {"mesh_id": text}
    raise FileNotFoundError(f"no mesh file {text!r} (and not a stored mesh's id, mesh_...)")


def _placement(args: argparse.Namespace) -> dict:
    return {k: v for k, v in (("resolution", args.resolution), ("margin", args.margin))
            if v is not None}


def _load_points(path: str) -> np.ndarray:
    if path.endswith(".npy"):
        pts = np.load(path)
    else:
        with open(path) as f:
            rows = [line.replace(",", " ").split() for line in f]
        pts = np.array([[float(x) for x in row] for row in rows if row], dtype=np.float64)
    pts = np.asarray(pts, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"{path}: points must be N x 3, got shape {pts.shape}")
    return pts


def _run(args: argparse.Namespace) -> None:
    client = Client(args.url, timeout=args.http_timeout)
    if args.command == "upload":
        params = {"name": args.name, "levels": args.levels, "neighborhood": args.neighborhood,
                  "candidates": args.candidates, "pca_dims": args.pca_dims, "seed": args.seed,
                  "plane_weights": args.plane_weights}
        out = client.upload_exemplar(args.image, yz=args.yz, zx=args.zx, mask=args.mask, **params)
        if args.wait:
            job = client.wait_for_job(out["job"]["id"], timeout=args.wait_timeout)
            out = {"exemplar": client.get_exemplar(out["exemplar"]["id"]), "job": job}
        _print_json(out)
    elif args.command == "field":
        with open(args.sketch) as f:
            sketch = json.load(f)
        _print_json(client.create_field(sketch, timeout=args.timeout))
    elif args.command == "volume":
        params = {k: v for k, v in (("scheme", args.scheme), ("matcher", args.matcher)) if v}
        field: Optional[dict] = None
        if args.field_id:
            field = {"id": args.field_id}
        elif args.field_spec:
            field = {"spec": args.field_spec}
        _print_json(client.create_volume(exemplar=args.exemplar, field=field,
                                         params=params or None, seed=args.seed, name=args.name))
    elif args.command == "slice":
        png = client.slice(args.volume, args.axis, args.at, args.size, origin=args.origin,
                           dtype="png_bytes", timeout=args.timeout, scale=args.scale)
        with open(args.output, "wb") as f:
            f.write(png)
    elif args.command == "region":
        if args.output.endswith(".npy"):
            arr = client.region(args.volume, args.min, args.size, fmt=args.dtype,
                                timeout=args.timeout)
            np.save(args.output, arr)
        else:
            data = client.region(args.volume, args.min, args.size, fmt="vdb", timeout=args.timeout)
            with open(args.output, "wb") as f:
                f.write(data)
    elif args.command == "points":
        rgb = client.points(args.volume, _load_points(args.points), timeout=args.timeout, resample=args.resample)
        if args.output.endswith(".txt"):
            np.savetxt(args.output, rgb, fmt="%.9g")
        else:
            np.save(args.output, rgb)
    elif args.command == "mesh":
        _print_json(client.upload_mesh(args.mesh, name=args.name))
    elif args.command == "render":
        if (args.colors or ("vertex" if args.ply else "pixel")) == "pixel":
            _render_pixels(client, args)
        else:
            _render(client, args)
    elif args.command == "bake":
        _bake(client, args)


def _render_pixels(client: Client, args: argparse.Namespace) -> None:
    from PIL import Image

    if args.size[0] < 1 or args.size[1] < 1:
        raise ValueError(f"--size must be positive, got {args.size}")
    if max(args.size) > MAX_IMAGE_SIDE:
        raise ValueError(f"--size must be at most {MAX_IMAGE_SIDE} pixels per side (memory grows "
                         f"with the pixel count, ~225 bytes per pixel), got {args.size}")
    if args.ply:
        raise ValueError("--ply writes vertex colors: it needs --colors vertex")
    out = client.render_pixels(args.volume, **_mesh_arg(args.mesh), placement=_placement(args),
                               azimuth=args.azimuth, elevation=args.elevation, size=args.size,
                               light=not args.no_light, up=args.up, timeout=args.timeout)
    Image.fromarray(out.image, "RGB").save(args.output, format="PNG")
    _print_json({"output": args.output, "colors": "pixel", "triangles": len(out.mesh.faces),
                 "placement": out.placement.to_json(), **out.stats})


def _bake(client: Client, args: argparse.Namespace) -> None:
    out = client.bake(args.volume, **_mesh_arg(args.mesh), placement=_placement(args),
                      atlas_size=args.atlas_size, texels_per_voxel=args.texels_per_voxel,
                      padding=args.padding, dilate_texels=args.dilate, timeout=args.timeout)
    glb = out.glb()
    with open(args.output, "wb") as f:
        f.write(glb)
    if args.texture:
        with open(args.texture, "wb") as f:
            f.write(out.png())
    _print_json({"output": args.output, "bytes": len(glb), "placement": out.placement.to_json(),
                 **out.stats})


def _render(client: Client, args: argparse.Namespace) -> None:
    from PIL import Image

    from .render import render

    if args.size[0] < 1 or args.size[1] < 1:
        raise ValueError(f"--size must be positive, got {args.size}")
    if max(args.size) > MAX_IMAGE_SIDE:
        raise ValueError(f"--size must be at most {MAX_IMAGE_SIDE} pixels per side (memory grows "
                         f"with the pixel count, ~225 bytes per pixel), got {args.size}")
    where = _mesh_arg(args.mesh)
    colored = client.surface(args.volume, **where, placement=_placement(args), fmt="ply",
                             timeout=args.timeout)
    if args.ply:
        with open(args.ply, "wb") as f:
            f.write(colored.to_ply())
    img = render(colored, azimuth=args.azimuth, elevation=args.elevation, size=args.size,
                 light=not args.no_light, up=args.up)
    Image.fromarray(img, "RGB").save(args.output, format="PNG")
    summary = {"output": args.output, "colors": "vertex", "vertices": len(colored.vertices),
               "triangles": len(colored.faces)}
    for key, header in (("target_voxels", "X-Target-Voxels"),
                        ("bounding_voxels", "X-Bounding-Voxels"),
                        ("voxels_synthesized", "X-Voxels-Synthesized")):
        try:
            summary[key] = colored.header_int(header)
        except (KeyError, ValueError):
            pass
    _print_json(summary)


_NEGATIVE_VALUE = re.compile(r"^-[0-9.]")


def attach_negative_values(argv: Sequence[str]) -> List[str]:
    """``--origin -60,-60`` -> ``--origin=-60,-60``.

    argparse reads a token starting with ``-`` as an option unless it is a single negative
    number, so comma lists of coordinates (``--min -8,0,0``) would be refused; no option
    of ours starts with a digit, so such a token is always the previous option's value.
    """
    out: List[str] = []
    for token in argv:
        if (out and _NEGATIVE_VALUE.match(token) and out[-1].startswith("--") and "=" not in out[-1]):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Entry point; returns the process exit status (0, or 1 on any error)."""
    args = _parser().parse_args(attach_negative_values(sys.argv[1:] if argv is None else list(argv)))
    try:
        _run(args)
    except SolidtexError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    except requests.RequestException as e:
        print(f"error: connection: {e}", file=sys.stderr)
        return 1
    except (OSError, ValueError, TimeoutError, ImportError, RuntimeError) as e:
        print(f"error: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    except MemoryError:
        print("error: out of memory (a smaller --size, --atlas-size or --resolution needs less)",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
