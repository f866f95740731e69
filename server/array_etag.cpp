#include "array_etag.h"

#include <cstdio>

namespace solidtex::server {

std::string fnv1a_hex(std::string_view bytes) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const char c : bytes) h = (h ^ uint8_t(c)) * 0x100000001b3ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

std::string metadata_etag(const std::string& tag, int64_t extent, std::string_view path) {
  return "\"" + tag + "-" + std::to_string(extent) + "-" + fnv1a_hex(path) + "\"";
}

std::string chunk_etag(const std::string& tag, const std::string& format, int scale, const std::string& key) {
  return "\"" + tag + "-" + format + "-" + std::to_string(scale) + "-" + key + "\"";
}

}  // namespace solidtex::server
