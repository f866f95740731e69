// Entity tags of the chunked-array views (RFC 9110 section 8.8.3): strong, quoted, made only of
// the volume's content tag (VolumeService::ArrayInfo::tag) and the resource, so that they are
// the same across restarts and differ between any two representations the service can send.
// - A metadata document (zarr.json, .zgroup, .zattrs, .zarray, info) depends on the window
//   (--array-extent) and on the exact resource: its request path, which names the volume, the
//   view, the dataset and the document kind. The path is hashed (FNV-1a, 64 bits) so that the
//   tag holds only characters an ETag may hold, whatever the path's bytes.
// - A chunk depends on the format, the dataset and the chunk key (its bytes do not depend on
//   the window); it is also the chunk cache's key.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace solidtex::server {

// FNV-1a 64 of `bytes` as 16 lower-case hex digits (the same on every build and run).
std::string fnv1a_hex(std::string_view bytes);

std::string metadata_etag(const std::string& tag, int64_t extent, std::string_view path);
std::string chunk_etag(const std::string& tag, const std::string& format, int scale, const std::string& key);

}  // namespace solidtex::server
