#include "api_json.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>
#include <variant>

#include "core/json_fields.h"

namespace solidtex::server {

using nlohmann::json;

namespace {

// One JSON key of a parameter struct P: the member it stands for and, for numbers, the range
// the JSON value must lie in (each element's, for the weight triples). The struct's own
// validate() runs afterwards for the rules that involve several members.
template <typename P>
struct Param {
  // std::optional<float>: a number in range, or "auto" for absent (resolved per table).
  using Member = std::variant<int P::*, uint32_t P::*, float P::*, std::optional<float> P::*, std::array<float, 3> P::*,
                              Scheme P::*, Matcher P::*, Init P::*, ColorRule P::*, FinestMatch P::*,
                              FinestSources P::*>;
  const char* key;
  Member member;
  int64_t lo = 0, hi = 0;
};

// Both directions of every key, in the order errors are looked for.
constexpr Param<AnalysisParams> kAnalysisParams[] = {
    {"levels", &AnalysisParams::levels, 0, 8},  // 0: kAutoLevels
    {"neighborhood", &AnalysisParams::neighborhood, 3, 15},
    {"candidates", &AnalysisParams::candidates, 1, 32},
    {"pca_dims", &AnalysisParams::pca_dims, 1, 64},
    {"search_k", &AnalysisParams::search_k, 1, 64},
    {"knn_checks", &AnalysisParams::knn_checks, 16, 100000},
    {"seed", &AnalysisParams::seed, 0, 1 << 30},
    {"suggested_plane_weights", &AnalysisParams::suggested_plane_weights, 0, 1},
};

// SynthesisParams::seed is not a key: volumes take it from their own "seed".
constexpr Param<SynthesisParams> kSynthesisParams[] = {
    {"scheme", &SynthesisParams::scheme},
    {"matcher", &SynthesisParams::matcher},
    {"coarse_passes", &SynthesisParams::coarse_passes, 0, 8},
    {"passes", &SynthesisParams::passes, 0, 8},
    {"subpass_size", &SynthesisParams::subpass_size, 1, 2},
    {"finest_subpass_size", &SynthesisParams::finest_subpass_size, 1, 2},
    {"cell_size", &SynthesisParams::cell_size, 4, 64},
    {"init", &SynthesisParams::init},
    {"color", &SynthesisParams::color},
    {"finest_match", &SynthesisParams::finest_match},
    {"finest_sources", &SynthesisParams::finest_sources},
    {"init_subpart", &SynthesisParams::init_subpart, 8, 256},
    {"init_band", &SynthesisParams::init_band, 0, 256},
    {"trilinear_levels", &SynthesisParams::trilinear_levels, 0, 8},
    {"plane_weights", &SynthesisParams::plane_weights, 0, 1},
    {"typicality", &SynthesisParams::typicality, 0, 4},
    {"finest_typicality_scale", &SynthesisParams::finest_typicality_scale, 0, 1},
    {"balance", &SynthesisParams::balance, 0, 4},
};

template <typename... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <typename... F> Overloaded(F...) -> Overloaded<F...>;  // clang < 17: no aggregate CTAD

// A named enum value; the parser's message (e.g. "scheme 'standard' was renamed 'plain' ...")
// is kept, the field becomes the value's path.
template <typename E>
Status read_name(const json& v, const std::string& field, Result<E> (*parse)(const std::string&), E& out) {
  SOLIDTEX_ASSIGN_OR_RETURN(std::string s, json_string(v, field));
  Result<E> r = parse(s);
  if (!r) return Status(StatusCode::kInvalidArgument, r.status().message(), field);
  out = *r;
  return Status::ok();
}

template <typename P>
Status read_param(const Param<P>& d, const json& v, const std::string& field, P& p) {
  return std::visit(
      Overloaded{
          [&](int P::*m) -> Status {
            SOLIDTEX_ASSIGN_OR_RETURN(int64_t x, json_int(v, field, d.lo, d.hi));
            p.*m = int(x);
            return Status::ok();
          },
          [&](uint32_t P::*m) -> Status {
            SOLIDTEX_ASSIGN_OR_RETURN(int64_t x, json_int(v, field, d.lo, d.hi));
            p.*m = uint32_t(x);
            return Status::ok();
          },
          [&](float P::*m) -> Status {
            SOLIDTEX_ASSIGN_OR_RETURN(double x, json_number(v, field, double(d.lo), double(d.hi)));
            p.*m = float(x);
            return Status::ok();
          },
          [&](std::optional<float> P::*m) -> Status {
            if (v.is_string() && v.get<std::string>() == "auto") {
              p.*m = std::nullopt;
              return Status::ok();
            }
            if (!v.is_number()) return Status(StatusCode::kInvalidArgument, "must be a number or \"auto\"", field);
            SOLIDTEX_ASSIGN_OR_RETURN(double x, json_number(v, field, double(d.lo), double(d.hi)));
            p.*m = float(x);
            return Status::ok();
          },
          [&](std::array<float, 3> P::*m) -> Status {
            if (!v.is_array() || v.size() != 3) return Status(StatusCode::kInvalidArgument, "must be 3 numbers", field);
            double largest = 0;
            for (size_t i = 0; i < 3; ++i) {
              SOLIDTEX_ASSIGN_OR_RETURN(double x, json_number(v[i], field, double(d.lo), double(d.hi)));
              (p.*m)[i] = float(x);
              largest = std::max(largest, x);
            }
            // The triples are plane weights: not all zero, and none that float would make zero.
            if (!(largest >= 1e-6)) return Status(StatusCode::kInvalidArgument, "must not all be zero (one at least 1e-6)", field);
            return Status::ok();
          },
          [&](Scheme P::*m) { return read_name(v, field, &parse_scheme, p.*m); },
          [&](Matcher P::*m) { return read_name(v, field, &parse_matcher, p.*m); },
          [&](Init P::*m) { return read_name(v, field, &parse_init, p.*m); },
          [&](ColorRule P::*m) { return read_name(v, field, &parse_color_rule, p.*m); },
          [&](FinestMatch P::*m) { return read_name(v, field, &parse_finest_match, p.*m); },
          [&](FinestSources P::*m) { return read_name(v, field, &parse_finest_sources, p.*m); },
      },
      d.member);
}

// A float as the shortest decimal that reads back to it (0.7f as 0.7, not 0.699999988079071):
// what a client wrote comes back as written, and reading it back gives the same float.
json shortest(float f) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, f);
  *r.ptr = '\0';
  return json(std::strtod(buf, nullptr));
}

