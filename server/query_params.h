// Strict reading of a request's query string: only declared keys are accepted (an unknown or
// repeated key is an error naming it), values are parsed and range-checked, errors name the key.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/status.h"

namespace solidtex::server {

// A JSON number (RFC 8259 section 6, leading zeros allowed): the only number syntax the
// contract's query values and text specs take (no spaces, '+', hex, inf or nan).
bool is_number_text(std::string_view s);
// Exactly `count` comma-separated JSON numbers.
bool is_number_list_text(std::string_view s, size_t count);

class QueryParams {
 public:
  static Result<QueryParams> parse(const std::vector<std::pair<std::string, std::string>>& query,
                                   const std::set<std::string>& allowed);
  bool has(const std::string& key) const;
  std::optional<std::string> get(const std::string& key) const;
  Result<std::string> required(const std::string& key) const;
  Result<int64_t> get_int(const std::string& key, int64_t fallback, int64_t lo, int64_t hi) const;
  Result<double> get_double(const std::string& key, double fallback, double lo, double hi) const;
  // Exactly `count` comma-separated numbers (required).
  Result<std::vector<double>> get_list(const std::string& key, size_t count) const;
  // Like get_list, all integers.
  Result<std::vector<int>> get_int_list(const std::string& key, size_t count) const;

 private:
  std::vector<std::pair<std::string, std::string>> values_;
};

}  // namespace solidtex::server
