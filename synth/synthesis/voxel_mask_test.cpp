#include "synthesis/voxel_mask.h"

#include <gtest/gtest.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <random>
#include <set>
#include <vector>

#include "synthesis/brick_index.h"

namespace solidtex {
namespace {

// A box straddling the origin on every axis, several bricks wide, with lo not brick-aligned.
const VoxelBox kBox{{-19, -11, -9}, {13, 9, 17}};

std::vector<Voxel> all_voxels(const VoxelBox& b) {
  std::vector<Voxel> out;
  for (int z = b.lo.z; z < b.hi.z; ++z)
    for (int y = b.lo.y; y < b.hi.y; ++y)
      for (int x = b.lo.x; x < b.hi.x; ++x) out.push_back({x, y, z});
  return out;
}

TEST(VoxelMask, FloorDivRoundsTowardsMinusInfinity) {
  EXPECT_EQ(floor_div(0, 8), 0);
  EXPECT_EQ(floor_div(7, 8), 0);
  EXPECT_EQ(floor_div(8, 8), 1);
  EXPECT_EQ(floor_div(-1, 8), -1);
  EXPECT_EQ(floor_div(-8, 8), -1);
  EXPECT_EQ(floor_div(-9, 8), -2);
  EXPECT_EQ(floor_div(-16, 8), -2);
  EXPECT_EQ(floor_div(-17, 8), -3);
}

TEST(VoxelMask, VoxelsOnEitherSideOfNegativeBrickBoundariesAreDistinct) {
  // -1/0 and -8/-9 sit on brick boundaries; with truncating division they would share a brick
  // and alias (e.g. -1 and 7 would land on the same bit).
  VoxelMask m(kBox);
  const std::vector<Voxel> pts = {{-1, 0, 0}, {0, 0, 0}, {-8, -8, -8}, {-9, -9, -9}, {7, 7, 7},
                                  {-1, -1, -1}, {-9, 0, 0}, {-8, 0, 0}, {0, -9, 0}, {0, 0, -9}};
  for (size_t i = 0; i < pts.size(); ++i) {
    ASSERT_TRUE(m.insert(pts[i])) << i;
    for (size_t j = 0; j < pts.size(); ++j) EXPECT_EQ(m.contains(pts[j]), j <= i) << i << " " << j;
  }
  EXPECT_EQ(m.count(), int64_t(pts.size()));
  // Neighbours of the inserted points that were never inserted.
  for (const Voxel& p : {Voxel{1, 0, 0}, Voxel{-2, 0, 0}, Voxel{7, -1, 0}, Voxel{-1, 7, 0}, Voxel{-16, -8, -8},
                         Voxel{-10, -9, -9}, Voxel{-9, -9, -1}, Voxel{7, 7, -1}})
    EXPECT_FALSE(m.contains(p)) << p.x << "," << p.y << "," << p.z;
}

TEST(VoxelMask, EveryVoxelOfTheBoxRoundTrips) {
  // Insert every other voxel (checkerboard) over the whole box: each bit of every brick,
  // including the partial bricks at the faces, must map back to its own voxel.
  VoxelMask m(kBox);
  int64_t inserted = 0;
  for (const Voxel& p : all_voxels(kBox))
    if (((p.x + p.y + p.z) & 1) == 0) {
      ASSERT_TRUE(m.insert(p));
      ++inserted;
    }
  EXPECT_EQ(m.count(), inserted);
  for (const Voxel& p : all_voxels(kBox))
    ASSERT_EQ(m.contains(p), ((p.x + p.y + p.z) & 1) == 0) << p.x << "," << p.y << "," << p.z;
  const auto v = m.to_vector();
  ASSERT_EQ(int64_t(v.size()), inserted);
  for (const Voxel& p : v) {
    EXPECT_TRUE(kBox.contains(p));
    EXPECT_EQ((p.x + p.y + p.z) & 1, 0);
  }
  EXPECT_EQ(std::set<Voxel>(v.begin(), v.end()).size(), v.size());
}

TEST(VoxelMask, InsertReturnsTrueOnlyTheFirstTime) {
  VoxelMask m(kBox);
  EXPECT_TRUE(m.insert({-9, 3, -1}));
  EXPECT_FALSE(m.insert({-9, 3, -1}));
  EXPECT_FALSE(m.insert({-9, 3, -1}));
  EXPECT_EQ(m.count(), 1);
  EXPECT_TRUE(m.insert({-9, 3, 0}));  // same (x, y), next brick in z
  EXPECT_FALSE(m.insert({-9, 3, 0}));
  EXPECT_EQ(m.count(), 2);
  const auto v = m.to_vector();
  ASSERT_EQ(v.size(), 2u);
}

TEST(VoxelMask, OutsideTheBoxIsNotContained) {
  VoxelMask m(kBox);
  m.insert(kBox.lo);
  m.insert({kBox.hi.x - 1, kBox.hi.y - 1, kBox.hi.z - 1});
  EXPECT_TRUE(m.contains(kBox.lo));
  EXPECT_TRUE(m.contains({kBox.hi.x - 1, kBox.hi.y - 1, kBox.hi.z - 1}));
  EXPECT_FALSE(m.contains(kBox.hi));
  EXPECT_FALSE(m.contains({kBox.lo.x - 1, kBox.lo.y, kBox.lo.z}));
  EXPECT_FALSE(m.contains({kBox.hi.x, kBox.lo.y, kBox.lo.z}));
}

TEST(VoxelMask, ToVectorOrderDoesNotDependOnInsertionOrderOrThreads) {
  // A sparse pseudo-random subset of the box, plus a dense corner block.
  std::mt19937 rng(12345);
  std::vector<Voxel> pts;
  for (const Voxel& p : all_voxels(kBox))
    if (rng() % 5 == 0 || (p.x < -12 && p.y < -4 && p.z < -2)) pts.push_back(p);
  ASSERT_GT(pts.size(), 2000u);

  VoxelMask serial(kBox);
  for (const Voxel& p : pts) ASSERT_TRUE(serial.insert(p));
  const auto expected = serial.to_vector();
  ASSERT_EQ(expected.size(), pts.size());
  EXPECT_EQ(std::set<Voxel>(expected.begin(), expected.end()), std::set<Voxel>(pts.begin(), pts.end()));

  for (int round = 0; round < 4; ++round) {
    // Every voxel twice, shuffled, inserted from many tasks at once.
    std::vector<Voxel> work = pts;
    work.insert(work.end(), pts.begin(), pts.end());
    std::shuffle(work.begin(), work.end(), rng);
    VoxelMask parallel(kBox);
    std::atomic<int64_t> firsts{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, work.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i)
        if (parallel.insert(work[i])) firsts.fetch_add(1, std::memory_order_relaxed);
    });
    EXPECT_EQ(firsts.load(), int64_t(pts.size())) << "round " << round;
    EXPECT_EQ(parallel.count(), int64_t(pts.size())) << "round " << round;
    const auto got = parallel.to_vector();
    ASSERT_EQ(got.size(), expected.size()) << "round " << round;
    for (size_t i = 0; i < got.size(); ++i)
      ASSERT_EQ(got[i], expected[i]) << "round " << round << " index " << i;
  }

