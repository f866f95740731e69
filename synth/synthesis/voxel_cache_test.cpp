#include "synthesis/voxel_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace solidtex {
namespace {

// Exemplar coordinates are wrapped pixels: 16 bits each is the documented packing.
CoordinateTriple triple_for(const Voxel& p, int level) {
  CoordinateTriple t;
  for (int k = 0; k < 3; ++k) {
    const uint32_t h = uint32_t(p.x) * 73856093u ^ uint32_t(p.y) * 19349663u ^ uint32_t(p.z) * 83492791u ^
                       uint32_t(level * 3 + k) * 2654435761u;
    t.at[size_t(k)] = {int32_t(h & 0xffffu), int32_t((h >> 16) & 0xffffu)};
  }
  return t;
}

std::vector<CoordinateTriple> triples_for(const std::vector<Voxel>& v, int level) {
  std::vector<CoordinateTriple> out;
  for (const Voxel& p : v) out.push_back(triple_for(p, level));
  return out;
}

// A few voxels of the 8^3 brick with origin o (o a multiple of 8), corners included.
std::vector<Voxel> brick(const Voxel& o) {
  return {o, {o.x + 7, o.y + 7, o.z + 7}, {o.x + 3, o.y, o.z + 5}, {o.x, o.y + 6, o.z + 1}};
}

int64_t found_count(VoxelCache& c, int level, const std::vector<Voxel>& v) {
  std::vector<CoordinateTriple> out;
  std::vector<uint8_t> found;
  return c.lookup(PyramidLevel{level}, v, out, found);
}

// What a brick of brick(o)'s four voxels costs, as the cache counts it.
int64_t four_voxel_brick_bytes() {
  VoxelCache c(1, int64_t(1) << 30);
  c.insert(PyramidLevel{0}, brick({0, 0, 0}), triples_for(brick({0, 0, 0}), 0));
  EXPECT_EQ(c.counters().bytes, VoxelCache::brick_bytes(4));
  return c.counters().bytes;
}

TEST(VoxelCache, InsertedTriplesReadBackExactlyAndOthersMiss) {
  VoxelCache c(3, int64_t(1) << 30);
  std::vector<Voxel> v;
  for (int z = -9; z <= 8; z += 3)
    for (int y = -17; y <= 9; y += 4)
      for (int x = -8; x <= 1; ++x) v.push_back({x, y, z});
  v.push_back({-1, -1, -1});
  v.push_back({0, 0, 0});
  v.push_back({-100000, 77777, -3});
  c.insert(PyramidLevel{1}, v, triples_for(v, 1));

  std::vector<CoordinateTriple> out{CoordinateTriple{}};
  std::vector<uint8_t> found{7, 7, 7};
  EXPECT_EQ(c.lookup(PyramidLevel{1}, v, out, found), int64_t(v.size()));
  ASSERT_EQ(out.size(), v.size());
  ASSERT_EQ(found.size(), v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    EXPECT_EQ(found[i], 1) << i;
    EXPECT_EQ(out[i], triple_for(v[i], 1)) << v[i].x << "," << v[i].y << "," << v[i].z;
  }
  // Neighbours that were never inserted, some in the same bricks, and extreme 16-bit values.
  const std::vector<Voxel> others = {{2, 0, 0},  {-9, -17, -9}, {-8, -16, -9},
                                     {-1, -2, 0}, {0, 0, -1},    {-100000, 77777, -4}};
  EXPECT_EQ(c.lookup(PyramidLevel{1}, others, out, found), 0);
  for (size_t i = 0; i < others.size(); ++i) {
    EXPECT_EQ(found[i], 0);
    EXPECT_EQ(out[i], CoordinateTriple{});
  }
  CoordinateTriple extreme;
  extreme.at = {ExemplarPixel{65535, 0}, ExemplarPixel{0, 65535}, ExemplarPixel{32768, 32767}};
  c.insert(PyramidLevel{2}, {{5, 5, 5}}, {extreme});
  EXPECT_EQ(c.lookup(PyramidLevel{2}, {{5, 5, 5}}, out, found), 1);
  EXPECT_EQ(out[0], extreme);
}

TEST(VoxelCache, LevelsAreIndependent) {
  VoxelCache c(3, int64_t(1) << 30);
  const std::vector<Voxel> v = {{0, 0, 0}, {-1, 2, -3}, {9, -9, 17}};
  c.insert(PyramidLevel{0}, v, triples_for(v, 0));
  EXPECT_EQ(found_count(c, 1, v), 0);
  EXPECT_EQ(found_count(c, 2, v), 0);
  c.insert(PyramidLevel{2}, v, triples_for(v, 2));
  std::vector<CoordinateTriple> out;
  std::vector<uint8_t> found;
  ASSERT_EQ(c.lookup(PyramidLevel{0}, v, out, found), 3);
  for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(out[i], triple_for(v[i], 0));
  ASSERT_EQ(c.lookup(PyramidLevel{2}, v, out, found), 3);
  for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(out[i], triple_for(v[i], 2));
  EXPECT_EQ(found_count(c, 1, v), 0);
  const auto k = c.counters();
  ASSERT_EQ(k.voxels_per_level.size(), 3u);
  EXPECT_EQ(k.voxels_per_level[0], 3);
  EXPECT_EQ(k.voxels_per_level[1], 0);
  EXPECT_EQ(k.voxels_per_level[2], 3);
}

TEST(VoxelCache, CountersTrackHitsMissesInsertsAndBricks) {
    VoxelCache c(2, int64_t(1) << 30);
  auto k = c.counters();
  EXPECT_EQ(k.hits, 0);
  EXPECT_EQ(k.misses, 0);
  EXPECT_EQ(k.inserted, 0);
  EXPECT_EQ(k.bricks, 0);
  EXPECT_EQ(k.bytes, 0);
  // Bricks split at -1/0 and -9/-8 on each axis: (-1,0,0) and (0,0,0) are different leaves.
  const std::vector<Voxel> v = {{-1, 0, 0}, {0, 0, 0}, {-8, 0, 0}, {-9, 0, 0}, {7, 7, 7}, {0, -1, 0}};
  c.insert(PyramidLevel{0}, v, triples_for(v, 0));
  k = c.counters();
  EXPECT_EQ(k.inserted, 6);
  EXPECT_EQ(k.bricks, 4);  // (-1,0,0) and (-8,0,0) share [-8, 0); (0,0,0) and (7,7,7) share [0, 8)
  const int64_t four_bricks = 2 * VoxelCache::brick_bytes(2) + 2 * VoxelCache::brick_bytes(1);
  EXPECT_EQ(k.bytes, four_bricks);
  EXPECT_EQ(k.voxels_per_level[0], 6);
  // Re-inserting cached voxels adds nothing.
  c.insert(PyramidLevel{0}, {v[0], v[1]}, triples_for({v[0], v[1]}, 0));
  k = c.counters();
  EXPECT_EQ(k.inserted, 6);
  EXPECT_EQ(k.voxels_per_level[0], 6);
  EXPECT_EQ(k.bricks, 4);
  // Level 1 has its own leaves.
  c.insert(PyramidLevel{1}, {{0, 0, 0}}, {triple_for({0, 0, 0}, 1)});
  k = c.counters();
  EXPECT_EQ(k.bricks, 5);
  EXPECT_EQ(k.bytes, four_bricks + VoxelCache::brick_bytes(1));
  EXPECT_EQ(k.inserted, 7);
  // Lookups: 3 hits and 2 misses, then 0 and 4.
  EXPECT_EQ(found_count(c, 0, {{-1, 0, 0}, {1, 0, 0}, {7, 7, 7}, {-9, 0, 0}, {-9, 0, -1}}), 3);
  k = c.counters();
  EXPECT_EQ(k.hits, 3);
  EXPECT_EQ(k.misses, 2);
  EXPECT_EQ(found_count(c, 1, {{-1, 0, 0}, {1, 0, 0}, {7, 7, 8}, {-9, 0, 0}}), 0);
  k = c.counters();
  EXPECT_EQ(k.hits, 3);
  EXPECT_EQ(k.misses, 6);
  EXPECT_EQ(k.evicted_bricks, 0);
}

TEST(VoxelCache, SmallBudgetEvictsTheLeastRecentlyUsedBrick) {
  const int64_t leaf = four_voxel_brick_bytes();
  const Voxel a{0, 0, 0}, b{8, 0, 0}, cc{-8, 0, 0}, d{0, -8, 0};
  // Room for three and a half bricks: a fourth evicts one (down to <= 90% of the budget).
  for (const bool touch_a : {false, true}) {
    SCOPED_TRACE(touch_a ? "a looked up" : "a untouched");
    VoxelCache c(1, 3 * leaf + leaf / 2);
    for (const Voxel& o : {a, b, cc}) c.insert(PyramidLevel{0}, brick(o), triples_for(brick(o), 0));
    EXPECT_EQ(c.counters().bricks, 3);
    EXPECT_EQ(c.counters().evicted_bricks, 0);
    if (touch_a) {
      EXPECT_EQ(found_count(c, 0, {a}), 1);
    }
    c.insert(PyramidLevel{0}, brick(d), triples_for(brick(d), 0));
    const auto k = c.counters();
    EXPECT_EQ(k.bricks, 3);
    EXPECT_EQ(k.evicted_bricks, 1);
    EXPECT_LE(k.bytes, (3 * leaf + leaf / 2) * 9 / 10);
    EXPECT_EQ(k.voxels_per_level[0], 12);
    // The oldest brick goes: a when untouched, b when a was looked up after b's insert.
    const Voxel gone = touch_a ? b : a;
    EXPECT_EQ(found_count(c, 0, brick(gone)), 0);
    for (const Voxel& o : {a, b, cc, d}) {
      if (o == gone) continue;
      std::vector<CoordinateTriple> out;
      std::vector<uint8_t> found;
      EXPECT_EQ(c.lookup(PyramidLevel{0}, brick(o), out, found), 4) << o.x << "," << o.y;
      for (size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i], triple_for(brick(o)[i], 0));
    }
  }
}

