#include "synthesis/synthesis_params.h"

namespace solidtex {

Result<Scheme> parse_scheme(const std::string& name) {
  if (name == "plain") return Scheme::kPlain;
  if (name == "standard")  // renamed: the paper's standard scheme is the one with subpasses
    return Status(StatusCode::kInvalidArgument,
                  "scheme 'standard' was renamed 'plain' (plain passes without subpasses); the paper's "
                  "standard scheme is 'subpass'",
                  "scheme");
  if (name == "subpass") return Scheme::kSubpass;
  if (name == "grid") return Scheme::kGrid;
  if (name == "dual-grid") return Scheme::kDualGrid;
  return Status(StatusCode::kInvalidArgument, "unknown scheme '" + name + "' (plain, subpass, grid, dual-grid)", "scheme");
}

Result<Init> parse_init(const std::string& name) {
  if (name == "auto") return Init::kAuto;
  if (name == "slab") return Init::kSlab;
  if (name == "scatter") return Init::kScatter;
  return Status(StatusCode::kInvalidArgument, "unknown init '" + name + "' (auto, scatter, slab)", "init");
}

const char* init_name(Init i) { return i == Init::kAuto ? "auto" : i == Init::kSlab ? "slab" : "scatter"; }

Result<ColorRule> parse_color_rule(const std::string& name) {
  if (name == "mean") return ColorRule::kMean;
  if (name == "medoid") return ColorRule::kMedoid;
  if (name == "vote") return ColorRule::kVote;
  if (name == "auto") return ColorRule::kAuto;
  return Status(StatusCode::kInvalidArgument, "unknown color '" + name + "' (auto, vote, medoid, mean)", "color");
}

const char* color_rule_name(ColorRule c) {
  switch (c) {
    case ColorRule::kMean: return "mean";
    case ColorRule::kVote: return "vote";
    case ColorRule::kAuto: return "auto";
    default: return "medoid";
  }
}

Result<FinestMatch> parse_finest_match(const std::string& name) {
  if (name == "auto") return FinestMatch::kAuto;
  if (name == "triple") return FinestMatch::kTriple;
  if (name == "plane") return FinestMatch::kPlane;
  return Status(StatusCode::kInvalidArgument, "unknown finest_match '" + name + "' (auto, triple, plane)", "finest_match");
}

const char* finest_match_name(FinestMatch m) {
  return m == FinestMatch::kAuto ? "auto" : m == FinestMatch::kTriple ? "triple" : "plane";
}

Result<FinestSources> parse_finest_sources(const std::string& name) {
  if (name == "square") return FinestSources::kSquare;
  if (name == "cross") return FinestSources::kCross;
  return Status(StatusCode::kInvalidArgument, "unknown finest_sources '" + name + "' (cross, square)", "finest_sources");
}

const char* finest_sources_name(FinestSources s) { return s == FinestSources::kSquare ? "square" : "cross"; }

Result<Matcher> parse_matcher(const std::string& name) {
  if (name == "paper") return Matcher::kPaper;
  if (name == "coherent") return Matcher::kCoherent;
  return Status(StatusCode::kInvalidArgument, "unknown matcher '" + name + "' (paper, coherent)", "matcher");
}

const char* matcher_name(Matcher m) { return m == Matcher::kPaper ? "paper" : "coherent"; }

const char* scheme_name(Scheme s) {
  switch (s) {
    case Scheme::kPlain: return "plain";
    case Scheme::kSubpass: return "subpass";
    case Scheme::kGrid: return "grid";
    case Scheme::kDualGrid: return "dual-grid";
  }
  return "?";
}

Status SynthesisParams::validate() const {
  auto range = [](int v, int lo, int hi, const char* f) {
    return v < lo || v > hi ? Status(StatusCode::kInvalidArgument,
                                     "is " + std::to_string(v) + "; must be in [" + std::to_string(lo) + ", " +
                                         std::to_string(hi) + "]",
                                     f)
                            : Status::ok();
  };
  SOLIDTEX_RETURN_IF_ERROR(range(coarse_passes, 0, 8, "coarse_passes"));
  SOLIDTEX_RETURN_IF_ERROR(range(passes, 0, 8, "passes"));
  SOLIDTEX_RETURN_IF_ERROR(range(subpass_size, 1, 2, "subpass_size"));
  SOLIDTEX_RETURN_IF_ERROR(range(finest_subpass_size, 1, 2, "finest_subpass_size"));
  SOLIDTEX_RETURN_IF_ERROR(range(cell_size, 4, 64, "cell_size"));
  SOLIDTEX_RETURN_IF_ERROR(range(init_subpart, 8, 256, "init_subpart"));
  if (init_subpart % 2) return Status(StatusCode::kInvalidArgument, "must be even", "init_subpart");
  if (init_band != 0 && (init_band < 8 || init_band > 256))
    return Status(StatusCode::kInvalidArgument, "is " + std::to_string(init_band) + "; must be 0 or in [8, 256]", "init_band");
  if (init_band % 2) return Status(StatusCode::kInvalidArgument, "must be even", "init_band");
  SOLIDTEX_RETURN_IF_ERROR(range(trilinear_levels, 0, 8, "trilinear_levels"));
  float total = 0.f;
  for (float w : plane_weights) {
    if (!(w >= 0.f && w <= 1.f)) return Status(StatusCode::kInvalidArgument, "each must be in [0, 1]", "plane_weights");
    total += w;
  }
  if (!(total > 0.f)) return Status(StatusCode::kInvalidArgument, "must not all be zero", "plane_weights");
  if (typicality && !(*typicality >= 0.f && *typicality <= 4.f))
    return Status(StatusCode::kInvalidArgument, "must be in [0, 4]", "typicality");
  if (!(finest_typicality_scale >= 0.f && finest_typicality_scale <= 1.f))
    return Status(StatusCode::kInvalidArgument, "must be in [0, 1]", "finest_typicality_scale");
  if (!(balance >= 0.f && balance <= 4.f)) return Status(StatusCode::kInvalidArgument, "must be in [0, 4]", "balance");
  return Status::ok();
}

}  // namespace solidtex
