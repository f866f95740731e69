// The route table: URL templates to handlers, nothing else. `{id}` matches one path segment.
// Execution says where a handler runs: kInline on the I/O thread (cheap lookups only), or
// kWorker on the bounded worker pool (anything that decodes images, solves or synthesizes).
// proto/openapi.json documents exactly these routes (routes_test.cpp checks both ways).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "api.h"

namespace solidtex::server {

enum class Execution { kInline, kWorker };

struct Route {
  const char* method;
  const char* path;
  Execution execution;
  HttpResponse (Api::*handler)(const HttpRequest&);
};

const std::vector<Route>& route_table();

// The route for (method, path), filling `params`; null when none. HEAD matches the GET route
// (the adapter sends its head only). `allowed` receives the methods of routes whose template
// matches the path, HEAD with every GET (for 405 and the Allow header).
const Route* match_route(const std::string& method, const std::string& path, std::map<std::string, std::string>& params,
                         std::vector<std::string>& allowed);

}  // namespace solidtex::server
