// Patch-vote output colours (patch_vote.h): what wins, what never does, and what a vote reads.
#include "synthesis/patch_vote.h"

#include <gtest/gtest.h>

#include <set>

#include "analysis/analysis.h"
#include "core/hash.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

std::shared_ptr<const Table> three_image_table() {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kPebbles, 40, 40);
  in.yz = testing::procedural(ProceduralKind::kStripes, 40, 40);
  in.zx = testing::procedural(ProceduralKind::kSpots, 40, 40);
  AnalysisParams p;
  p.levels = 2;
  p.neighborhood = 5;
  p.candidates = 8;
  p.pca_dims = 10;
  return analyze(ExemplarSet::create(std::move(in)).value(), p).value().table;
}

ExemplarPixel random_pixel(uint64_t trial, int k, int ab, int w) {
  return {int(hash_u64(trial, k, ab, 11) % uint64_t(3 * w)) - w, int(hash_u64(trial, k, ab, 12) % uint64_t(3 * w)) - w};
}

bool same_rgb(const float* a, const float* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

// Nine neighbours continuing one patch of plane k into the voxel outvote 18 scattered ones,
// whatever the colours, at every spacing; the colour is that pixel's, from plane k's image.
TEST(PatchVote, NeighboursContinuingOnePatchWin) {
  const auto table = three_image_table();
  const ExemplarSet& e = table->exemplars();
  const int w = e.plane(Plane::kXY).width;
  const PlaneWeights pw = normalised_weights({1, 1, 1});
  for (int spacing : {1, 2})
    for (int k = 0; k < 3; ++k)
      for (uint64_t trial = 0; trial < 50; ++trial) {
        CoordinateTriple own;
        VoteSources src;
        for (int j = 0; j < 3; ++j) {
          own.at[size_t(j)] = random_pixel(trial, j, 99, w);
          for (int ab = 0; ab < 9; ++ab) src[size_t(j)][size_t(ab)] = random_pixel(trial, j, ab, w);
        }
        const ExemplarPixel patch = random_pixel(trial, k, 50, w);
        for (int ab = 0; ab < 9; ++ab)
          src[size_t(k)][size_t(ab)] = {patch.x + spacing * (ab % 3 - 1), patch.y + spacing * (ab / 3 - 1)};
        float rgb[3];
        vote_color(*table, pw, spacing, own, src, rgb);
        ASSERT_TRUE(same_rgb(rgb, e.plane(Plane(k)).wrapped(patch.x, patch.y)))
            << "plane " << k << " spacing " << spacing << " trial " << trial;
      }
}

// Without agreement the output is still one of the voted exemplar pixels (never a blend), the
// one nearest the voxel's medoid colour; a plane of weight 0 casts no vote.
TEST(PatchVote, ScatteredVotesGiveAVotedPixelNearTheMedoid) {
  const auto table = three_image_table();
  const ExemplarSet& e = table->exemplars();
  const int w = e.plane(Plane::kXY).width;
  for (const std::array<float, 3> raw : {std::array<float, 3>{1, 1, 1}, std::array<float, 3>{0, 1, 1}}) {
    const PlaneWeights pw = normalised_weights(raw);
    for (uint64_t trial = 0; trial < 100; ++trial) {
      CoordinateTriple own;
      VoteSources src;
      for (int j = 0; j < 3; ++j) {
        own.at[size_t(j)] = random_pixel(trial, j, 98, w);
        for (int ab = 0; ab < 9; ++ab) src[size_t(j)][size_t(ab)] = random_pixel(trial, j, ab + 20, w);
      }
      float rgb[3], medoid[3];
      vote_color(*table, pw, 1, own, src, rgb);
      output_color(*table, own, pw, ColorRule::kMedoid, medoid);
      auto d2 = [&](const float* c) {
        return (c[0] - medoid[0]) * (c[0] - medoid[0]) + (c[1] - medoid[1]) * (c[1] - medoid[1]) + (c[2] - medoid[2]) * (c[2] - medoid[2]);
      };
      bool voted = false;
      float nearest = 1e9f;
      for (int j = 0; j < 3; ++j) {
        if (raw[size_t(j)] == 0.f) continue;
        for (int ab = 0; ab < 9; ++ab) {
          const ExemplarPixel s = src[size_t(j)][size_t(ab)];
          const float* c = e.plane(Plane(j)).wrapped(s.x - (ab % 3 - 1), s.y - (ab / 3 - 1));
          voted = voted || same_rgb(rgb, c);
          nearest = std::min(nearest, d2(c));
        }
      }
      ASSERT_TRUE(voted) << "trial " << trial;
      // 27 random pixels of three images rarely coincide; when they do, two votes may beat distance.
      EXPECT_LE(d2(rgb), nearest + 1.f / kVoteColorPull + 1e-6f) << "trial " << trial;
    }
  }
}

// The support of a voxel under the identity frame: the voxel and its 18 face and edge
// neighbours (the three planes' 3x3 steps), no corner; sorted and distinct for any target.
TEST(PatchVote, SupportIsTheTargetAndItsCandidateOffsets) {
  const ConstantField identity(Quat{});
  const FrameStencils frames = FrameStencils::make(identity, 5, 2, 1).value();
  const std::vector<Voxel> one = vote_support({Voxel{5, -3, 7}}, frames, PyramidLevel{1});
  ASSERT_EQ(one.size(), 19u);
  for (const Voxel& v : one) {
    const int nonzero = (v.x != 5) + (v.y != -3) + (v.z != 7);
    EXPECT_LE(nonzero, 2);
    EXPECT_LE(std::abs(v.x - 5) + std::abs(v.y + 3) + std::abs(v.z - 7), 2);
  }
  std::vector<Voxel> plane;
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 30; ++x) plane.push_back({x, y, 0});
  const std::vector<Voxel> s = vote_support(plane, frames, PyramidLevel{1});
  EXPECT_TRUE(std::is_sorted(s.begin(), s.end()));
  EXPECT_EQ(std::set<Voxel>(s.begin(), s.end()).size(), s.size());
  // z = 0: the plane grown by xy's 3x3 steps (32 x 22); z = +-1: grown along y by yz's steps
  // (30 x 22) or along x by zx's (32 x 20), whose union has 660 + 640 - 600 voxels.
  EXPECT_EQ(s.size(), size_t(32 * 22 + 2 * (30 * 22 + 32 * 20 - 30 * 20)));
}

}  // namespace
}  // namespace solidtex
