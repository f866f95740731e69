#include "synthesis/history_window.h"

#include <gtest/gtest.h>

namespace solidtex {
namespace {

TEST(HistoryWindow, LatestReadsThePreviousVersionEverywhere) {
  const auto w = HistoryWindow::latest(5).materialize({3, 4, 5}, 13);
  ASSERT_EQ(w.size(), 13u * 13u * 13u);
  for (int v : w) EXPECT_EQ(v, 4);
}

TEST(HistoryWindow, GridBarrierReadsBarrierVersionOutsideTheCell) {
  const CellLattice cells{12, 0};
  const auto w = HistoryWindow::grid(7, cells, 0);
  const Voxel p{11, 0, 5};  // on the +x face of cell [0, 12)
  EXPECT_EQ(w.version(p, 0, 0, 0), 6);
  EXPECT_EQ(w.version(p, -5, 3, 2), 6);
  EXPECT_EQ(w.version(p, 1, 0, 0), 0);   // crosses into the next cell
  EXPECT_EQ(w.version(p, 0, -1, 0), 0);  // y = -1 is in another cell
  const CellLattice dual{12, 6};
  const auto d = HistoryWindow::grid(7, dual, 3);
  EXPECT_EQ(d.version(p, 1, 5, 0), 6);   // dual cells: x [6, 18), y and z [-6, 6)
  EXPECT_EQ(d.version({11, 6, 5}, 1, -1, 0), 3);
}

TEST(HistoryWindow, IntersectionIsTheElementwiseMinimum) {
  const auto a = HistoryWindow::grid(9, {8, 0}, 2);
  const auto b = HistoryWindow::grid(9, {8, 4}, 5);
  const auto c = a.intersect(b);
  const Voxel p{6, 1, 3};
  const auto wa = a.materialize(p, 13), wb = b.materialize(p, 13), wc = c.materialize(p, 13);
  bool saw_each = false;
  for (size_t i = 0; i < wc.size(); ++i) {
    EXPECT_EQ(wc[i], std::min(wa[i], wb[i]));
    saw_each |= wa[i] != wb[i];
  }
  EXPECT_TRUE(saw_each);
}

TEST(LevelSchedule, DualGridStepsSlotsAndBarriers) {
  SynthesisParams p;  // dual-grid, 8 subpasses
  p.passes = 2;       // one grid pass, one dual pass
  const LevelSchedule fine = LevelSchedule::make(1, 4, p);
  ASSERT_EQ(fine.final_version(), 16);
  EXPECT_EQ(fine.slot_count(), 3);
  // Class 0 updates at versions 1 and 9; class 7 at 8 and 16.
  EXPECT_EQ(fine.slot({0, 0, 0}, 0), 0);
  EXPECT_EQ(fine.slot({0, 0, 0}, 1), 1);
  EXPECT_EQ(fine.slot({0, 0, 0}, 8), 1);
  EXPECT_EQ(fine.slot({0, 0, 0}, 9), 2);
  EXPECT_EQ(fine.slot({1, 1, 1}, 7), 0);
  EXPECT_EQ(fine.slot({1, 1, 1}, 8), 1);
  EXPECT_EQ(fine.slot({1, 1, 1}, 16), 2);
  // Primary pass: barrier 0 across cells; dual pass: barrier = end of the grid pass (8).
  const Voxel edge{11, 11, 11};
  EXPECT_EQ(fine.steps()[3].window.version(edge, 1, 0, 0), 0);
  EXPECT_EQ(fine.steps()[12].window.version(edge, 1, 0, 0), 12);   // same dual cell [6, 18)
  EXPECT_EQ(fine.steps()[12].window.version({17, 6, 6}, 1, 0, 0), 8);
  const LevelSchedule coarse = LevelSchedule::make(0, 4, p);
  EXPECT_EQ(coarse.final_version(), 3);
  for (const auto& s : coarse.steps()) EXPECT_FALSE(s.window.has_barrier());
  p.scheme = Scheme::kPlain;
  EXPECT_EQ(LevelSchedule::make(2, 4, p).final_version(), 2);
  // The default single fine pass is the grid pass alone: 8 steps, barrier 0, no dual cells.
  const LevelSchedule one = LevelSchedule::make(1, 4, SynthesisParams{});
  ASSERT_EQ(one.final_version(), 8);
  EXPECT_EQ(one.slot_count(), 2);
  EXPECT_EQ(one.steps()[7].window.version(edge, 1, 0, 0), 0);
  EXPECT_EQ(one.steps()[7].window.version(edge, -1, 0, 0), 7);
}

// The finest level runs finest_subpass_size: by default one step per pass updating every voxel
// from version 0 (a cut's finest voxels need no chain of earlier subpasses); with 2, the
// other levels' 8 subpasses. A one-level pyramid's only level is the coarsest: plain.
TEST(LevelSchedule, TheFinestLevelTakesItsOwnSubpassSize) {
  SynthesisParams p;
  const LevelSchedule finest = LevelSchedule::make(3, 4, p);
  ASSERT_EQ(finest.final_version(), 1);
  EXPECT_EQ(finest.subpass_size(), 1);
  EXPECT_TRUE(finest.steps()[0].updates.contains({1, 0, 1}));
  for (int dx : {-4, 0, 4}) EXPECT_EQ(finest.steps()[0].window.version({11, 11, 11}, dx, 0, 0), 0);
  EXPECT_EQ(LevelSchedule::make(2, 4, p).final_version(), 8);
  p.passes = 2;
  EXPECT_EQ(LevelSchedule::make(3, 4, p).final_version(), 2);
  p.finest_subpass_size = 2;
  EXPECT_EQ(LevelSchedule::make(3, 4, p).final_version(), 16);
  EXPECT_EQ(LevelSchedule::make(3, 4, p).subpass_size(), 2);
  EXPECT_EQ(LevelSchedule::make(0, 1, p).subpass_size(), 1);
}

TEST(NeighbourSlots, EqualTheSchedulesSlotOfTheWindowsVersionForEveryOffset) {
  int64_t checked = 0, distinct_slots = 0;
  for (Scheme scheme : {Scheme::kPlain, Scheme::kSubpass, Scheme::kGrid, Scheme::kDualGrid}) {
    SynthesisParams params;
    params.scheme = scheme;
    params.passes = 3;
    params.cell_size = 6;  // small cells: the +-8 offsets cross several barriers
    for (int level : {0, 2}) {
      const LevelSchedule sch = LevelSchedule::make(level, 4, params);
      for (const Voxel p : {Voxel{0, 0, 0}, Voxel{5, -1, 7}, Voxel{-13, 22, 3}, Voxel{11, 6, -6}})
        for (const CorrectionStep& step : sch.steps()) {
          const HistoryWindow::Resolved w = step.window.resolve(p);
          // The step's table from another voxel's window: the versions do not depend on p.
          const auto table = NeighbourSlots::StepTable::make(sch, step.window.resolve({100, -50, 7}));
          const NeighbourSlots slots(table, sch, w, p);
          const int r = NeighbourSlots::kReach;
          int first = -1;
          for (int dz = -r; dz <= r; ++dz)
            for (int dy = -r; dy <= r; ++dy)
              for (int dx = -r; dx <= r; ++dx) {
                const Voxel q{p.x + dx, p.y + dy, p.z + dz};
                const int want = sch.slot(q, w.version_of(q));
                ASSERT_EQ(slots.slot(dx, dy, dz), want) << scheme_name(scheme) << " level " << level << " step "
                                                        << step.version << " offset " << dx << "," << dy << "," << dz;
                if (first < 0) first = want;
                distinct_slots += want != first;
                ++checked;
              }
        }
    }
  }
  EXPECT_GT(checked, 100000);
  EXPECT_GT(distinct_slots, 0);  // the offsets do reach different slots
}

}  // namespace
}  // namespace solidtex