template <typename P, size_t N>
json write_params(const P& p, const Param<P> (&table)[N]) {
  json out = json::object();
  for (const Param<P>& d : table)
    out[d.key] = std::visit(Overloaded{
                                [&](Scheme P::*m) { return json(scheme_name(p.*m)); },
                                [&](Matcher P::*m) { return json(matcher_name(p.*m)); },
                                [&](Init P::*m) { return json(init_name(p.*m)); },
                                [&](ColorRule P::*m) { return json(color_rule_name(p.*m)); },
                                [&](FinestMatch P::*m) { return json(finest_match_name(p.*m)); },
                                [&](FinestSources P::*m) { return json(finest_sources_name(p.*m)); },
                                [&](std::optional<float> P::*m) { return p.*m ? shortest(*(p.*m)) : json("auto"); },
                                [&](float P::*m) { return shortest(p.*m); },
                                [&](std::array<float, 3> P::*m) {
                                  return json::array({shortest((p.*m)[0]), shortest((p.*m)[1]), shortest((p.*m)[2])});
                                },
                                [&](auto m) { return json(p.*m); },
                            },
                            d.member);
  return out;
}

// Strict decoding into `p` (which supplies what `j` leaves out): unknown keys, then each key
// in table order, then p.validate(); every error names its field as `where`.key.
template <typename P, size_t N>
Result<P> read_params(const json& j, const std::string& where, const Param<P> (&table)[N], P p) {
  auto path = [&](const std::string& key) { return where.empty() ? key : where + "." + key; };
  std::set<std::string> keys;
  for (const Param<P>& d : table) keys.insert(d.key);
  SOLIDTEX_RETURN_IF_ERROR(check_keys(j, keys, where));
  for (const Param<P>& d : table) {
    const auto it = j.find(d.key);
    if (it != j.end()) SOLIDTEX_RETURN_IF_ERROR(read_param(d, *it, path(d.key), p));
  }
  const Status st = p.validate();
  if (!st.is_ok()) return Status(st.code(), st.message(), st.field().empty() ? where : path(st.field()));
  return p;
}

}  // namespace

json to_json(const AnalysisParams& p) { return write_params(p, kAnalysisParams); }

Result<AnalysisParams> analysis_params_from_json(const json& j, const std::string& where) {
  return read_params(j, where, kAnalysisParams, AnalysisParams{});
}

json to_json(const SynthesisParams& p) { return write_params(p, kSynthesisParams); }

Result<SynthesisParams> synthesis_params_from_json(const json& j, const std::string& where, SynthesisParams base) {
  return read_params(j, where, kSynthesisParams, std::move(base));
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

size_t utf8_length(std::string_view s) {
  size_t n = 0;
  for (const char c : s)
    if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) ++n;  // count every byte that starts a character
  return n;
}

Result<std::string> json_text(const json& j, const std::string& where, size_t max_chars) {
  if (!j.is_string()) return Status(StatusCode::kInvalidArgument, "must be a string", where);
  std::string s = j.get<std::string>();
  if (utf8_length(s) > max_chars)
    return Status(StatusCode::kInvalidArgument, "is longer than " + std::to_string(max_chars) + " characters", where);
  return s;
}

namespace {
void integral_floats_to_integers(json& j) {
  if (j.is_number_float()) {
    const double d = j.get<double>();
    // Exactly representable as int64 (|d| < 2^63); larger integral floats stay floats.
    if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9.2e18) j = int64_t(d);
  } else if (j.is_array() || j.is_object()) {
    for (auto& v : j) integral_floats_to_integers(v);
  }
}
}  // namespace

Result<json> parse_request_json(const std::string& text, const std::string& where) {
  SOLIDTEX_ASSIGN_OR_RETURN(json j, parse_json_text(text, where));
  integral_floats_to_integers(j);
  return j;
}

std::string normalized_body(const std::string& text) {
  auto j = parse_request_json(text, "body");
  return j ? j->dump() : text;
}

json status_json(const Status& s) {
  if (s.is_ok()) return nullptr;
  return {{"code", status_code_name(s.code())}, {"message", s.message()}, {"field", s.field()}};
}

}  // namespace solidtex::server
