#include "byte_range.h"

#include <charconv>
#include <optional>

namespace solidtex::server {

std::string_view trim_ows(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}
namespace {


// 1*DIGIT; an overflowing position is as unusable as a malformed one.
std::optional<int64_t> digits(std::string_view s) {
  if (s.empty()) return std::nullopt;
  int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v < 0) return std::nullopt;
  return v;
}

bool unit_is_bytes(std::string_view unit) {
  if (unit.size() != 5) return false;
  for (size_t i = 0; i < 5; ++i)
    if ((unit[i] | 0x20) != "bytes"[i]) return false;  // range units are case-insensitive
  return true;
}

}  // namespace

ByteRange parse_byte_range(std::string_view header, int64_t total) {
  const ByteRange ignored;
  const size_t eq = header.find('=');
  if (eq == std::string_view::npos || !unit_is_bytes(trim_ows(header.substr(0, eq)))) return ignored;
  const std::string_view spec = trim_ows(header.substr(eq + 1));
  if (spec.find(',') != std::string_view::npos) return ignored;  // several ranges: not served as multipart
  const size_t dash = spec.find('-');
  if (dash == std::string_view::npos) return ignored;
  const std::string_view a = spec.substr(0, dash), b = spec.substr(dash + 1);
  ByteRange r;
  if (a.empty()) {  // suffix: the last n bytes
    const auto n = digits(b);
    if (!n) return ignored;
    if (*n == 0 || total == 0) return {ByteRange::kUnsatisfiable};
    r.first = *n >= total ? 0 : total - *n;
    r.last = total - 1;
  } else {
    const auto first = digits(a);
    if (!first) return ignored;
    std::optional<int64_t> last = total - 1;
    if (!b.empty()) {
      last = digits(b);
      if (!last || *last < *first) return ignored;  // a-b with b < a is invalid syntax, not unsatisfiable
    }
    if (*first >= total) return {ByteRange::kUnsatisfiable};
    r.first = *first;
    r.last = *last >= total ? total - 1 : *last;
  }
  r.kind = ByteRange::kSatisfiable;
  return r;
}

}  // namespace solidtex::server
