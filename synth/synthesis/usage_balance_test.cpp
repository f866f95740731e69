#include "synthesis/usage_balance.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <limits>

#include "analysis/analysis.h"
#include "synthesis/synthesizer.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

std::shared_ptr<const Table> small_table(ProceduralKind kind) {
  ExemplarInputs in;
  in.xy = testing::procedural(kind, 40, 40);
  AnalysisParams p;
  p.levels = 3;
  p.neighborhood = 7;
  p.candidates = 8;
  p.pca_dims = 12;
  return analyze(ExemplarSet::create(std::move(in)).value(), p).value().table;
}

UsageBalanceParams small_balance() {
  UsageBalanceParams b;
  b.rounds = 2;
  b.box = 16;
  return b;
}

std::vector<CoordinateTriple> finest_block(const std::shared_ptr<const Table>& table, float balance, Voxel at) {
  SynthesisParams p;
  p.balance = balance;
  return level_triples(table, p, PyramidLevel{table->levels() - 1}, at, 20).value();
}

// Calibration is a pure function of the table: the same penalties, bit for bit, whatever the
// thread count; they are non-negative and differ between pixels.
TEST(UsageBalance, PenaltiesAreDeterministicAndNonNegative) {
  auto table = small_table(ProceduralKind::kPebbles);
  auto a = balance_usage(table, small_balance());
  ASSERT_TRUE(a.is_ok()) << a.status().to_string();
  ASSERT_TRUE((*a)->has_usage());
  UsagePenalties b_usage;
  {
    tbb::task_arena one(1);
    one.execute([&] { b_usage = balance_usage(table, small_balance()).value()->usage(); });
  }
  EXPECT_EQ((*a)->usage(), b_usage);
  for (const auto& level : (*a)->usage())
    for (const auto& image : level) {
      const auto [lo, hi] = std::minmax_element(image.begin(), image.end());
      EXPECT_EQ(*lo, 0.f);
      EXPECT_GT(*hi, 0.f);
    }
  EXPECT_EQ(balance_usage(*a, small_balance()).status().code(), StatusCode::kInvalidArgument);  // only once
}

// The point of it: away from the calibration blocks, synthesis with the penalties names the
// exemplar's pixels more evenly than without them.
TEST(UsageBalance, SynthesisUsesTheExemplarMoreEvenly) {
  for (ProceduralKind kind : {ProceduralKind::kPebbles, ProceduralKind::kBricks}) {
    auto table = small_table(kind);
    auto balanced = balance_usage(table, small_balance()).value();
    const PyramidLevel finest{table->levels() - 1};
    const Voxel at{-300, 700, 50};
    const double before = usage_divergence(*table, finest, finest_block(table, 1.f, at), 2.f);
    const double after = usage_divergence(*balanced, finest, finest_block(balanced, 1.f, at), 2.f);
    EXPECT_LT(after, 0.9 * before) << int(kind) << ": " << before << " -> " << after;
  }
}

// balance = 0 ignores the penalties: the same bits as the table without them, so volumes that
// pinned balance 0 (made before balancing existed) keep their voxels.
TEST(UsageBalance, BalanceZeroIsTheUnbalancedSynthesis) {
  auto table = small_table(ProceduralKind::kBricks);
  auto balanced = balance_usage(table, small_balance()).value();
  const Voxel at{5, 6, 7};
  EXPECT_EQ(finest_block(balanced, 0.f, at), finest_block(table, 1.f, at));
  EXPECT_NE(finest_block(balanced, 1.f, at), finest_block(table, 1.f, at));
}

TEST(UsageBalance, FineGainScalesOnlyTheFinerLevelsOfIsotropicTables) {
  auto table = small_table(ProceduralKind::kNoise);
  ASSERT_TRUE(table->exemplars().shared());
  UsageBalanceParams one = small_balance(), two = small_balance();
  one.fine_gain = 1.f;
  two.fine_gain = 2.f;
  auto a = balance_usage(table, one).value(), b = balance_usage(table, two).value();
  const UsagePenalties pa = a->usage(), pb = b->usage();
  bool any_positive = false;
  for (int l = 0; l < table->levels(); ++l) {
    const float gain = table->spacing(PyramidLevel{l}) <= 2 ? 2.f : 1.f;
    for (size_t k = 0; k < pa[size_t(l)].size(); ++k)
      for (size_t i = 0; i < pa[size_t(l)][k].size(); ++i) {
        ASSERT_EQ(pb[size_t(l)][k][i], gain * pa[size_t(l)][k][i]) << "level " << l;
        any_positive = any_positive || (gain > 1.f && pa[size_t(l)][k][i] > 0.f);
      }
  }
  EXPECT_TRUE(any_positive);  // the finer levels have penalties to scale
  UsageBalanceParams edge = small_balance();
  for (float g : {0.25f, 4.f}) {
    edge.fine_gain = g;
    EXPECT_TRUE(edge.validate().is_ok()) << g;
  }
  for (float g : {0.2f, 5.f, std::numeric_limits<float>::quiet_NaN()}) {
    edge.fine_gain = g;
    EXPECT_EQ(edge.validate().field(), "fine_gain") << g;
  }
}

TEST(UsageBalance, ParametersAreValidatedAndCancellationIsClean) {
  UsageBalanceParams b;
  b.box = 4;
  EXPECT_EQ(b.validate().field(), "box");
  b = {};
  b.strength = -1.f;
  EXPECT_EQ(b.validate().field(), "strength");
  b = {};
  b.rounds = 9;
  EXPECT_EQ(b.validate().field(), "rounds");
  b = {};
  b.sigma = 0.f;
  EXPECT_EQ(b.validate().field(), "sigma");
  auto table = small_table(ProceduralKind::kNoise);
  b = {};
  b.rounds = 0;
  EXPECT_FALSE(balance_usage(table, b).value()->has_usage());
  struct Cancel : Interrupter {
    bool was_interrupted(int) override { return true; }
  } cancel;
  EXPECT_EQ(balance_usage(table, small_balance(), cancel).status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace solidtex
