// JSON encodings of the service's parameter structs, shared by the services and handlers.
// Each params struct has one table of (JSON key, member, range) in api_json.cpp driving both
// directions. Decoding is strict: unknown keys are errors naming their path, each value is
// type- and range-checked, then the struct's own validate() runs; every error's field is the
// path of the offending key (`where`.key, e.g. "params.passes").
#pragma once

#include <cstdint>
#include <string_view>

#include <nlohmann/json.hpp>

#include "analysis/analysis.h"
#include "analysis/analysis_params.h"
#include "mesh/mesh.h"
#include "synthesis/synthesis_params.h"

namespace solidtex::server {

nlohmann::json to_json(const AnalysisParams& p);
Result<AnalysisParams> analysis_params_from_json(const nlohmann::json& j, const std::string& where);
nlohmann::json to_json(const SynthesisParams& p);
// `base` supplies what `j` leaves out (e.g. the table's suggested plane weights).
Result<SynthesisParams> synthesis_params_from_json(const nlohmann::json& j, const std::string& where,
                                                   SynthesisParams base);
nlohmann::json to_json(const std::vector<LevelReport>& levels);
nlohmann::json status_json(const Status& s);
// The Placement schema of proto/openapi.json: explicit {scale, translate} or a fit of the
// enlarged bounding box to {resolution (512), margin (0.25)}. `margin` receives the margin.
Result<Placement> placement_from_json(const nlohmann::json& j, const std::string& where, const MeshBounds& bounds,
                                      double* margin);  // null when ok, else {"code","message","field"}

// Characters (code points) of valid UTF-8 text: what JSON Schema's maxLength counts.
size_t utf8_length(std::string_view s);
// A JSON string of at most `max_chars` characters (code points).
Result<std::string> json_text(const nlohmann::json& j, const std::string& where, size_t max_chars = 4096);
// A request body's JSON (strict, as parse_json_text) read as JSON Schema reads numbers: a
// float with an integral value (150.0) becomes that integer, so that it passes as an integer.
Result<nlohmann::json> parse_request_json(const std::string& text, const std::string& where);
// The body text handed on to a service that parses it itself: the normalised JSON of
// parse_request_json, or the text unchanged when it is not valid JSON (the service then says why).
std::string normalized_body(const std::string& text);

}  // namespace solidtex::server
