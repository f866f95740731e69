#include "core/json_fields.h"

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
  nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return bad(where, "is not valid JSON");
  return j;
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