TEST(VoxelCache, EvictionIsLeastRecentlyUsedAcrossLevels) {
  const int64_t leaf = four_voxel_brick_bytes();
  VoxelCache c(2, 3 * leaf + leaf / 2);
  const Voxel o{-16, -16, -16};
  c.insert(PyramidLevel{1}, brick(o), triples_for(brick(o), 1));  // oldest
  c.insert(PyramidLevel{0}, brick(o), triples_for(brick(o), 0));
  c.insert(PyramidLevel{0}, brick({0, 0, 0}), triples_for(brick({0, 0, 0}), 0));
  c.insert(PyramidLevel{1}, brick({0, 0, 0}), triples_for(brick({0, 0, 0}), 1));
  EXPECT_EQ(c.counters().evicted_bricks, 1);
  EXPECT_EQ(found_count(c, 1, brick(o)), 0);
  EXPECT_EQ(found_count(c, 0, brick(o)), 4);
  EXPECT_EQ(found_count(c, 0, brick({0, 0, 0})), 4);
  EXPECT_EQ(found_count(c, 1, brick({0, 0, 0})), 4);
  const auto k = c.counters();
  EXPECT_EQ(k.voxels_per_level[0], 8);
  EXPECT_EQ(k.voxels_per_level[1], 4);
}

