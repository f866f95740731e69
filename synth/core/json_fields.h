// Strict reading of JSON inputs (sketches, volume specs, request bodies): unknown keys are
// errors (pbrt's ReportUnused habit), and every error names the offending field by its path
// ("curves[2].points[5]", "params.passes").
#pragma once

#include <nlohmann/json.hpp>

#include <set>
#include <string>
#include <string_view>

#include "core/status.h"
#include "core/types.h"

namespace solidtex {

// kInvalidArgument "unknown key" naming where.key, or "must be a JSON object".
Status check_keys(const nlohmann::json& j, const std::set<std::string>& allowed, const std::string& where);
// Parses text as JSON; a syntax error names `where` and the byte offset.
Result<nlohmann::json> parse_json_text(const std::string& text, const std::string& where);

// Well-formed UTF-8 (no overlong forms, surrogates or code points beyond U+10FFFF).
bool is_valid_utf8(std::string_view s);
Result<WorldPoint> json_point(const nlohmann::json& j, const std::string& where);
Result<int64_t> json_int(const nlohmann::json& j, const std::string& where, int64_t lo, int64_t hi);
Result<double> json_number(const nlohmann::json& j, const std::string& where, double lo, double hi);
Result<std::string> json_string(const nlohmann::json& j, const std::string& where, size_t max_length = 4096);

}  // namespace solidtex
