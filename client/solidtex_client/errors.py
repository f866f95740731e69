"""Typed exceptions built from the service's error body.

Every error answer of the service has the shape
``{"error": {"code": str, "message": str, "field": str}}``; :func:`error_from_response`
turns it into the :class:`SolidtexError` subclass for its HTTP status.
"""
from __future__ import annotations

from email.utils import parsedate_to_datetime
from datetime import datetime, timezone
from typing import Any, Dict, Optional, Type


class SolidtexError(Exception):
    """An error answer of the service (or a failed background job).

    ``status`` is the HTTP status (``None`` for a failed job), ``code`` the machine-readable
    code (``invalid_argument``, ``not_found``, ...), ``field`` the input it is about (a JSON
    path, a query parameter, ``body``; may be empty).
    """

    def __init__(self, status: Optional[int], code: str, message: str, field: str = "",
                 response: Any = None) -> None:
        self.status = status
        self.code = code
        self.message = message
        self.field = field
        self.response = response
        super().__init__(str(self))

    def __str__(self) -> str:
        text = f"{self.code}: {self.message}"
        if self.field:
            text += f" ({self.field})"
        return text

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(status={self.status!r}, code={self.code!r}, "
                f"message={self.message!r}, field={self.field!r})")


class BadRequest(SolidtexError):
    """400: malformed request (bad JSON, unknown key or query parameter, value out of range)."""


class NotFound(SolidtexError):
    """404: no such resource."""


class MethodNotAllowed(SolidtexError):
    """405: the route exists but not with this method."""


class Conflict(SolidtexError):
    """409: resource in use or not ready."""


class PayloadTooLarge(SolidtexError):
    """413: body larger than the server's upload limit."""


class UnsupportedMediaType(SolidtexError):
    """415: unsupported Content-Type or image format."""


class Unprocessable(SolidtexError):
    """422: well-formed but unusable (image too large or corrupt, too many voxels)."""


class TooManyRequests(SolidtexError):
    """429: too many concurrent analysis jobs."""


class ServiceUnavailable(SolidtexError):
    """503: worker queue full or shutting down; ``retry_after`` in seconds (or ``None``)."""

    def __init__(self, status: Optional[int], code: str, message: str, field: str = "",
                 response: Any = None, retry_after: Optional[float] = None) -> None:
        self.retry_after = retry_after
        super().__init__(status, code, message, field, response)


class StorageUnavailable(ServiceUnavailable):
    """502: the server's storage backend cannot be reached right now (code ``unavailable``);
    ``retry_after`` in seconds (or ``None``). A ServiceUnavailable, so one handler retries both."""


class DeadlineExceeded(SolidtexError):
    """504: the request's deadline passed and its work was cancelled."""


class JobFailed(SolidtexError):
    """A background job ended in state ``failed`` (``status`` is ``None``)."""

    def __init__(self, job: Dict[str, Any]) -> None:
        self.job = job
        err = job.get("error") or {}
        if not isinstance(err, dict):
            err = {"message": str(err)}
        super().__init__(None, str(err.get("code", "failed")),
                         str(err.get("message", f"job {job.get('id')} failed")),
                         str(err.get("field", "") or ""))


_BY_STATUS: Dict[int, Type[SolidtexError]] = {
    400: BadRequest,
    404: NotFound,
    405: MethodNotAllowed,
    409: Conflict,
    413: PayloadTooLarge,
    415: UnsupportedMediaType,
    422: Unprocessable,
    429: TooManyRequests,
    502: StorageUnavailable,
    503: ServiceUnavailable,
    504: DeadlineExceeded,
}


def parse_retry_after(value: Optional[str]) -> Optional[float]:
    """Seconds from a Retry-After header (delta-seconds or HTTP date); ``None`` if absent/bad."""
    if value is None:
        return None
    value = value.strip()
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:
        when = parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    return max(0.0, (when - datetime.now(timezone.utc)).total_seconds())


def error_from_response(response: Any) -> SolidtexError:
    """The typed exception for an error answer (a ``requests.Response`` with status >= 400).

    Bodies that are not the documented error JSON still give an exception: ``code`` is then
    ``http_<status>`` and ``message`` the body text (truncated).
    """
    status = int(response.status_code)
    code, message, field = f"http_{status}", "", ""
    try:
        body = response.json()
        err = body.get("error") if isinstance(body, dict) else None
        if isinstance(err, dict):
            code = str(err.get("code") or code)
            message = str(err.get("message") or "")
            field = str(err.get("field") or "")
        else:
            message = response.text[:500]
    except ValueError:
        message = response.text[:500] if response.text else (getattr(response, "reason", "") or "")
    cls = _BY_STATUS.get(status, SolidtexError)
    if issubclass(cls, ServiceUnavailable):
        return cls(status, code, message, field, response,
                   retry_after=parse_retry_after(response.headers.get("Retry-After")))
    return cls(status, code, message, field, response)