TEST(VoxelCache, LoweringTheBudgetEvictsAtOnce) {
  const int64_t leaf = four_voxel_brick_bytes();
  VoxelCache c(1, 100 * leaf);
  EXPECT_EQ(c.budget_bytes(), 100 * leaf);
  for (int i = 0; i < 10; ++i)
    c.insert(PyramidLevel{0}, brick({8 * i - 40, 0, 0}), triples_for(brick({8 * i - 40, 0, 0}), 0));
  EXPECT_EQ(c.counters().bricks, 10);
  c.set_budget_bytes(5 * leaf);  // a service lowering every volume's share: no insert needed
  EXPECT_EQ(c.budget_bytes(), 5 * leaf);
  auto k = c.counters();
  EXPECT_LE(k.bytes, 5 * leaf * 9 / 10);
  EXPECT_EQ(k.bricks, 4);
  EXPECT_EQ(k.evicted_bricks, 6);
  // The newest bricks survive: the four inserted last.
  for (int i = 6; i < 10; ++i) EXPECT_EQ(found_count(c, 0, brick({8 * i - 40, 0, 0})), 4) << i;
  for (int i = 0; i < 6; ++i) EXPECT_EQ(found_count(c, 0, brick({8 * i - 40, 0, 0})), 0) << i;
  // Room for one more under the new budget; the next beyond it evicts the oldest again.
  c.insert(PyramidLevel{0}, brick({0, 64, 0}), triples_for(brick({0, 64, 0}), 0));
  EXPECT_EQ(c.counters().bricks, 5);
  c.insert(PyramidLevel{0}, brick({0, 72, 0}), triples_for(brick({0, 72, 0}), 0));
  k = c.counters();
  EXPECT_EQ(k.bricks, 4);
  EXPECT_EQ(k.evicted_bricks, 8);
  EXPECT_EQ(found_count(c, 0, brick({0, 72, 0})), 4);
  EXPECT_EQ(found_count(c, 0, brick({0, 64, 0})), 4);
  EXPECT_EQ(found_count(c, 0, brick({16, 0, 0})), 0);  // i = 6 and 7 went (looked up first)
}

