"""Python client for the solidtex solid-texture service.

>>> from solidtex_client import Client
>>> c = Client("http://127.0.0.1:8080")
>>> up = c.upload_exemplar("wood.png", levels=3)
>>> c.wait_for_job(up["job"]["id"])
>>> vol = c.create_volume(exemplar=up["exemplar"]["id"], seed=7)
>>> rgb = c.slice(vol["id"], "z", 0, (64, 64))        # uint8 (64, 64, 3), sRGB
>>> m = c.upload_mesh("bunny.off")
>>> colored = c.surface(vol["id"], mesh_id=m["id"], placement={"resolution": 256})
>>> from solidtex_client.render import render
>>> img = render(colored, azimuth=30, elevation=20, size=(512, 512))   # per-vertex colors
>>> view = c.render_pixels(vol["id"], mesh_id=m["id"], size=(512, 512))  # a color per pixel
>>> baked = c.bake(vol["id"], mesh_id=m["id"], atlas_size=1024)          # needs xatlas
>>> open("bunny.glb", "wb").write(baked.glb())
"""
from .client import Client, encode_png, image_bytes
from .mesh import (ColoredMesh, PlyFormatError, TriangleMesh, mesh_bytes, parse_colored_ply,
                   parse_mesh_ply)
from .errors import (BadRequest, Conflict, DeadlineExceeded, JobFailed, MethodNotAllowed,
                     NotFound, PayloadTooLarge, ServiceUnavailable, SolidtexError, StorageUnavailable,
                     TooManyRequests, Unprocessable, UnsupportedMediaType,
                     error_from_response)

__all__ = [
    "Client", "encode_png", "image_bytes",
    "ColoredMesh", "PlyFormatError", "TriangleMesh", "mesh_bytes", "parse_colored_ply",
    "parse_mesh_ply",
    "SolidtexError", "BadRequest", "NotFound", "MethodNotAllowed", "Conflict",
    "PayloadTooLarge", "UnsupportedMediaType", "Unprocessable", "TooManyRequests",
    "ServiceUnavailable", "StorageUnavailable", "DeadlineExceeded", "JobFailed", "error_from_response",
]
__version__ = "1.0.0"