  // The documented order: bricks x fastest, then y, then z; inside a brick by bit x + 8y + 64z.
  auto key = [](const Voxel& p) {
    return std::array<int, 6>{floor_div(p.z, 8), floor_div(p.y, 8), floor_div(p.x, 8), p.z & 7, p.y & 7, p.x & 7};
  };
  for (size_t i = 1; i < expected.size(); ++i) ASSERT_LT(key(expected[i - 1]), key(expected[i])) << i;

  // Reverse serial insertion gives the same sequence too.
  VoxelMask reversed(kBox);
  for (auto it = pts.rbegin(); it != pts.rend(); ++it) reversed.insert(*it);
  EXPECT_EQ(reversed.to_vector(), expected);
}

TEST(VoxelMask, WholeBrickAccessAgreesWithPerVoxelAccess) {
  VoxelMask m(kBox);
  const BrickIndex& index = m.index();
  const Voxel p{-9, 3, -1};
  const size_t b = index.brick_of(p);
  VoxelMask::Bits bits;
  EXPECT_FALSE(m.bits(b, bits));
  m.or_bits(b, VoxelMask::Bits{});  // nothing to add: no brick allocated
  EXPECT_EQ(m.bricks(), 0);
  VoxelMask::Bits add{};
  const int bit = BrickIndex::voxel_in_brick(p);
  add[size_t(bit >> 6)] |= uint64_t(1) << (bit & 63);
  add[7] |= uint64_t(1) << 63;  // the brick's highest voxel
  m.or_bits(b, add);
  m.or_bits(b, add);  // idempotent
  EXPECT_EQ(m.bricks(), 1);
  EXPECT_EQ(m.count(), 2);
  EXPECT_TRUE(m.contains(p));
  const Voxel top = BrickIndex::voxel_at(index.brick_origin(b), 511);
  EXPECT_TRUE(m.contains(top));
  EXPECT_FALSE(m.insert(top));
  EXPECT_TRUE(m.insert({p.x + 1, p.y, p.z}));
  ASSERT_TRUE(m.bits(b, bits));
  EXPECT_EQ(bits[size_t(bit >> 6)] & add[size_t(bit >> 6)], add[size_t(bit >> 6)]);
  EXPECT_EQ(m.count(), 3);
  EXPECT_EQ(m.to_vector(), (std::vector<Voxel>{p, top, {p.x + 1, p.y, p.z}}));  // p.x + 1 starts the next brick
  // The brick coordinates the cover starts at and spans.
  EXPECT_EQ(index.first_brick(), (std::array<int, 3>{-3, -2, -2}));
  EXPECT_EQ(index.extent(), (std::array<int, 3>{5, 4, 5}));
}

