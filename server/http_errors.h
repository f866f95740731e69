// The one place that maps solidtex StatusCodes to HTTP statuses, and the one JSON error shape
// every endpoint answers with: {"error": {"code", "message", "field"}}.
#pragma once

#include <string>

#include "core/status.h"

namespace solidtex::server {

int http_status_for(StatusCode code);
// The Retry-After seconds an error answer carries, or null for none: a store outage (usually
// a restart) is worth retrying soon, from any replica.
const char* retry_after_for(StatusCode code);
// {"error": {"code": "<status_code_name>", "message": ..., "field": ...}}
std::string error_body(const Status& status);
// For errors the HTTP layer itself raises (no route, wrong method): explicit code name.
std::string error_body(const std::string& code, const std::string& message, const std::string& field);

}  // namespace solidtex::server