TEST(VoxelCache, BricksFarApartAreDistinctAndEachCostsOneBrick) {
  // Coordinates that agree in their low 24 bits, up to the lattice's +-2^28: no two share a
  // brick (or its LRU entry), and scattered bricks cost what adjacent ones cost.
  const std::vector<Voxel> v = {{0, 0, 0},           {1 << 24, 0, 0},       {0, -(1 << 24), 0},
                                {0, 0, (1 << 28) - 1}, {-(1 << 28), 0, 0}, {(1 << 28) - 1, -(1 << 28), 1 << 27}};
  VoxelCache c(1, int64_t(1) << 30);
  c.insert(PyramidLevel{0}, v, triples_for(v, 0));
  auto k = c.counters();
  EXPECT_EQ(k.bricks, int64_t(v.size()));
  EXPECT_EQ(k.bytes, int64_t(v.size()) * VoxelCache::brick_bytes(1));
  std::vector<CoordinateTriple> out;
  std::vector<uint8_t> found;
  ASSERT_EQ(c.lookup(PyramidLevel{0}, v, out, found), int64_t(v.size()));
  for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(out[i], triple_for(v[i], 0)) << i;
  // A budget of two bricks keeps the two used last, whatever their coordinates.
  c.set_budget_bytes(2 * VoxelCache::brick_bytes(1) + VoxelCache::brick_bytes(1) / 2);
  EXPECT_EQ(found_count(c, 0, {v[1]}), 1);
  c.insert(PyramidLevel{0}, {v[4]}, {triple_for(v[4], 0)});
  k = c.counters();
  EXPECT_EQ(k.bricks, 2);
  EXPECT_EQ(found_count(c, 0, {v[1], v[4]}), 2);
  EXPECT_EQ(found_count(c, 0, {v[0], v[2], v[3], v[5]}), 0);
}

