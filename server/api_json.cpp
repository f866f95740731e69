#include "api_json.h"

#include "core/json_fields.h"

namespace solidtex::server {

using nlohmann::json;

json to_json(const AnalysisParams& p) {
  return {{"levels", p.levels},         {"neighborhood", p.neighborhood}, {"candidates", p.candidates},
          {"pca_dims", p.pca_dims},     {"search_k", p.search_k},         {"knn_checks", p.knn_checks},
          {"seed", p.seed},             {"suggested_plane_weights", p.suggested_plane_weights}};
}

Result<AnalysisParams> analysis_params_from_json(const json& j, const std::string& where) {
  SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"levels", "neighborhood", "candidates", "pca_dims", "search_k", "knn_checks",
                                          "seed", "suggested_plane_weights"},
                                      where));
  AnalysisParams p;
  auto field = [&](const char* k) { return where + "." + k; };
  if (j.contains("levels")) { SOLIDTEX_ASSIGN_OR_RETURN(p.levels, json_int(j["levels"], field("levels"), 1, 8)); }
  if (j.contains("neighborhood")) { SOLIDTEX_ASSIGN_OR_RETURN(p.neighborhood, json_int(j["neighborhood"], field("neighborhood"), 3, 15)); }
  if (j.contains("candidates")) { SOLIDTEX_ASSIGN_OR_RETURN(p.candidates, json_int(j["candidates"], field("candidates"), 1, 32)); }
  if (j.contains("pca_dims")) { SOLIDTEX_ASSIGN_OR_RETURN(p.pca_dims, json_int(j["pca_dims"], field("pca_dims"), 1, 64)); }
  if (j.contains("search_k")) { SOLIDTEX_ASSIGN_OR_RETURN(p.search_k, json_int(j["search_k"], field("search_k"), 1, 64)); }
  if (j.contains("knn_checks")) { SOLIDTEX_ASSIGN_OR_RETURN(p.knn_checks, json_int(j["knn_checks"], field("knn_checks"), 16, 100000)); }
  if (j.contains("seed")) { SOLIDTEX_ASSIGN_OR_RETURN(auto s, json_int(j["seed"], field("seed"), 0, 1 << 30)); p.seed = uint32_t(s); }
  if (j.contains("suggested_plane_weights")) {
    const json& w = j["suggested_plane_weights"];
    if (!w.is_array() || w.size() != 3) return Status(StatusCode::kInvalidArgument, "must be 3 numbers", field("suggested_plane_weights"));
    for (size_t i = 0; i < 3; ++i) {
      SOLIDTEX_ASSIGN_OR_RETURN(double v, json_number(w[i], field("suggested_plane_weights"), 0, 1));
      p.suggested_plane_weights[i] = float(v);
    }
  }
  SOLIDTEX_RETURN_IF_ERROR(p.validate());
  return p;
}

json to_json(const SynthesisParams& p) {
  return {{"scheme", scheme_name(p.scheme)},   {"matcher", matcher_name(p.matcher)},
          {"coarse_passes", p.coarse_passes},  {"passes", p.passes},
          {"subpass_size", p.subpass_size},    {"cell_size", p.cell_size},
          {"init_subpart", p.init_subpart},    {"trilinear_levels", p.trilinear_levels},
          {"plane_weights", p.plane_weights}};
}

