#include "synthesis/level_store.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace solidtex {
namespace {

// A distinct, recognisable state for every (voxel, slot).
VoxelState state_for(const Voxel& p, int slot) {
  VoxelState s;
  for (int k = 0; k < 3; ++k)
    s.triple.at[size_t(k)] = {p.x * 7 + slot * 1000 + k, p.y * 13 - slot * 100 + p.z * 3 + k};
  s.color = {float(p.x) + 0.25f * float(slot), float(p.y), float(p.z), float(slot)};
  return s;
}

bool same(const VoxelState& a, const VoxelState& b) { return a.triple == b.triple && a.color == b.color; }

std::vector<Voxel> voxels_of(const VoxelBox& b) {
  std::vector<Voxel> out;
  for (int z = b.lo.z; z < b.hi.z; ++z)
    for (int y = b.lo.y; y < b.hi.y; ++y)
      for (int x = b.lo.x; x < b.hi.x; ++x) out.push_back({x, y, z});
  return out;
}

TEST(LevelStore, ValuesReadBackPerVoxelAndSlotAcrossNegativeBricks) {
  const VoxelBox box{{-12, -9, -17}, {10, 8, 3}};  // lo not brick-aligned, straddles 0 and -8
  const int slots = 3;
  LevelStore store(box, slots);
  EXPECT_EQ(store.slots(), slots);
  const auto all = voxels_of(box);
  for (const Voxel& p : all) store.allocate(p);
  for (const Voxel& p : all)
    for (int s = 0; s < slots; ++s) store.set(p, s, state_for(p, s));
  const LevelStore& cs = store;
  for (const Voxel& p : all) {
    ASSERT_TRUE(cs.has(p));
    for (int s = 0; s < slots; ++s)
      ASSERT_TRUE(same(cs.state(p, s), state_for(p, s))) << p.x << "," << p.y << "," << p.z << " slot " << s;
  }
}

TEST(LevelStore, SlotsAndBricksAreIndependent) {
  const VoxelBox box{{-16, -16, -16}, {16, 16, 16}};
  LevelStore store(box, 2);
  // Pairs that alias under truncating division or a missing slot stride.
  const Voxel a{-1, 0, 0}, b{7, 0, 0}, c{-8, -8, -8}, d{0, 0, 0}, e{-9, -9, -9}, f{7, 7, 7};
  for (const Voxel& p : {a, b, c, d, e, f}) store.allocate(p);
  for (const Voxel& p : {a, b, c, d, e, f})
    for (int s = 0; s < 2; ++s) store.set(p, s, VoxelState{});
  store.set(a, 0, state_for(a, 0));
  // Writing slot 0 of `a` leaves slot 1 and every other voxel untouched.
  EXPECT_TRUE(same(store.state(a, 1), VoxelState{}));
  for (const Voxel& p : {b, c, d, e, f})
    for (int s = 0; s < 2; ++s) EXPECT_TRUE(same(store.state(p, s), VoxelState{})) << p.x << " " << s;
  store.set(a, 1, state_for(a, 1));
  store.set(b, 0, state_for(b, 0));
  store.set(e, 1, state_for(e, 1));
  store.set(c, 0, state_for(c, 0));
  EXPECT_TRUE(same(store.state(a, 0), state_for(a, 0)));
  EXPECT_TRUE(same(store.state(a, 1), state_for(a, 1)));
  EXPECT_TRUE(same(store.state(b, 0), state_for(b, 0)));
  EXPECT_TRUE(same(store.state(c, 0), state_for(c, 0)));
  EXPECT_TRUE(same(store.state(e, 1), state_for(e, 1)));
  EXPECT_TRUE(same(store.state(e, 0), VoxelState{}));
  EXPECT_TRUE(same(store.state(d, 0), VoxelState{}));
  EXPECT_TRUE(same(store.state(f, 1), VoxelState{}));
}

TEST(LevelStore, HasOnlyForAllocatedBricksInsideTheBox) {
  const VoxelBox box{{-16, -8, 0}, {16, 8, 8}};
  LevelStore store(box, 1);
  EXPECT_FALSE(store.has({-1, 0, 0}));
  EXPECT_FALSE(store.has({0, 0, 0}));
  store.allocate({-1, 0, 0});  // brick [-8, 0) x [0, 8) x [0, 8)
  EXPECT_TRUE(store.has({-1, 0, 0}));
  EXPECT_TRUE(store.has({-8, 7, 7}));   // same brick
  EXPECT_FALSE(store.has({0, 0, 0}));   // next brick in x
  EXPECT_FALSE(store.has({-9, 0, 0}));  // previous brick in x
  EXPECT_FALSE(store.has({-1, -1, 0})); // brick below in y
  EXPECT_FALSE(store.has({-1, 0, 8}));  // outside the box
  EXPECT_FALSE(store.has({-1, 0, -1})); // outside the box
  EXPECT_FALSE(store.has({-17, 0, 0})); // outside the box
  store.allocate({-1, 0, 0});           // idempotent
  store.allocate({-8, 3, 3});           // same brick
  LevelStore one(box, 1);
  one.allocate({0, 0, 0});
  EXPECT_EQ(store.bytes(), one.bytes());  // still one brick
}

TEST(LevelStore, BytesGrowPerBrickAndWithSlots) {
  const VoxelBox box{{-16, -16, -16}, {16, 16, 16}};
  LevelStore s1(box, 1), s3(box, 3);
  EXPECT_EQ(s1.bytes(), 0);
  s1.allocate({0, 0, 0});
  const int64_t one = s1.bytes();
  EXPECT_GE(one, 512 * int64_t(sizeof(CoordinateTriple) + sizeof(StateColor)));
  for (int x = 1; x < 8; ++x) s1.allocate({x, x, x});  // same brick
  EXPECT_EQ(s1.bytes(), one);
  s1.allocate({-1, 0, 0});
  EXPECT_EQ(s1.bytes(), 2 * one);
  s1.allocate({-9, -9, -9});
  s1.allocate({-8, -8, -8});
  EXPECT_EQ(s1.bytes(), 4 * one);
  s3.allocate({0, 0, 0});
  EXPECT_EQ(s3.bytes(), 3 * one);
}

TEST(LevelStore, FlagsAccumulatePerVoxelAndSlot) {
  const VoxelBox box{{-8, -8, -8}, {8, 8, 8}};
  LevelStore store(box, 2);
  for (const Voxel& p : voxels_of(box)) store.allocate(p);
  const Voxel p{-1, -1, -1}, q{0, 0, 0}, r{7, 7, 7};
  for (const Voxel& v : {p, q, r})
    for (int s = 0; s < 2; ++s) EXPECT_EQ(store.flags(v, s), 0);
  store.set_flag(p, 1, LevelStore::kRequired);
  EXPECT_EQ(store.flags(p, 1), LevelStore::kRequired);
  EXPECT_EQ(store.flags(p, 0), 0);
  EXPECT_EQ(store.flags(q, 1), 0);
  EXPECT_EQ(store.flags(r, 1), 0);  // 7 == -1 mod 8: would alias in another brick
  store.set_flag(p, 1, LevelStore::kRead);
  store.set_flag(p, 1, LevelStore::kRead);
  EXPECT_EQ(store.flags(p, 1), LevelStore::kRequired | LevelStore::kRead);
  store.set_flag(q, 0, LevelStore::kRead);
  EXPECT_EQ(store.flags(q, 0), LevelStore::kRead);
  EXPECT_EQ(store.flags(p, 0), 0);
  EXPECT_EQ(store.flags(p, 1), LevelStore::kRequired | LevelStore::kRead);
  // Unallocated or outside voxels report no flags.
  LevelStore sparse(box, 1);
  sparse.allocate({0, 0, 0});
  sparse.set_flag({0, 0, 0}, 0, LevelStore::kRead);
  EXPECT_EQ(sparse.flags({-1, 0, 0}, 0), 0);
  EXPECT_EQ(sparse.flags({100, 0, 0}, 0), 0);
}

TEST(LevelStore, NeighborhoodMatchesAtOverTheFullReach) {
  // Box and centres chosen so that every offset in [-8, 8]^3 around each centre is inside the
  // box, the centres sit at every position within their brick class that matters (0, 7, and
  // interior), and coordinates are negative and positive.
  const VoxelBox box{{-32, -32, -32}, {24, 24, 24}};
  const int slots = 2;
  LevelStore store(box, slots);
  const auto all = voxels_of(box);
  for (const Voxel& p : all) store.allocate(p);
  for (const Voxel& p : all)
    for (int s = 0; s < slots; ++s) store.set(p, s, state_for(p, s));
  const LevelStore& cs = store;
  constexpr int R = LevelStore::Neighborhood::kReach;
  static_assert(R >= 1 && R <= 8, "the box and centres below assume a reach of at most one brick");
  const std::vector<Voxel> centres = {{0, 0, 0}, {-1, -1, -1}, {-8, -9, 7}, {-16, 8, -9}, {3, -5, 15}, {-17, -24, 5}};
  int64_t compared = 0;
  for (const Voxel& c : centres) {
    const LevelStore::Neighborhood near(cs, c);
    for (int dz = -R; dz <= R; ++dz)
      for (int dy = -R; dy <= R; ++dy)
        for (int dx = -R; dx <= R; ++dx) {
          const Voxel q{c.x + dx, c.y + dy, c.z + dz};
          for (int s = 0; s < slots; ++s) {
            ASSERT_EQ(near.color(dx, dy, dz, s), &cs.color(q, s)) << "centre " << c.x << "," << c.y << "," << c.z
                                                                  << " offset " << dx << "," << dy << "," << dz << " slot " << s;
            ASSERT_EQ(near.triple(dx, dy, dz, s), &cs.triple(q, s));
            ASSERT_TRUE(same(cs.state(q, s), state_for(q, s)));
            ++compared;
          }
        }
  }
  EXPECT_EQ(compared, int64_t(centres.size()) * (2 * R + 1) * (2 * R + 1) * (2 * R + 1) * slots);
}

TEST(LevelStore, NeighborhoodAtTheBoxEdgeReadsAllocatedNeighbours) {
  // Centre in the box's first brick: the bricks below are outside (null) but the ones inside
  // still resolve.
  const VoxelBox box{{-8, -8, -8}, {16, 16, 16}};
  LevelStore store(box, 1);
  for (const Voxel& p : voxels_of(box)) store.allocate(p);
  for (const Voxel& p : voxels_of(box)) store.set(p, 0, state_for(p, 0));
  const Voxel c{-8, -8, -8};
  const LevelStore::Neighborhood near(store, c);
  constexpr int R = LevelStore::Neighborhood::kReach;
  for (int dz = 0; dz <= R; ++dz)
    for (int dy = 0; dy <= R; ++dy)
      for (int dx = 0; dx <= R; ++dx)
        ASSERT_TRUE(same({*near.triple(dx, dy, dz, 0), *near.color(dx, dy, dz, 0)}, state_for({c.x + dx, c.y + dy, c.z + dz}, 0)));
  // Offsets into the bricks below the box find nothing.
  EXPECT_EQ(near.color(-1, 0, 0, 0), nullptr);
  EXPECT_EQ(near.color(0, -1, 0, 0), nullptr);
  EXPECT_EQ(near.color(0, 0, -R, 0), nullptr);
  EXPECT_EQ(near.color(-1, -1, -1, 0), nullptr);
  EXPECT_NE(near.color(R, R, R, 0), nullptr);
}

TEST(LevelStore, HasIsFalseOutsideTheBoxAndInUnallocatedBricks) {
  const VoxelBox box{{-16, -16, -16}, {16, 16, 16}};
  LevelStore store(box, 2);
  store.allocate({-1, -1, -1});  // brick [-8, 0)^3
  store.set({-1, -1, -1}, 1, state_for({-1, -1, -1}, 1));
  const LevelStore& cs = store;
  ASSERT_TRUE(cs.has({-1, -1, -1}));
  EXPECT_TRUE(same(cs.state({-1, -1, -1}, 1), state_for({-1, -1, -1}, 1)));
  EXPECT_TRUE(cs.has({-8, -8, -8}));
  EXPECT_FALSE(cs.has({0, -1, -1}));    // next brick, not allocated
  EXPECT_FALSE(cs.has({-9, -1, -1}));   // previous brick, not allocated
  EXPECT_FALSE(cs.has({-1, -1, -17}));  // outside the box
  EXPECT_FALSE(cs.has({16, 0, 0}));     // outside the box
  // Neighborhood: null where the neighbouring brick is missing, the voxel otherwise.
  const LevelStore::Neighborhood near(cs, {-4, -4, -4});
  EXPECT_EQ(near.color(3, 3, 3, 1), &cs.color({-1, -1, -1}, 1));
  EXPECT_EQ(near.triple(3, 3, 3, 1), &cs.triple({-1, -1, -1}, 1));
  EXPECT_EQ(near.color(4, 0, 0, 0), nullptr);
  EXPECT_EQ(near.triple(4, 0, 0, 0), nullptr);
  EXPECT_EQ(near.color(-5, 0, 0, 0), nullptr);
  EXPECT_EQ(near.color(0, -8, 0, 0), nullptr);
}

}  // namespace
}  // namespace solidtex
