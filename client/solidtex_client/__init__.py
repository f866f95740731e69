"""Python client for the solidtex solid-texture service.

>>> from solidtex_client import Client
>>> c = Client("http://127.0.0.1:8080")
>>> up = c.upload_exemplar("wood.png", levels=3)
>>> c.wait_for_job(up["job"]["id"])
>>> vol = c.create_volume(exemplar=up["exemplar"]["id"], seed=7)
>>> rgb = c.slice(vol["id"], "z", 0, (64, 64))        # uint8 (64, 64, 3), sRGB
"""
from .client import Client, encode_png, image_bytes
from .errors import (BadRequest, Conflict, DeadlineExceeded, JobFailed, MethodNotAllowed,
                     NotFound, PayloadTooLarge, ServiceUnavailable, SolidtexError,
                     TooManyRequests, Unprocessable, UnsupportedMediaType,
                     error_from_response)

__all__ = [
    "Client", "encode_png", "image_bytes",
    "SolidtexError", "BadRequest", "NotFound", "MethodNotAllowed", "Conflict",
    "PayloadTooLarge", "UnsupportedMediaType", "Unprocessable", "TooManyRequests",
    "ServiceUnavailable", "DeadlineExceeded", "JobFailed", "error_from_response",
]
__version__ = "1.0.0"