Result<SynthesisParams> synthesis_params_from_json(const json& j, const std::string& where, SynthesisParams p) {
  SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"scheme", "matcher", "coarse_passes", "passes", "subpass_size", "cell_size",
                                          "init_subpart", "trilinear_levels", "plane_weights"},
                                      where));
  auto field = [&](const char* k) { return where + "." + k; };
  if (j.contains("scheme")) {
    SOLIDTEX_ASSIGN_OR_RETURN(std::string s, json_string(j["scheme"], field("scheme")));
    auto r = parse_scheme(s);
    if (!r) return Status(StatusCode::kInvalidArgument, r.status().message(), field("scheme"));
    p.scheme = *r;
  }
  if (j.contains("matcher")) {
    SOLIDTEX_ASSIGN_OR_RETURN(std::string s, json_string(j["matcher"], field("matcher")));
    auto r = parse_matcher(s);
    if (!r) return Status(StatusCode::kInvalidArgument, r.status().message(), field("matcher"));
    p.matcher = *r;
  }
  if (j.contains("coarse_passes")) { SOLIDTEX_ASSIGN_OR_RETURN(p.coarse_passes, json_int(j["coarse_passes"], field("coarse_passes"), 0, 8)); }
  if (j.contains("passes")) { SOLIDTEX_ASSIGN_OR_RETURN(p.passes, json_int(j["passes"], field("passes"), 0, 8)); }
  if (j.contains("subpass_size")) { SOLIDTEX_ASSIGN_OR_RETURN(p.subpass_size, json_int(j["subpass_size"], field("subpass_size"), 1, 2)); }
  if (j.contains("cell_size")) { SOLIDTEX_ASSIGN_OR_RETURN(p.cell_size, json_int(j["cell_size"], field("cell_size"), 4, 64)); }
  if (j.contains("init_subpart")) { SOLIDTEX_ASSIGN_OR_RETURN(p.init_subpart, json_int(j["init_subpart"], field("init_subpart"), 8, 256)); }
  if (j.contains("trilinear_levels")) { SOLIDTEX_ASSIGN_OR_RETURN(p.trilinear_levels, json_int(j["trilinear_levels"], field("trilinear_levels"), 0, 8)); }
  if (j.contains("plane_weights")) {
    const json& w = j["plane_weights"];
    if (!w.is_array() || w.size() != 3) return Status(StatusCode::kInvalidArgument, "must be 3 numbers", field("plane_weights"));
    for (size_t i = 0; i < 3; ++i) {
      SOLIDTEX_ASSIGN_OR_RETURN(double v, json_number(w[i], field("plane_weights"), 0, 1));
      p.plane_weights[i] = float(v);
    }
  }
  Status st = p.validate();
  if (!st.is_ok()) return Status(st.code(), st.message(), st.field().empty() ? where : where + "." + st.field());
  return p;
}

json to_json(const std::vector<LevelReport>& levels) {
  json out = json::array();
  for (const LevelReport& r : levels)
    out.push_back({{"level", r.level},
                   {"spacing", r.spacing},
                   {"mean_crossbar_error", r.mean_crossbar_error},
                   {"random_crossbar_error", r.random_crossbar_error},
                   {"coherent_fraction", r.coherent_fraction}});
  return out;
}

Result<Placement> placement_from_json(const json& j, const std::string& where, const MeshBounds& bounds, double* margin) {
  SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"resolution", "margin", "scale", "translate"}, where));
  double m = 0.25;
  if (j.contains("margin")) { SOLIDTEX_ASSIGN_OR_RETURN(m, json_number(j["margin"], where + ".margin", 0, 1)); }
  if (margin) *margin = m;
  if (j.contains("scale")) {
    if (j.contains("resolution"))
      return Status(StatusCode::kInvalidArgument, "give either scale/translate or resolution", where + ".resolution");
    Placement p;
    SOLIDTEX_ASSIGN_OR_RETURN(p.scale, json_number(j["scale"], where + ".scale", 1e-12, 1e12));
    if (j.contains("translate")) {
      SOLIDTEX_ASSIGN_OR_RETURN(WorldPoint t, json_point(j["translate"], where + ".translate"));
      p.translate = {t.x, t.y, t.z};
    }
    return p;
  }
  if (j.contains("translate")) return Status(StatusCode::kInvalidArgument, "needs scale", where + ".translate");
  int64_t resolution = 512;
  if (j.contains("resolution")) { SOLIDTEX_ASSIGN_OR_RETURN(resolution, json_int(j["resolution"], where + ".resolution", 8, 4096)); }
  return fit_placement(bounds, int(resolution), m);
}

json status_json(const Status& s) {
  if (s.is_ok()) return nullptr;
  return {{"code", status_code_name(s.code())}, {"message", s.message()}, {"field", s.field()}};
}

}  // namespace solidtex::server
