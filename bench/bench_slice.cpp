// Benchmark: lazy synthesis of cuts. Prints one JSON object.
//   bench_slice TABLE.stx [--quick]
// 1. dependency-set sizes (voxels, corrections per level) of a 512x512 axis cut and a
//    512x512 oblique cut under plain, subpass and dual-grid correction (sets only);
// 2. full synthesis of a 128x128 cut: corrections per second, paper and coherent matchers;
// 3. a new 256x256 cut once another cut has warmed the cache (coarse levels cached), then the
//    same cut again entirely from the cache.
#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include <chrono>
#include <cstring>
#include <iostream>

#include "synthesis/synthesizer.h"
#include "analysis/table_file.h"

using namespace solidtex;

namespace {

nlohmann::json level_json(const SynthesisStats& s) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& l : s.levels)
    a.push_back({{"level", l.level}, {"voxels", l.voxels}, {"corrections", l.corrections}, {"cache_hits", l.cache_hits}});
  return a;
}

std::shared_ptr<Synthesizer> make(std::shared_ptr<const Table> table, Scheme scheme, Matcher matcher, int64_t cache) {
  SynthesisParams p;
  p.scheme = scheme;
  p.matcher = matcher;
  p.plane_weights = table->params().suggested_plane_weights;
  return Synthesizer::create(table, parse_field_spec("identity").value(), p, cache).value();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: bench_slice TABLE.stx [--quick]\n";
    return 2;
  }
  const bool quick = argc > 2 && std::strcmp(argv[2], "--quick") == 0;
  auto table = load_table(argv[1]);
  if (!table) {
    std::cerr << table.status().to_string() << "\n";
    return 1;
  }
  nlohmann::json out;
  out["benchmark"] = "slice";
  out["table"] = argv[1];
  out["levels"] = (*table)->levels();
  out["neighborhood"] = (*table)->params().neighborhood;

  // 1. Dependency sets.
  const int big = quick ? 128 : 512;
  struct Cut {
    const char* name;
    TargetSet target;
  };
  std::vector<Cut> cuts;
  cuts.push_back({"axis_z", TargetSet::axis_cut('z', 0, 0, 0, big, big).value()});
  cuts.push_back({"oblique", TargetSet::plane_cut({0, 0, 0}, {0.6, 0.8, 0}, {-0.48, 0.36, 0.8}, big, big).value()});
  nlohmann::json sets = nlohmann::json::array();
  for (const Cut& c : cuts) {
    int64_t subpass_voxels = 0;
    for (Scheme scheme : {Scheme::kPlain, Scheme::kSubpass, Scheme::kDualGrid}) {
      auto s = make(*table, scheme, Matcher::kPaper, 0);
      SynthesisStats st;
      SynthesisOptions o;
      o.dependencies_only = true;
      o.use_cache = false;
      auto r = s->synthesize(c.target, null_interrupter(), &st, o);
      if (!r) {
        std::cerr << r.status().to_string() << "\n";
        return 1;
      }
      if (scheme == Scheme::kSubpass) subpass_voxels = st.voxels;
      nlohmann::json j = {{"cut", c.name},
                          {"size", big},
                          {"scheme", scheme_name(scheme)},
                          {"voxels", st.voxels},
                          {"corrections", st.corrections},
                          {"analysis_seconds", st.dependency_seconds},
                          {"levels", level_json(st)}};
      if (scheme == Scheme::kDualGrid && subpass_voxels > 0)
        j["voxels_vs_subpass"] = double(st.voxels) / double(subpass_voxels);
      sets.push_back(j);
    }
  }
  out["dependency_sets"] = sets;

  // 2. Throughput.
  nlohmann::json tp = nlohmann::json::array();
  for (Matcher m : {Matcher::kPaper, Matcher::kCoherent}) {
    auto s = make(*table, Scheme::kDualGrid, m, 0);
    SynthesisStats st;
    auto r = s->synthesize(TargetSet::axis_cut('z', 0, 0, 0, 128, 128).value(), null_interrupter(), &st);
    if (!r) return 1;
    const double synth_seconds = st.seconds - st.dependency_seconds;
    tp.push_back({{"matcher", matcher_name(m)},
                  {"cut", "axis_z 128x128"},
                  {"corrections", st.corrections},
                  {"seconds", st.seconds},
                  {"dependency_seconds", st.dependency_seconds},
                  {"corrections_per_second", double(st.corrections) / st.seconds},
                  {"corrections_per_second_excluding_dependency_analysis", double(st.corrections) / synth_seconds}});
  }
  out["throughput"] = tp;

  // 3. New cut with coarse levels cached, then the same cut from cache.
  {
    const int side = quick ? 96 : 256;
    auto s = make(*table, Scheme::kDualGrid, Matcher::kPaper, int64_t(4) << 30);
    SynthesisStats warm, fresh, again;
    s->synthesize(TargetSet::axis_cut('z', 0, 0, 0, side, side).value(), null_interrupter(), &warm);
    s->synthesize(TargetSet::axis_cut('z', 24, 0, 0, side, side).value(), null_interrupter(), &fresh);
    s->synthesize(TargetSet::axis_cut('z', 24, 0, 0, side, side).value(), null_interrupter(), &again);
    const auto c = s->cache().counters();
    out["cached"] = {{"size", side},
                     {"first_cut_seconds", warm.seconds},
                     {"new_cut_seconds", fresh.seconds},
                     {"new_cut_levels", level_json(fresh)},
                     {"same_cut_again_seconds", again.seconds},
                     {"cache_bytes", c.bytes},
                     {"cache_bricks", c.bricks}};
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  out["peak_rss_mb"] = double(ru.ru_maxrss) / 1024.0;
  std::cout << out.dump() << "\n";
  return 0;
}
