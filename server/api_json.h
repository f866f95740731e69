// JSON encodings of the service's parameter structs, shared by the services and handlers.
// Each params struct has one table of (JSON key, member, range) in api_json.cpp driving both
// directions. Decoding is strict: unknown keys are errors naming their path, each value is
// type- and range-checked, then the struct's own validate() runs; every error's field is the
// path of the offending key (`where`.key, e.g. "params.passes").
#pragma once

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

}  // namespace solidtex::server
