#include "conditional_get.h"

#include <string_view>

#include "byte_range.h"
#include "http_errors.h"

namespace solidtex::server {
namespace {


std::string_view opaque(std::string_view tag) {
  if (tag.size() >= 2 && tag.substr(0, 2) == "W/") tag.remove_prefix(2);
  return tag;
}

// If-None-Match: "*" or a comma-separated list of entity tags, compared weakly.
bool none_match_fails(std::string_view header, std::string_view etag) {
  header = trim_ows(header);
  if (header.empty()) return false;
  if (header == "*") return true;
  while (!header.empty()) {
    const size_t comma = header.find(',');
    const std::string_view tag = trim_ows(header.substr(0, comma));
    if (!tag.empty() && opaque(tag) == opaque(etag)) return true;
    if (comma == std::string_view::npos) break;
    header.remove_prefix(comma + 1);
  }
  return false;
}

const std::string* header_of(const HttpResponse& r, std::string_view name) {
  for (const auto& [k, v] : r.headers)
    if (k == name) return &v;
  return nullptr;
}

}  // namespace

HttpResponse conditional_get(const HttpRequest& r, HttpResponse full) {
  if (full.status != 200) return full;
  full.headers.push_back({"Accept-Ranges", "bytes"});
  const std::string* etag = header_of(full, "ETag");
  const int64_t total = int64_t(full.body.size());
  if (etag && none_match_fails(r.if_none_match, *etag)) {
    full.status = 304;
    full.content_length = total;
    full.body.clear();
    return full;
  }
  if (r.range.empty()) return full;
  // If-Range: strong comparison, so a weak or different tag (or a date) means "send it all".
  if (!r.if_range.empty() && (!etag || trim_ows(r.if_range) != *etag || etag->starts_with("W/"))) return full;
  const ByteRange range = parse_byte_range(r.range, total);
  if (range.kind == ByteRange::kIgnored) return full;
  const std::string size = "/" + std::to_string(total);
  if (range.kind == ByteRange::kUnsatisfiable) {
    HttpResponse out;
    out.status = 416;
    out.body = error_body("range_not_satisfiable", "the representation has " + std::to_string(total) + " bytes", "Range");
    // CORS stays (a browser must be able to read the refusal); caching headers do not.
    for (const auto& h : full.headers)
      if (h.first.starts_with("Access-Control-") || h.first == "Accept-Ranges") out.headers.push_back(h);
    out.headers.push_back({"Content-Range", "bytes *" + size});
    return out;
  }
  full.status = 206;
  full.body = full.body.substr(size_t(range.first), size_t(range.last - range.first + 1));
  full.headers.push_back({"Content-Range", "bytes " + std::to_string(range.first) + "-" + std::to_string(range.last) + size});
  return full;
}

}  // namespace solidtex::server
