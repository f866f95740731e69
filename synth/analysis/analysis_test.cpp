#include "analysis/analysis.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "core/image_io.h"
#include "analysis/table_file.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

AnalysisParams fast_params() {
  AnalysisParams p;
  p.levels = 3;
  p.neighborhood = 7;
  p.candidates = 8;
  p.pca_dims = 12;
  return p;
}

std::vector<uint8_t> analyse_with_threads(const ExemplarSet& set, const AnalysisParams& p, int threads) {
  tbb::task_arena arena(threads);
  std::vector<uint8_t> bytes;
  arena.execute([&] { bytes = encode_table(*analyze(set, p).value().table); });
  return bytes;
}

TEST(Analysis, TableBytesAreIdenticalAcrossRunsAndThreadCounts) {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kWood, 48, 40);
  auto set = ExemplarSet::create(std::move(in)).value();
  const auto one = analyse_with_threads(set, fast_params(), 1);
  const auto two = analyse_with_threads(set, fast_params(), 2);
  const auto again = analyse_with_threads(set, fast_params(), 2);
  EXPECT_EQ(one, two);
  EXPECT_EQ(two, again);
}

TEST(Analysis, InvalidParametersNameTheField) {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kWood, 16, 16);
  auto set = ExemplarSet::create(std::move(in)).value();
  AnalysisParams p;
  p.neighborhood = 8;
  auto r = analyze(set, p);
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(r.status().field(), "neighborhood");
  p = AnalysisParams{};
  p.levels = 9;
  EXPECT_EQ(analyze(set, p).status().field(), "levels");
  p.levels = -1;
  EXPECT_EQ(analyze(set, p).status().field(), "levels");
}

// The coarsest template, N * 2^(L-1) pixels wide, spans at most half the shorter side.
TEST(Analysis, AutoLevelsFollowTheExemplarsShorterSide) {
  EXPECT_EQ(auto_levels(62, 9), 2);    // leopard
  EXPECT_EQ(auto_levels(82, 9), 3);    // tree_bark (82 x 90)
  EXPECT_EQ(auto_levels(96, 9), 3);    // bricks, weave_burlap, wood_grain
  EXPECT_EQ(auto_levels(128, 9), 3);   // marble_pink
  EXPECT_EQ(auto_levels(143, 9), 3);   // 72 > 71.5
  EXPECT_EQ(auto_levels(144, 9), 4);   // 72 <= 72
  EXPECT_EQ(auto_levels(256, 9), 4);   // pebbles, wood_planks: what the old fixed default gave
  EXPECT_EQ(auto_levels(512, 9), 5);   // gravel
  EXPECT_EQ(auto_levels(256, 5), 5);
  EXPECT_EQ(auto_levels(16, 9), 1);    // too small for a second level
  EXPECT_EQ(auto_levels(1 << 30, 15), 8);
  for (int side = 8; side <= 4096; ++side)
    for (int n = 3; n <= 15; n += 2) {
      const int l = auto_levels(side, n);
      ASSERT_GE(l, 1);
      ASSERT_LE(l, 8);
      if (l > 1) ASSERT_LE(2 * n << (l - 1), side) << side << " " << n;
      if (l < 8) ASSERT_GT(2 * n << l, side) << side << " " << n;
    }
}

TEST(Analysis, AutoLevelsAreResolvedFromTheSmallestPlaneAndStored) {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kNoise, 64, 40);
  in.yz = testing::procedural(ProceduralKind::kNoise, 64, 64);
  in.zx = testing::procedural(ProceduralKind::kNoise, 36, 64);
  auto set = ExemplarSet::create(std::move(in)).value();
  AnalysisParams p = fast_params();
  p.levels = kAutoLevels;
  EXPECT_EQ(resolve_levels(p, set).levels, auto_levels(36, 7));
  EXPECT_EQ(auto_levels(36, 7), 2);
  p.levels = 3;
  EXPECT_EQ(resolve_levels(p, set).levels, 3);  // explicit counts are kept
  p.levels = kAutoLevels;
  const auto table = analyze(set, p).value().table;
  EXPECT_EQ(table->levels(), 2);
  EXPECT_EQ(table->params().levels, 2);
  p.levels = 2;  // auto is exactly that count: the same table, bit for bit
  EXPECT_EQ(encode_table(*table), encode_table(*analyze(set, p).value().table));
  AnalysisParams automatic = p;
  automatic.levels = kAutoLevels;
  EXPECT_EQ(estimate_analysis_bytes(set, automatic), estimate_analysis_bytes(set, p));
  p.levels = 3;
  EXPECT_GT(estimate_analysis_bytes(set, p), estimate_analysis_bytes(set, automatic));
}

TEST(Analysis, ExemplarSetValidation) {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kWood, 16, 16);
  in.yz = testing::procedural(ProceduralKind::kWood, 16, 16);
  EXPECT_EQ(ExemplarSet::create(in).status().field(), "zx");
  ExemplarInputs tiny;
  tiny.xy = ImageF(4, 4, 3);
  EXPECT_EQ(ExemplarSet::create(tiny).status().field(), "xy");
  ExemplarInputs badmask;
  badmask.xy = testing::procedural(ProceduralKind::kWood, 16, 16);
  badmask.mask_xy = ImageF(8, 8, 3);
  EXPECT_EQ(ExemplarSet::create(badmask).status().field(), "mask");
}

class CountingInterrupter : public Interrupter {
 public:
  bool was_interrupted(int percent) override {
    if (percent > max_percent) max_percent = percent;
    return percent >= stop_at;
  }
  int max_percent = -1;
  int stop_at = 1000;
};

TEST(Analysis, ReportsProgressAndHonoursCancellation) {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kNoise, 32, 32);
  auto set = ExemplarSet::create(std::move(in)).value();
  CountingInterrupter progress;
  ASSERT_TRUE(analyze(set, fast_params(), progress).is_ok());
  EXPECT_EQ(progress.max_percent, 100);
  CountingInterrupter stop;
  stop.stop_at = 30;
  EXPECT_EQ(analyze(set, fast_params(), stop).status().code(), StatusCode::kCancelled);
}

// The real exemplars: stored candidates must beat random triples by a wide margin.
TEST(Analysis, RealExemplarsCandidatesBeatRandomTriples) {
  const char* names[] = {"wood_grain.png", "bricks.png", "tree_bark.png", "stripes_dunes.png", "leopard.png"};
  if (testing::exemplar_path("wood_grain.png").empty())
    GTEST_SKIP() << "../shared/data/exemplars is absent: real-exemplar test skipped";
  for (const char* name : names) {
    SCOPED_TRACE(name);
    ExemplarInputs in;
    in.xy = load_image(testing::exemplar_path(name)).value();
    auto set = ExemplarSet::create(std::move(in)).value();
    AnalysisParams p;  // defaults: 4 levels, N = 9, N_T = 12
    auto r = analyze(set, p);
    ASSERT_TRUE(r.is_ok()) << r.status().to_string();
    for (const LevelReport& lr : r->levels) {
      EXPECT_LT(lr.mean_crossbar_error, 0.5 * lr.random_crossbar_error)
          << "level " << lr.level << ": " << lr.mean_crossbar_error << " vs random " << lr.random_crossbar_error;
    }
  }
}

}  // namespace
}  // namespace solidtex
