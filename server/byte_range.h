// The Range request header (RFC 9110 section 14.2) for one representation of `total` bytes.
// Only what array clients send is honoured: a single range of unit "bytes" in one of the forms
// `a-b`, `a-` or `-n`. Anything else (another unit, several ranges, a syntax error) is reported
// as kIgnored, and the server answers 200 with the whole body, as the RFC allows.
#pragma once

#include <cstdint>
#include <string_view>

namespace solidtex::server {

struct ByteRange {
  enum Kind {
    kIgnored,        // no header, or one we do not honour: send everything (200)
    kSatisfiable,    // send bytes [first, last] (206, Content-Range: bytes first-last/total)
    kUnsatisfiable,  // a valid range past the end, or a zero-length suffix (416, bytes */total)
  };
  Kind kind = kIgnored;
  int64_t first = 0;  // kSatisfiable: 0 <= first <= last < total
  int64_t last = -1;
};

// `s` without the optional whitespace (spaces, tabs) HTTP allows around header values.
std::string_view trim_ows(std::string_view s);

ByteRange parse_byte_range(std::string_view header, int64_t total);

}  // namespace solidtex::server