// Bricks hold their present voxels only: values survive inserts in any order, merged into
// bricks that already hold others, and overwrites; a cut's one-layer bricks cost under 16 bytes
// per voxel (issue #13's budget), full bricks about 12.
TEST(VoxelCache, SparseBricksMergeInsertsAndCostWhatTheyHold) {
  EXPECT_GE(VoxelCache::brick_bytes(512), 512 * 12);
  EXPECT_LT(double(VoxelCache::brick_bytes(512)) / 512, 12.5);
  EXPECT_LT(double(VoxelCache::brick_bytes(64)) / 64, 16.0);
  EXPECT_LT(VoxelCache::brick_bytes(1), VoxelCache::brick_bytes(64));
  VoxelCache c(1, int64_t(1) << 30);
  // A z layer of 24 x 24 voxels (9 bricks of 64), inserted odd rows first, then even rows
  // backwards, then a second layer into the same bricks, then overwrites of a few.
  std::vector<Voxel> odd, even, layer2;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) (y % 2 ? odd : even).push_back({x - 8, y - 8, 3});
  std::reverse(even.begin(), even.end());
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) layer2.push_back({x - 8, y - 8, 5});
  c.insert(PyramidLevel{0}, odd, triples_for(odd, 0));
  c.insert(PyramidLevel{0}, even, triples_for(even, 0));
  auto k = c.counters();
  EXPECT_EQ(k.bricks, 9);
  EXPECT_EQ(k.bytes, 9 * VoxelCache::brick_bytes(64));
  EXPECT_LT(double(k.bytes) / 576, 16.0);
  c.insert(PyramidLevel{0}, layer2, triples_for(layer2, 0));
  EXPECT_EQ(c.counters().bytes, 9 * VoxelCache::brick_bytes(128));
  const std::vector<Voxel> again = {odd[3], layer2[100], even[7]};
  std::vector<CoordinateTriple> other = triples_for(again, 1);
  c.insert(PyramidLevel{0}, again, other);
  k = c.counters();
  EXPECT_EQ(k.inserted, 1152);
  EXPECT_EQ(k.voxels_per_level[0], 1152);
  std::vector<Voxel> all = odd;
  all.insert(all.end(), even.begin(), even.end());
  all.insert(all.end(), layer2.begin(), layer2.end());
  std::vector<CoordinateTriple> out;
  std::vector<uint8_t> found;
  ASSERT_EQ(c.lookup(PyramidLevel{0}, all, out, found), int64_t(all.size()));
  for (size_t i = 0; i < all.size(); ++i) {
    const auto hit = std::find(again.begin(), again.end(), all[i]);
    const CoordinateTriple want = hit == again.end() ? triple_for(all[i], 0) : other[size_t(hit - again.begin())];
    ASSERT_EQ(out[i], want) << all[i].x << "," << all[i].y << "," << all[i].z;
  }
  EXPECT_EQ(found_count(c, 0, {{0, 0, 4}, {-8, -8, 2}, {15, 15, 6}}), 0);
}

TEST(VoxelCache, ZeroBudgetCachesNothing) {
  VoxelCache c(1, 0);
  c.insert(PyramidLevel{0}, {{1, 2, 3}}, {triple_for({1, 2, 3}, 0)});
  EXPECT_EQ(found_count(c, 0, {{1, 2, 3}}), 0);
  EXPECT_EQ(c.counters().bricks, 0);
}

TEST(VoxelCache, ClearEmptiesEveryLevel) {
  VoxelCache c(2, int64_t(1) << 30);
  const std::vector<Voxel> v = {{-1, -1, -1}, {0, 0, 0}, {30, -30, 5}};
  c.insert(PyramidLevel{0}, v, triples_for(v, 0));
  c.insert(PyramidLevel{1}, v, triples_for(v, 1));
  ASSERT_EQ(found_count(c, 0, v), 3);
  c.clear();
  EXPECT_EQ(found_count(c, 0, v), 0);
  EXPECT_EQ(found_count(c, 1, v), 0);
  auto k = c.counters();
  EXPECT_EQ(k.bricks, 0);
  EXPECT_EQ(k.bytes, 0);
  EXPECT_EQ(k.voxels_per_level, (std::vector<int64_t>{0, 0}));
  // Usable again afterwards.
  c.insert(PyramidLevel{1}, {v[2]}, {triple_for(v[2], 1)});
  std::vector<CoordinateTriple> out;
  std::vector<uint8_t> found;
  ASSERT_EQ(c.lookup(PyramidLevel{1}, {v[2]}, out, found), 1);
  EXPECT_EQ(out[0], triple_for(v[2], 1));
  k = c.counters();
  EXPECT_EQ(k.bricks, 1);
  EXPECT_EQ(k.voxels_per_level, (std::vector<int64_t>{0, 1}));
}

}  // namespace
}  // namespace solidtex
