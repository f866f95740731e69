#include "http_errors.h"

#include <nlohmann/json.hpp>

namespace solidtex::server {

int http_status_for(StatusCode code) {
  switch (code) {
    case StatusCode::kOk: return 200;
    case StatusCode::kInvalidArgument: return 400;
    case StatusCode::kNotFound: return 404;
    case StatusCode::kUnsupported: return 415;
    // Asking for too much (voxels, grid nodes) is unusable content, 422; 413 is only ever the
    // HTTP layer's answer to a body over --max-upload-mb (http_server.cpp), as the contract says.
    case StatusCode::kTooLarge:
    case StatusCode::kCorrupt:
    case StatusCode::kVersionMismatch:
    case StatusCode::kUnprocessable: return 422;
    case StatusCode::kAlreadyExists:
    case StatusCode::kFailedPrecondition: return 409;
    case StatusCode::kRateLimited: return 429;
    // Cancelled: the client went away or the server is shutting down; either way "not now".
    case StatusCode::kCancelled:
    case StatusCode::kResourceExhausted: return 503;
    case StatusCode::kDeadlineExceeded: return 504;
    // The store behind this replica failed, not the replica: 502, which the reference nginx
    // neither retries on another replica (they share the store) nor counts against this one
    // (503 counts, and a store outage would mark every replica down: deploy/README.md).
    case StatusCode::kUnavailable: return 502;
    case StatusCode::kInternal:
    case StatusCode::kIo: return 500;
  }
  return 500;
}

const char* retry_after_for(StatusCode code) { return code == StatusCode::kUnavailable ? "1" : nullptr; }

std::string error_body(const std::string& code, const std::string& message, const std::string& field) {
  nlohmann::json j = {{"error", {{"code", code}, {"message", message}, {"field", field}}}};
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);  // messages may echo client bytes
}

std::string error_body(const Status& status) {
  return error_body(status_code_name(status.code()), status.message(), status.field());
}

}  // namespace solidtex::server
