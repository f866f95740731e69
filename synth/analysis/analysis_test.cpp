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
  p.levels = 0;
  EXPECT_EQ(analyze(set, p).status().field(), "levels");
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
