#include "analysis/candidate_triples.h"

#include <gtest/gtest.h>

#include "analysis/gaussian_stack.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

CandidateParams small_params() {
  CandidateParams p;
  p.neighborhood = 7;
  p.candidates = 8;
  p.search_k = 16;
  return p;
}

TEST(CandidateTriples, StoredTriplesBeatRandomOnesAndContainTheirPixel) {
  ImageF img = testing::procedural(ProceduralKind::kWood, 40, 32);
  PlaneStacks stacks{&img, &img, &img};
  auto level = compute_level_candidates(stacks, true, 1, small_params(), 1, nullptr);
  ASSERT_TRUE(level.is_ok()) << level.status().to_string();
  measure_level_candidates(stacks, 7, 1, 1, *level);
  EXPECT_LT(level->mean_crossbar_error, 0.5 * level->random_crossbar_error)
      << level->mean_crossbar_error << " vs " << level->random_crossbar_error;
  EXPECT_GT(level->coherent_fraction, 0.0);
  for (int k = 0; k < 3; ++k) {
    const PlaneCandidates& pc = level->planes[k];
    for (int y = 0; y < pc.height; ++y)
      for (int x = 0; x < pc.width; ++x) {
        auto list = pc.at({x, y});
        ASSERT_EQ(list.size(), 8u);
        double prev = -1;
        for (const CoordinateTriple& t : list) {
          ASSERT_EQ(t.at[k], (ExemplarPixel{x, y}));
          double e = crossbar_error(stacks, t, 7, 1);
          EXPECT_GE(e + 1e-6, prev);  // sorted best first
          prev = e;
        }
      }
  }
}

TEST(CandidateTriples, SharedExemplarRotationEqualsSearchingEveryPlane) {
  ImageF img = testing::procedural(ProceduralKind::kStripes, 24, 20);
  ImageF a = img, b = img, c = img;  // distinct objects with equal pixels: no sharing shortcut
  auto shared = compute_level_candidates({&img, &img, &img}, true, 2, small_params(), 3, nullptr).value();
  auto full = compute_level_candidates({&a, &b, &c}, false, 2, small_params(), 3, nullptr).value();
  for (int k = 0; k < 3; ++k) EXPECT_EQ(shared.planes[k], full.planes[k]) << "plane " << k;
}

TEST(CandidateTriples, ThreeDifferentExemplarsAndMasksWork) {
  ImageF xy = testing::procedural(ProceduralKind::kWood, 32, 24);
  ImageF yz = testing::procedural(ProceduralKind::kStripes, 20, 28);
  ImageF zx = testing::procedural(ProceduralKind::kNoise, 26, 26);
  auto level = compute_level_candidates({&xy, &yz, &zx}, false, 1, small_params(), 1, nullptr);
  ASSERT_TRUE(level.is_ok());
  EXPECT_EQ(level->planes[1].width, 20);
  EXPECT_EQ(level->planes[2].height, 26);
  for (int k = 0; k < 3; ++k)
    for (const CoordinateTriple& t : level->planes[k].triples) {
      EXPECT_LT(t.at[1].x, 20);
      EXPECT_LT(t.at[1].y, 28);
    }
}

TEST(CandidateTriples, CancellationStopsTheSearch) {
  ImageF img = testing::procedural(ProceduralKind::kNoise, 32, 32);
  auto r = compute_level_candidates({&img, &img, &img}, true, 1, small_params(), 1, [](double) { return true; });
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace solidtex
