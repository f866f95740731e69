// api_json: the parameter structs' JSON encodings. Pins the wire format, checks that every key
// reads back what it writes, that errors name the field by its path, and that the synthesis
// keys and ranges are those of the contract (proto/volume.schema.json).
#include "api_json.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>

namespace solidtex::server {
namespace {

using nlohmann::json;

Status synthesis_error(const json& j) { return synthesis_params_from_json(j, "params", SynthesisParams{}).status(); }
Status analysis_error(const json& j) { return analysis_params_from_json(j, "params").status(); }

std::set<std::string> keys_of(const json& j) {
  std::set<std::string> out;
  for (auto it = j.begin(); it != j.end(); ++it) out.insert(it.key());
  return out;
}

TEST(ApiJson, WireFormatOfTheDefaults) {
  // levels 0 is kAutoLevels; uploads store the count it resolves to (ExemplarService::upload).
  EXPECT_EQ(to_json(AnalysisParams{}).dump(),
            R"({"candidates":12,"knn_checks":192,"levels":0,"neighborhood":9,"pca_dims":20,"search_k":24,"seed":1,)"
            R"("suggested_plane_weights":[1.0,1.0,1.0]})");
  EXPECT_EQ(to_json(SynthesisParams{}).dump(),
            R"({"balance":1.0,"cell_size":12,"coarse_passes":3,"color":"auto","finest_match":"auto","finest_sources":"square","finest_subpass_size":1,"finest_typicality_scale":0.7,"init":"auto","init_band":8,"init_subpart":32,"matcher":"paper","passes":1,)"
            R"("plane_weights":[1.0,1.0,1.0],"scheme":"dual-grid","subpass_size":2,"trilinear_levels":2,"typicality":"auto"})");
}

TEST(ApiJson, EveryKeyReadsBackWhatItWrites) {
  AnalysisParams a;
  a.levels = 3;
  a.neighborhood = 5;
  a.candidates = 4;
  a.pca_dims = 8;
  a.search_k = 30;
  a.knn_checks = 500;
  a.seed = 77;
  a.suggested_plane_weights = {1.f, 0.5f, 0.25f};
  auto a2 = analysis_params_from_json(to_json(a), "params");
  ASSERT_TRUE(a2.is_ok()) << a2.status().to_string();
  EXPECT_EQ(*a2, a);

  SynthesisParams s;
  s.scheme = Scheme::kGrid;
  s.matcher = Matcher::kCoherent;
  s.coarse_passes = 1;
  s.passes = 3;
  s.subpass_size = 1;
  s.cell_size = 16;
  s.init = Init::kSlab;
  s.init_subpart = 64;
  s.init_band = 0;
  s.finest_match = FinestMatch::kTriple;
  s.finest_sources = FinestSources::kCross;
  s.trilinear_levels = 0;
  s.plane_weights = {0.5f, 1.f, 0.f};
  s.typicality = 1.25f;
  auto s2 = synthesis_params_from_json(to_json(s), "params", SynthesisParams{});
  ASSERT_TRUE(s2.is_ok()) << s2.status().to_string();
  EXPECT_EQ(to_json(*s2), to_json(s));
  EXPECT_EQ(s2->scheme, Scheme::kGrid);
  EXPECT_EQ(s2->plane_weights, s.plane_weights);
  EXPECT_EQ(s2->typicality, 1.25f);
  // floats are written as the shortest decimal that reads back to them: what a client wrote
  s.typicality = 0.35f;
  s.finest_typicality_scale = 0.3f;
  s.plane_weights = {0.1f, 1.f, 0.7f};
  EXPECT_EQ(to_json(s)["typicality"].dump(), "0.35");
  EXPECT_EQ(to_json(s)["finest_typicality_scale"].dump(), "0.3");
  EXPECT_EQ(to_json(s)["plane_weights"].dump(), "[0.1,1.0,0.7]");
  auto s4 = synthesis_params_from_json(to_json(s), "params", SynthesisParams{});
  ASSERT_TRUE(s4.is_ok()) << s4.status().to_string();
  EXPECT_EQ(s4->typicality, 0.35f);
  EXPECT_EQ(s4->finest_typicality_scale, 0.3f);
  EXPECT_EQ(s4->plane_weights, s.plane_weights);
  // "auto" reads as absent over any base, and writes back as "auto"
  SynthesisParams base;
  base.typicality = 0.5f;
  auto s3 = synthesis_params_from_json(json{{"typicality", "auto"}}, "params", base);
  ASSERT_TRUE(s3.is_ok()) << s3.status().to_string();
  EXPECT_FALSE(s3->typicality.has_value());
  EXPECT_EQ(to_json(*s3)["typicality"], "auto");
}

TEST(ApiJson, MissingKeysKeepTheBase) {
  SynthesisParams base;
  base.plane_weights = {1.f, 0.25f, 0.5f};
  base.passes = 5;
  base.seed = 9;  // not a JSON key: always the base's
  auto p = synthesis_params_from_json(json{{"cell_size", 16}}, "params", base);
  ASSERT_TRUE(p.is_ok()) << p.status().to_string();
  EXPECT_EQ(p->cell_size, 16);
  EXPECT_EQ(p->passes, 5);
  EXPECT_EQ(p->seed, 9u);
  EXPECT_EQ(p->plane_weights, base.plane_weights);
  auto a = analysis_params_from_json(json::object(), "params");
  ASSERT_TRUE(a.is_ok());
  EXPECT_EQ(*a, AnalysisParams{});
}

TEST(ApiJson, ErrorsNameTheField) {
  struct Case {
    json j;
    std::string field;
    std::string message;  // a part of it
  };
  const Case synthesis[] = {
      {json::array(), "params", "must be a JSON object"},
      {{{"shceme", "grid"}}, "params.shceme", "unknown key"},
      {{{"seed", 1}}, "params.seed", "unknown key"},
      {{{"scheme", "bogus"}}, "params.scheme", "unknown scheme 'bogus'"},
      {{{"scheme", 3}}, "params.scheme", "must be a string"},
      {{{"matcher", "best"}}, "params.matcher", "unknown matcher 'best'"},
      {{{"passes", 9}}, "params.passes", "must be in [0, 8]"},
      {{{"passes", 1.5}}, "params.passes", "must be an integer"},
      {{{"cell_size", "12"}}, "params.cell_size", "must be an integer"},
      {{{"plane_weights", {1, 1}}}, "params.plane_weights", "must be 3 numbers"},
      {{{"plane_weights", {1, 2, 1}}}, "params.plane_weights", "must be in [0.000000, 1.000000]"},
      {{{"plane_weights", {0, 0, 0}}}, "params.plane_weights", "must not all be zero"},  // validate()
      {{{"init_subpart", 9}}, "params.init_subpart", "must be even"},                    // validate()
      {{{"init_band", 4}}, "params.init_band", "must be 0 or in [8, 256]"},              // validate()
      {{{"init_band", 9}}, "params.init_band", "must be even"},                          // validate()
      {{{"init_band", 10.5}}, "params.init_band", "must be an integer"},
      {{{"init_band", 300}}, "params.init_band", "must be in [0, 256]"},
      {{{"init", "random"}}, "params.init", "unknown init 'random'"},
      {{{"color", "median"}}, "params.color", "unknown color 'median'"},
      {{{"finest_match", "triples"}}, "params.finest_match", "unknown finest_match 'triples'"},
      {{{"finest_match", 1}}, "params.finest_match", "must be a string"},
      {{{"finest_sources", "diagonal"}}, "params.finest_sources", "unknown finest_sources 'diagonal'"},
      {{{"finest_sources", true}}, "params.finest_sources", "must be a string"},
      {{{"typicality", 5}}, "params.typicality", "must be in [0.000000, 4.000000]"},
      {{{"typicality", "high"}}, "params.typicality", "must be a number or \"auto\""},
      {{{"typicality", "0.5"}}, "params.typicality", "must be a number or \"auto\""},
      {{{"typicality", nullptr}}, "params.typicality", "must be a number or \"auto\""},
      {{{"finest_typicality_scale", 1.5}}, "params.finest_typicality_scale", "must be in [0.000000, 1.000000]"},
      {{{"finest_typicality_scale", "auto"}}, "params.finest_typicality_scale", "must be a number"},
  };
  for (const Case& c : synthesis) {
    const Status st = synthesis_error(c.j);
    EXPECT_EQ(st.code(), StatusCode::kInvalidArgument) << c.j.dump();
    EXPECT_EQ(st.field(), c.field) << c.j.dump() << ": " << st.to_string();
    EXPECT_NE(st.message().find(c.message), std::string::npos) << c.j.dump() << ": " << st.to_string();
  }
  const Case analysis[] = {
      {json(7), "params", "must be a JSON object"},
      {{{"colour", 1}}, "params.colour", "unknown key"},
      {{{"levels", 9}}, "params.levels", "must be in [0, 8]"},  // 0 is kAutoLevels
      {{{"seed", -1}}, "params.seed", "must be in [0, 1073741824]"},
      {{{"knn_checks", true}}, "params.knn_checks", "must be an integer"},
      {{{"suggested_plane_weights", "1,1,1"}}, "params.suggested_plane_weights", "must be 3 numbers"},
      {{{"neighborhood", 4}}, "params.neighborhood", "must be odd"},  // validate(), prefixed like synthesis
      {{{"search_k", 3}}, "params.search_k", "must be in [7, 64]"},   // validate(): candidates/2+1
  };
  for (const Case& c : analysis) {
    const Status st = analysis_error(c.j);
    EXPECT_EQ(st.code(), StatusCode::kInvalidArgument) << c.j.dump();
    EXPECT_EQ(st.field(), c.field) << c.j.dump() << ": " << st.to_string();
    EXPECT_NE(st.message().find(c.message), std::string::npos) << c.j.dump() << ": " << st.to_string();
  }
}

TEST(ApiJson, RenamedSchemeSaysWhatItBecame) {
  const Status st = synthesis_error({{"scheme", "standard"}});
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(st.field(), "params.scheme");
  EXPECT_EQ(st.message(), parse_scheme("standard").status().message());
  EXPECT_NE(st.message().find("'plain'"), std::string::npos) << st.message();
}

// The contract's synthesisParams: the same keys, integer ranges, enum values and defaults.
TEST(ApiJson, SynthesisParamsMatchTheVolumeSchema) {
  std::ifstream in(std::string(SOLIDTEX_SOURCE_DIR) + "/proto/volume.schema.json");
  ASSERT_TRUE(in) << "proto/volume.schema.json";
  std::stringstream text;
  text << in.rdbuf();
  const json props = json::parse(text.str())["$defs"]["synthesisParams"]["properties"];
  const json defaults = to_json(SynthesisParams{});
  EXPECT_EQ(keys_of(props), keys_of(defaults));
  // A property's type, or each alternative of a oneOf (a number or "auto"), is tested alike.
  std::function<void(const std::string&, const json&)> check = [&](const std::string& key, const json& prop) {
    if (prop.contains("oneOf")) {
      for (const json& alternative : prop["oneOf"]) check(key, alternative);
    } else if (prop["type"] == "integer") {
      const int64_t lo = prop["minimum"], hi = prop["maximum"];
      EXPECT_TRUE(synthesis_error({{key, lo}}).is_ok()) << key << " = " << lo;
      EXPECT_TRUE(synthesis_error({{key, hi}}).is_ok()) << key << " = " << hi;
      EXPECT_EQ(synthesis_error({{key, lo - 1}}).field(), "params." + key);
      EXPECT_EQ(synthesis_error({{key, hi + 1}}).field(), "params." + key);
    } else if (prop.contains("enum")) {
      for (const json& v : prop["enum"]) {
        auto p = synthesis_params_from_json({{key, v}}, "params", SynthesisParams{});
        ASSERT_TRUE(p.is_ok()) << key << " = " << v << ": " << p.status().to_string();
        EXPECT_EQ(to_json(*p)[key], v);
      }
    } else if (prop["type"] == "array") {
      const double lo = prop["items"]["minimum"], hi = prop["items"]["maximum"];
      EXPECT_TRUE(synthesis_error({{key, {lo, hi, hi}}}).is_ok()) << key;
      EXPECT_EQ(synthesis_error({{key, {lo, hi + 0.5, hi}}}).field(), "params." + key);
      EXPECT_EQ(synthesis_error({{key, {lo - 0.5, hi, hi}}}).field(), "params." + key);
    } else if (prop["type"] == "number") {
      const double lo = prop["minimum"], hi = prop["maximum"];
      EXPECT_TRUE(synthesis_error({{key, lo}}).is_ok()) << key << " = " << lo;
      EXPECT_TRUE(synthesis_error({{key, hi}}).is_ok()) << key << " = " << hi;
      EXPECT_EQ(synthesis_error({{key, lo - 0.5}}).field(), "params." + key);
      EXPECT_EQ(synthesis_error({{key, hi + 0.5}}).field(), "params." + key);
    } else {
      ADD_FAILURE() << "untested schema property " << key;
    }
  };
  for (auto it = props.begin(); it != props.end(); ++it) {
    if (it.value().contains("default")) {
      EXPECT_EQ(it.value()["default"], defaults[it.key()]) << it.key();
    }
    check(it.key(), it.value());
  }
}

}  // namespace
}  // namespace solidtex::server
