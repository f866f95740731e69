#include "core/json_fields.h"

#include <set>
#include <string>
#include <vector>

#include <cmath>

namespace solidtex {
namespace {
Status bad(const std::string& field, const std::string& msg) { return Status(StatusCode::kInvalidArgument, msg, field); }
}  // namespace

Status check_keys(const nlohmann::json& j, const std::set<std::string>& allowed, const std::string& where) {
  if (!j.is_object()) return bad(where, "must be a JSON object");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!allowed.count(it.key())) return bad(where.empty() ? it.key() : where + "." + it.key(), "unknown key");
  return Status::ok();
}

Result<nlohmann::json> parse_json_text(const std::string& text, const std::string& where) {
  // nlohmann keeps the last of duplicate keys; a strict reader refuses them instead.
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  auto callback = [&](int /*depth*/, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (event == E::object_start) keys.emplace_back();
    else if (event == E::object_end && !keys.empty()) keys.pop_back();
    else if (event == E::key && !keys.empty() && !keys.back().insert(parsed.get<std::string>()).second &&
             duplicate.empty())
      duplicate = parsed.get<std::string>();
    return true;
  };
  nlohmann::json j = nlohmann::json::parse(text, callback, /*allow_exceptions=*/false);
  if (j.is_discarded()) return bad(where, "is not valid JSON (UTF-8, RFC 8259)");
  if (!duplicate.empty()) return bad(where, "repeats the key '" + duplicate + "'");
  return j;
}

bool is_valid_utf8(std::string_view s) {
  size_t i = 0;
  while (i < s.size()) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    int extra = 0;
    uint32_t cp = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      extra = 1;
      cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2;
      cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3;
      cp = c & 0x07;
    } else {
      return false;
    }
    if (i + size_t(extra) >= s.size()) return false;  // truncated sequence
    for (int k = 1; k <= extra; ++k) {
      const unsigned char d = static_cast<unsigned char>(s[i + size_t(k)]);
      if ((d & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (d & 0x3F);
    }
    static constexpr uint32_t kMin[4] = {0, 0x80, 0x800, 0x10000};
    if (cp < kMin[extra] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += size_t(extra) + 1;
  }
  return true;
}

Result<WorldPoint> json_point(const nlohmann::json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) return bad(where, "must be an array of 3 numbers");
  double v[3];
  for (int i = 0; i < 3; ++i) {
    if (!j[size_t(i)].is_number()) return bad(where, "must be an array of 3 numbers");
    v[i] = j[size_t(i)].get<double>();
    if (!std::isfinite(v[i])) return bad(where, "must be finite");
  }
  return WorldPoint{v[0], v[1], v[2]};
}

Result<int64_t> json_int(const nlohmann::json& j, const std::string& where, int64_t lo, int64_t hi) {
  if (!j.is_number_integer()) return bad(where, "must be an integer");
  const int64_t v = j.is_number_unsigned() && j.get<uint64_t>() > uint64_t(INT64_MAX) ? INT64_MAX : j.get<int64_t>();
  if (v < lo || v > hi) return bad(where, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

Result<double> json_number(const nlohmann::json& j, const std::string& where, double lo, double hi) {
  if (!j.is_number()) return bad(where, "must be a number");
  const double v = j.get<double>();
  if (!std::isfinite(v) || v < lo || v > hi)
    return bad(where, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

Result<std::string> json_string(const nlohmann::json& j, const std::string& where, size_t max_length) {
  if (!j.is_string()) return bad(where, "must be a string");
  std::string s = j.get<std::string>();
  if (s.size() > max_length) return bad(where, "is longer than " + std::to_string(max_length) + " characters");
  return s;
}

}  // namespace solidtex