TEST(VoxelMask, MoveKeepsTheContents) {
  VoxelMask a(kBox);
  a.insert({-1, -1, -1});
  a.insert({5, 0, -9});
  VoxelMask b(std::move(a));
  EXPECT_EQ(b.count(), 2);
  EXPECT_TRUE(b.contains({-1, -1, -1}));
  EXPECT_TRUE(b.contains({5, 0, -9}));
  VoxelMask c;
  c = std::move(b);
  EXPECT_EQ(c.count(), 2);
  EXPECT_EQ(c.to_vector().size(), 2u);
  EXPECT_TRUE(c.insert({0, 0, 0}));
  EXPECT_TRUE(c.contains({0, 0, 0}));
}

TEST(VoxelMask, EmptyBoxHoldsNothing) {
  for (const VoxelBox& b : {VoxelBox{}, VoxelBox{{-4, -4, -4}, {-4, 4, 4}}, VoxelBox{{0, 0, 0}, {5, 5, -1}}}) {
    ASSERT_TRUE(b.empty());
    EXPECT_EQ(b.volume(), 0);
    VoxelMask m(b);
    EXPECT_EQ(m.count(), 0);
    EXPECT_TRUE(m.to_vector().empty());
    EXPECT_FALSE(m.contains({0, 0, 0}));
    EXPECT_FALSE(m.contains(b.lo));
  }
  VoxelMask d;
  EXPECT_EQ(d.count(), 0);
  EXPECT_TRUE(d.to_vector().empty());
  EXPECT_FALSE(d.contains({0, 0, 0}));
}

TEST(VoxelBox, IncludeDilateAndVolume) {
  VoxelBox b;
  EXPECT_TRUE(b.empty());
  b.include({-3, 2, 5});
  EXPECT_FALSE(b.empty());
  EXPECT_EQ(b.volume(), 1);
  EXPECT_TRUE(b.contains({-3, 2, 5}));
  b.include({1, -1, 5});
  EXPECT_EQ(b.lo, (Voxel{-3, -1, 5}));
  EXPECT_EQ(b.hi, (Voxel{2, 3, 6}));
  EXPECT_EQ(b.volume(), 5 * 4 * 1);
  const VoxelBox d = b.dilated(2);
  EXPECT_EQ(d.lo, (Voxel{-5, -3, 3}));
  EXPECT_EQ(d.hi, (Voxel{4, 5, 8}));
  EXPECT_FALSE(b.contains(b.hi));
}

}  // namespace
}  // namespace solidtex
