// `solidtex serve`: opens the data directory, starts the services, serves the route table over
// HTTP with RESTinio until SIGTERM or SIGINT, then shuts down gracefully: new requests get 503,
// running ones have a grace period (5 s) before they are interrupted, queued ones drain, and
// the analysis threads stop (an unfinished analysis runs again at the next start).
// The only translation unit that includes RESTinio.
#pragma once

#include "server_config.h"
#include "core/status.h"

namespace solidtex::server {

Status run_server(const ServerConfig& config);

}  // namespace solidtex::server
