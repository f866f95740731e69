// Transport-neutral request and response: the RESTinio adapter (http_server.cpp) fills an
// HttpRequest and sends the HttpResponse, so handlers never see the HTTP library.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "request_interrupter.h"
#include "core/status.h"

namespace solidtex::server {

struct HttpRequest {
  std::string method;  // "GET", "POST", ...
  std::string path;    // concrete path, without the query
  std::string route;   // the matched route template, e.g. "/v1/volumes/{id}/slice"
  std::map<std::string, std::string> path_params;             // "id" -> value
  std::vector<std::pair<std::string, std::string>> query;     // decoded, in order
  std::string content_type;                                   // lower-case media type, no parameters
  std::string accept;                                         // raw Accept header (may be empty)
  std::string range, if_range, if_none_match;                 // raw headers (conditional_get.h); may be empty
  std::string body;
  // Multipart bodies, split by the adapter: (part name, bytes).
  std::vector<std::pair<std::string, std::string>> parts;
  bool multipart = false;
  Clock::time_point arrival = Clock::now();
  std::shared_ptr<std::atomic<bool>> disconnected = std::make_shared<std::atomic<bool>>(false);

  const std::string& param(const std::string& name) const { return path_params.at(name); }
};

struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::vector<std::pair<std::string, std::string>> headers;
  std::string body;
  // >= 0: send only the head, with this Content-Length (a 304 gives the length a 200 would
  // have). The adapter answers every HEAD this way, with the length of the body it drops.
  int64_t content_length = -1;

  static HttpResponse json(int status, const nlohmann::json& j);
  static HttpResponse error(const Status& s);  // status code from http_errors.h
};

}  // namespace solidtex::server
