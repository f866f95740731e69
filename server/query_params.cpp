#include "query_params.h"

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <string_view>

#include "core/json_fields.h"
#include "core/number_list.h"

namespace solidtex::server {

bool is_number_text(std::string_view s) {
  size_t i = 0;
  auto digits = [&] {
    const size_t start = i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
    return i > start;
  };
  if (i < s.size() && s[i] == '-') ++i;
  if (!digits()) return false;
  if (i < s.size() && s[i] == '.') {
    ++i;
    if (!digits()) return false;
  }
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (!digits()) return false;
  }
  return i == s.size();
}

bool is_number_list_text(std::string_view s, size_t count) {
  size_t items = 0, start = 0;
  for (;;) {
    const size_t comma = s.find(',', start);
    if (!is_number_text(s.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start))) return false;
    ++items;
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return items == count;
}

Result<QueryParams> QueryParams::parse(const std::vector<std::pair<std::string, std::string>>& query,
                                       const std::set<std::string>& allowed) {
  QueryParams q;
  std::set<std::string> seen;
  for (const auto& [k, v] : query) {
    if (!is_valid_utf8(k) || !is_valid_utf8(v))
      return Status(StatusCode::kInvalidArgument, "a query parameter is not valid UTF-8", "query");
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      return Status(StatusCode::kInvalidArgument,
                    "unknown query parameter" + (list.empty() ? std::string(" (none accepted)") : " (accepted: " + list + ")"), k);
    }
    if (!seen.insert(k).second) return Status(StatusCode::kInvalidArgument, "given more than once", k);
    q.values_.emplace_back(k, v);
  }
  return q;
}

bool QueryParams::has(const std::string& key) const { return get(key).has_value(); }

std::optional<std::string> QueryParams::get(const std::string& key) const {
  for (const auto& [k, v] : values_)
    if (k == key) return v;
  return std::nullopt;
}

Result<std::string> QueryParams::required(const std::string& key) const {
  auto v = get(key);
  if (!v) return Status(StatusCode::kInvalidArgument, "is required", key);
  return *v;
}

Result<int64_t> QueryParams::get_int(const std::string& key, int64_t fallback, int64_t lo, int64_t hi) const {
  auto v = get(key);
  if (!v) return fallback;
  if (!is_number_text(*v)) return Status(StatusCode::kInvalidArgument, "must be an integer", key);
  long long n = 0;
  if (v->find_first_of(".eE") != std::string::npos) {  // 150.0 or 1.5e2 is the integer 150, as in JSON Schema
    const double d = std::strtod(v->c_str(), nullptr);
    if (!std::isfinite(d) || d != std::floor(d)) return Status(StatusCode::kInvalidArgument, "must be an integer", key);
    if (d < double(lo) || d > double(hi))
      return Status(StatusCode::kInvalidArgument, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", key);
    n = static_cast<long long>(d);
  } else {
    errno = 0;
    n = std::strtoll(v->c_str(), nullptr, 10);
    if (errno == ERANGE) n = v->front() == '-' ? LLONG_MIN : LLONG_MAX;  // out of any range below
  }
  if (n < lo || n > hi)
    return Status(StatusCode::kInvalidArgument, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", key);
  return int64_t(n);
}

Result<double> QueryParams::get_double(const std::string& key, double fallback, double lo, double hi) const {
  auto v = get(key);
  if (!v) return fallback;
  if (!is_number_text(*v)) return Status(StatusCode::kInvalidArgument, "must be a number", key);
  const double d = std::strtod(v->c_str(), nullptr);
  if (!std::isfinite(d)) return Status(StatusCode::kInvalidArgument, "must be a finite number", key);
  if (d < lo || d > hi)
    return Status(StatusCode::kInvalidArgument, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", key);
  return d;
}

Result<std::vector<double>> QueryParams::get_list(const std::string& key, size_t count) const {
  SOLIDTEX_ASSIGN_OR_RETURN(std::string v, required(key));
  if (!is_number_list_text(v, count))
    return Status(StatusCode::kInvalidArgument, "expects " + std::to_string(count) + " comma-separated numbers, got '" + v + "'", key);
  return parse_number_list(v, count, key);
}

Result<std::vector<int>> QueryParams::get_int_list(const std::string& key, size_t count) const {
  SOLIDTEX_ASSIGN_OR_RETURN(auto v, get_list(key, count));
  std::vector<int> out;
  for (double d : v) {
    if (d != std::floor(d) || std::abs(d) > double(1 << 28))
      return Status(StatusCode::kInvalidArgument, "must be integers within +-2^28", key);
    out.push_back(int(d));
  }
  return out;
}

}  // namespace solidtex::server
