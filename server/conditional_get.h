// GET and HEAD of an immutable representation that a handler answered in full (RFC 9110
// sections 13 and 14), so that array clients can revalidate and read parts of chunks:
// - If-None-Match naming the answer's ETag (weak comparison, or "*") -> 304 without a body,
//   keeping the answer's headers (ETag, Cache-Control, CORS) and the full Content-Length;
// - otherwise a Range the server honours (byte_range.h) -> 206 with those bytes and
//   Content-Range, or 416 with `Content-Range: bytes */total`; an If-Range that does not name
//   the ETag (strong comparison; dates are not supported) means the whole body, as the RFC says;
// - every 200 answer says `Accept-Ranges: bytes`.
// Answers other than 200 (errors) are returned unchanged.
#pragma once

#include "http_types.h"

namespace solidtex::server {

HttpResponse conditional_get(const HttpRequest& r, HttpResponse full);

}  // namespace solidtex::server
