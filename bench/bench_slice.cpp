// Benchmark: lazy synthesis of cuts. Prints one JSON object.
//   bench_slice TABLE.stx [--quick]
// 1. dependency-set sizes (voxels, corrections per level) of a 512x512 axis cut and a
//    512x512 oblique cut, nearest and cubic, under plain, subpass and dual-grid correction
//    (sets only);
// 2. full synthesis of a 128x128 cut: corrections per second, paper and coherent matchers;
// 3. per field (identity, a rotated constant field, a sketched ring): a cold 256x256 cut, the
//    adjacent cut, the same cut again, the cut two over; the identity cold cut on 1 thread too.
#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include <chrono>
#include <cstring>
#include <iostream>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <cmath>

#include "field/tensor_field.h"
#include "synthesis/synthesizer.h"
#include "analysis/table_file.h"

using namespace solidtex;

namespace {

nlohmann::json level_json(const SynthesisStats& s) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& l : s.levels)
    a.push_back({{"level", l.level},
                 {"voxels", l.voxels},
                 {"corrections", l.corrections},
                 {"cache_hits", l.cache_hits},
                 {"needed_final", l.needed_final},
                 {"seconds", l.seconds}});
  return a;
}

std::shared_ptr<Synthesizer> make(std::shared_ptr<const Table> table, Scheme scheme, Matcher matcher, int64_t cache,
                                  std::shared_ptr<const FrameField> field = parse_field_spec("identity").value()) {
  SynthesisParams p;
  p.scheme = scheme;
  p.matcher = matcher;
  p.plane_weights = table->params().suggested_plane_weights;
  return Synthesizer::create(table, std::move(field), p, cache).value();
}

// A sketched field: one circular curve of radius side/3 about the cut's centre in the plane
// z = 0, the grain (axis x) following it, solved on a 24-cell grid around the cut.
std::shared_ptr<const FrameField> ring_field(int side) {
  Sketch sk;
  sk.domain = {{-8, -8, -32}, {double(side) + 8, double(side) + 8, 32}, 24};
  SketchCurve cv;
  const double c = side / 2.0, r = side / 3.0;
  for (int i = 0; i <= 24; ++i) {
    const double a = 2 * M_PI * i / 24;
    cv.points.push_back({c + r * std::cos(a), c + r * std::sin(a), 0});
  }
  cv.plane_normal = WorldPoint{0, 0, 1};
  cv.axis = 0;
  sk.curves.push_back(cv);
  return FieldSolver::solve(sk).value()->field().value();
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
  // The same plane resampled (resample cubic, what auto picks for exemplars without 1-pixel
  // detail): it reads the 4x4x4 voxels around each pixel, a slab about 5 voxels thick.
  cuts.push_back({"oblique_cubic",
                  TargetSet::plane_cut({0, 0, 0}, {0.6, 0.8, 0}, {-0.48, 0.36, 0.8}, big, big, VoxelSampling::kCubic).value()});
  nlohmann::json sets = nlohmann::json::array();
  for (const Cut& c : cuts) {
    int64_t subpass_voxels = 0;
    std::vector<LevelStats> subpass_levels;
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
      if (scheme == Scheme::kSubpass) {
        subpass_voxels = st.voxels;
        subpass_levels = st.levels;
      }
      nlohmann::json j = {{"cut", c.name},
                          {"size", big},
                          {"scheme", scheme_name(scheme)},
                          {"voxels", st.voxels},
                          {"corrections", st.corrections},
                          {"analysis_seconds", st.dependency_seconds},
                          {"levels", level_json(st)}};
      if (scheme == Scheme::kDualGrid && subpass_voxels > 0) {
        j["voxels_vs_subpass"] = double(st.voxels) / double(subpass_voxels);
        // Zhang reports this per level, the finest apart (its sets are the ones that grow).
        nlohmann::json per_level = nlohmann::json::array();
        for (size_t l = 0; l < st.levels.size() && l < subpass_levels.size(); ++l)
          per_level.push_back(subpass_levels[l].voxels > 0 ? double(st.levels[l].voxels) / double(subpass_levels[l].voxels) : 0.0);
        j["voxels_vs_subpass_per_level"] = per_level;
      }
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

  // 3. New cuts as a user meets them, per field: a cold cut on a fresh synthesizer, the cut
  //    next to it (at z + 1: coarse levels and most fine dependencies cached), the same cut
  //    again (all from the cache), then the cut at z + 2 (the subpass parity the first cut's
  //    corrections left final in the cache); the identity field's cold cut also on one thread.
  {
    const int side = quick ? 96 : 256;
    nlohmann::json cuts_out = nlohmann::json::array();
    struct FieldCase {
      const char* name;
      std::shared_ptr<const FrameField> field;
    };
    std::vector<FieldCase> fields = {{"identity", parse_field_spec("identity").value()},
                                     {"rotated", parse_field_spec("axis:1,2,3,35").value()},
                                     {"ring", ring_field(side)}};
    for (const FieldCase& f : fields)
      for (int threads : {0, 1}) {
        if (threads == 1 && std::string(f.name) != "identity") continue;
        std::unique_ptr<tbb::global_control> limit;
        if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
        auto s = make(*table, Scheme::kDualGrid, Matcher::kPaper, int64_t(4) << 30, f.field);
        SynthesisStats cold, next, again, second;
        for (auto [at, st] : {std::pair{0, &cold}, std::pair{1, &next}, std::pair{1, &again}, std::pair{2, &second}}) {
          auto r = s->synthesize(TargetSet::axis_cut('z', at, 0, 0, side, side).value(), null_interrupter(), st);
          if (!r) {
            std::cerr << r.status().to_string() << "\n";
            return 1;
          }
        }
        const auto c = s->cache().counters();
        int64_t cached_voxels = 0;
        for (int64_t n : c.voxels_per_level) cached_voxels += n;
        cuts_out.push_back({{"field", f.name},
                            {"threads", threads > 0 ? threads : tbb::this_task_arena::max_concurrency()},
                            {"size", side},
                            {"cold_cut_seconds", cold.seconds},
                            {"cold_cut_dependency_seconds", cold.dependency_seconds},
                            {"cold_cut_corrections", cold.corrections},
                            {"cold_cut_corrections_per_second", double(cold.corrections) / cold.seconds},
                            {"cold_cut_levels", level_json(cold)},
                            {"next_cut_seconds", next.seconds},
                            {"next_cut_levels", level_json(next)},
                            {"same_cut_again_seconds", again.seconds},
                            {"cut_at_plus_2_seconds", second.seconds},
                            {"cut_at_plus_2_levels", level_json(second)},
                            {"cache_bytes", c.bytes},
                            {"cache_bricks", c.bricks},
                            {"cache_voxels", cached_voxels},
                            {"cache_bytes_per_voxel", cached_voxels > 0 ? double(c.bytes) / double(cached_voxels) : 0.0}});
        std::cerr << f.name << " threads " << threads << ": cold " << cold.seconds << " s, next " << next.seconds
                  << " s, again " << again.seconds << " s\n";
      }
    out["cuts"] = cuts_out;
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  out["peak_rss_mb"] = double(ru.ru_maxrss) / 1024.0;
  std::cout << out.dump() << "\n";
  return 0;
}
