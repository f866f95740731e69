#include "analysis/candidate_triples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "analysis/exemplar.h"
#include "analysis/gaussian_stack.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

// Eq. 4, independently of the implementation: a 3D step d moves plane j's pixel by
// (d[first_j], d[second_j]) with first = (x, y, z) and second = (y, z, x), wrapped.
CoordinateTriple shifted(CoordinateTriple t, const int d[3], const PlaneStacks& stacks) {
  static constexpr int kFirst[3] = {0, 1, 2}, kSecond[3] = {1, 2, 0};
  for (int j = 0; j < 3; ++j) {
    t.at[j].x = ImageF::wrap(t.at[j].x + d[kFirst[j]], stacks[j]->width);
    t.at[j].y = ImageF::wrap(t.at[j].y + d[kSecond[j]], stacks[j]->height);
  }
  return t;
}

// Fraction of the triples of plane k in `lists(x, y)` that some 4-neighbour's list holds,
// shifted by the same 3D step (spacing 1).
template <class Lists>
double coherent_share(const PlaneStacks& stacks, int k, int width, int height, const Lists& lists) {
  static constexpr int kFirst[3] = {0, 1, 2}, kSecond[3] = {1, 2, 0};
  static constexpr int kDeltas[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  int64_t coherent = 0, total = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (const CoordinateTriple& t : lists(x, y)) {
        ++total;
        bool hit = false;
        for (const auto& dl : kDeltas) {
          int d[3] = {0, 0, 0};
          d[kFirst[k]] = dl[0];
          d[kSecond[k]] = dl[1];
          const CoordinateTriple want = shifted(t, d, stacks);
          const auto theirs = lists(ImageF::wrap(x + dl[0], width), ImageF::wrap(y + dl[1], height));
          hit = hit || std::find(theirs.begin(), theirs.end(), want) != theirs.end();
        }
        coherent += hit;
      }
  return total ? double(coherent) / double(total) : 0.0;
}

// The mask channel (channel 3 of a 4-channel matching image) as a grey RGB image.
ImageF mask_channel(const ImageF& matching) {
  ImageF out(matching.width, matching.height, 3);
  for (int64_t i = 0; i < matching.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) out.pixels[size_t(i) * 3 + c] = matching.pixels[size_t(i) * 4 + 3];
  return out;
}

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
  // Coherence (Eq. 4): the neighbour at p + delta holds the triple shifted by delta. On a
  // 40x32 wood exemplar about a third of the stored triples are (0.37 measured); random
  // triples practically never are (checked below).
  EXPECT_GT(level->coherent_fraction, 0.25);
  EXPECT_LE(level->coherent_fraction, 1.0);
  // Recomputed from the stored lists alone: a triple coherent with a neighbour's *stored*
  // list is coherent with its longer raw list too, so this is a lower bound of the reported
  // figure, and must itself be far above chance.
  const PlaneCandidates& xy = level->planes[0];
  const double stored_share =
      coherent_share(stacks, 0, xy.width, xy.height, [&](int x, int y) { return xy.at({x, y}); });
  EXPECT_LE(stored_share, level->coherent_fraction + 1e-12);
  EXPECT_GT(stored_share, 0.15);
  // Chance level: 8 uniformly random triples per pixel.
  std::vector<CoordinateTriple> random(size_t(xy.width) * xy.height * 8);
  uint64_t h = 88172645463325252ull;
  for (CoordinateTriple& t : random)
    for (int k = 0; k < 3; ++k) {
      h ^= h << 13, h ^= h >> 7, h ^= h << 17;
      t.at[k] = {int32_t(h % uint64_t(img.width)), int32_t((h >> 32) % uint64_t(img.height))};
    }
  const double chance = coherent_share(stacks, 0, xy.width, xy.height, [&](int x, int y) {
    return std::span<const CoordinateTriple>(random.data() + (size_t(y) * xy.width + x) * 8, 8);
  });
  EXPECT_LT(chance, 0.01);
  EXPECT_GT(level->coherent_fraction, 20 * chance + 0.2);
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
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(shared.planes[k], full.planes[k]) << "plane " << k;
    // One stored list read three ways: a shared exemplar's table holds a third of the triples.
    EXPECT_EQ(shared.planes[k].triples.get(), shared.planes[0].triples.get()) << "plane " << k;
    EXPECT_EQ(shared.planes[k].rotation, k);
  }
}

TEST(CandidateTriples, PackedTriplesKeepEveryCoordinateAndRotateLikeRotatePlanes) {
  CoordinateTriple t;
  t.at = {ExemplarPixel{0, 65535}, ExemplarPixel{65535, 1}, ExemplarPixel{300, 40000}};
  const PackedTriple p = PackedTriple::pack(t);
  EXPECT_EQ(sizeof(PackedTriple), 12u);
  for (int r = 0; r < 3; ++r) EXPECT_EQ(p.unpack(r), rotate_planes(t, r)) << "rotation " << r;
  // A list read with rotation r offers rotate_planes of each stored triple, in stored order.
  const std::vector<PackedTriple> stored{p, PackedTriple::pack(rotate_planes(t, 1))};
  const CandidateList list(stored, 2);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0], rotate_planes(t, 2));
  EXPECT_EQ(list[1], rotate_planes(rotate_planes(t, 1), 2));
  std::vector<CoordinateTriple> walked(list.begin(), list.end());
  EXPECT_EQ(walked, (std::vector<CoordinateTriple>{list[0], list[1]}));
}

TEST(CandidateTriples, ThreeDifferentExemplarsAndMasksWork) {
  // Three different exemplars of different sizes, each with a feature mask (exemplar.h: the
  // mask becomes a fourth matching channel) unrelated to its colors.
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kWood, 32, 24);
  in.yz = testing::procedural(ProceduralKind::kStripes, 20, 28);
  in.zx = testing::procedural(ProceduralKind::kNoise, 26, 26);
  in.mask_xy = testing::procedural(ProceduralKind::kSpots, 32, 24, 5);
  in.mask_yz = testing::procedural(ProceduralKind::kBricks, 20, 28, 6);
  in.mask_zx = testing::procedural(ProceduralKind::kSpots, 26, 26, 7);
  in.mask_weight = 3.f;
  ExemplarInputs plain = in;
  plain.mask_xy.reset();
  plain.mask_yz.reset();
  plain.mask_zx.reset();
  auto masked_set = ExemplarSet::create(in);
  ASSERT_TRUE(masked_set.is_ok()) << masked_set.status().to_string();
  auto plain_set = ExemplarSet::create(plain);
  ASSERT_TRUE(plain_set.is_ok()) << plain_set.status().to_string();
  ASSERT_TRUE(masked_set->has_mask());
  ASSERT_EQ(masked_set->channels(), 4);
  ASSERT_FALSE(masked_set->shared());
  const PlaneStacks masked{&masked_set->plane(Plane::kXY), &masked_set->plane(Plane::kYZ),
                           &masked_set->plane(Plane::kZX)};
  const PlaneStacks colors{&plain_set->plane(Plane::kXY), &plain_set->plane(Plane::kYZ), &plain_set->plane(Plane::kZX)};

  auto level = compute_level_candidates(masked, false, 1, small_params(), 1, nullptr);
  ASSERT_TRUE(level.is_ok()) << level.status().to_string();
  auto unmasked = compute_level_candidates(colors, false, 1, small_params(), 1, nullptr);
  ASSERT_TRUE(unmasked.is_ok()) << unmasked.status().to_string();

  const int widths[3] = {32, 20, 26}, heights[3] = {24, 28, 26};
  for (int k = 0; k < 3; ++k) {
    const PlaneCandidates& pc = level->planes[k];
    ASSERT_EQ(pc.width, widths[k]);
    ASSERT_EQ(pc.height, heights[k]);
    for (int y = 0; y < pc.height; ++y)
      for (int x = 0; x < pc.width; ++x) {
        const auto list = pc.at({x, y});
        ASSERT_GT(list.size(), 0u);
        for (const CoordinateTriple& t : list) {
          ASSERT_EQ(t.at[k], (ExemplarPixel{x, y})) << "plane " << k;
          for (int j = 0; j < 3; ++j) {  // every coordinate inside its own plane's exemplar
            ASSERT_GE(t.at[j].x, 0);
            ASSERT_LT(t.at[j].x, widths[j]);
            ASSERT_GE(t.at[j].y, 0);
            ASSERT_LT(t.at[j].y, heights[j]);
          }
        }
      }
  }

  // The masks steer the search: measured on the mask channel alone, the crossbars of the
  // triples found with masks agree far better than those found from the colors alone (which
  // are at chance level for masks unrelated to the colors). Ignoring the mask channel would
  // make the two sets equal. Measured: 0.16 vs 0.57 (random triples 0.55).
  const ImageF mxy = mask_channel(*masked[0]), myz = mask_channel(*masked[1]), mzx = mask_channel(*masked[2]);
  const PlaneStacks mask_only{&mxy, &myz, &mzx};
  auto mask_error = [&](const LevelCandidates& l) {
    double sum = 0;
    int64_t n = 0;
    for (int k = 0; k < 3; ++k)
      for (int y = 0; y < l.planes[k].height; ++y)
        for (int x = 0; x < l.planes[k].width; ++x)
          for (const CoordinateTriple& t : l.planes[k].at({x, y})) {
            sum += crossbar_error(mask_only, t, 7, 1);
            ++n;
          }
    return sum / double(n);
  };
  const double with_masks = mask_error(*level), without_masks = mask_error(*unmasked);
  EXPECT_LT(with_masks, 0.5 * without_masks) << with_masks << " vs " << without_masks;
  // And the full (4-channel) crossbar error of the stored triples beats random ones.
  measure_level_candidates(masked, 7, 1, 1, *level);
  EXPECT_LT(level->mean_crossbar_error, 0.5 * level->random_crossbar_error)
      << level->mean_crossbar_error << " vs " << level->random_crossbar_error;
}

TEST(CandidateTriples, PlaneLayoutFindsTransposedPlanes) {
  const ImageF e = testing::procedural(ProceduralKind::kNoise, 24, 18);
  const ImageF et = transposed(e);
  const ImageF copy = e;
  const ImageF other = testing::procedural(ProceduralKind::kWood, 24, 18);
  EXPECT_EQ(plane_layout({&e, &e, &e}), kSharedLayout);
  EXPECT_EQ(plane_layout({&e, &copy, &copy}), kSharedLayout);  // equal pixels, distinct objects
  EXPECT_EQ(plane_layout({&e, &et, &et}), (PlaneLayout{{{0, false}, {0, true}, {0, true}}}));  // crossed
  EXPECT_EQ(plane_layout({&e, &copy, &et}), (PlaneLayout{{{0, false}, {0, false}, {0, true}}}));  // grain x
  EXPECT_EQ(plane_layout({&e, &other, &et}), (PlaneLayout{{{0, false}, {1, false}, {0, true}}}));
  EXPECT_EQ(plane_layout({&e, &other, &other}), kDistinctLayout);
}

TEST(CandidateTriples, TransposedPlanesSharingSearchesEqualSearchingEachPlane) {
  // With exact k-NN (checks above the pixel count), sharing E's lines and searches with the
  // planes that hold E transposed finds the same triples as searching those planes' own lines:
  // a transposed image's first-axis lines are its original's second-axis lines, float for float.
  const ImageF e = testing::procedural(ProceduralKind::kNoise, 22, 18, 7);
  const ImageF et = transposed(e);
  CandidateParams p = small_params();
  p.knn.checks = 100000;
  for (const PlaneStacks& stacks : {PlaneStacks{&e, &et, &et}, PlaneStacks{&e, &e, &et}, PlaneStacks{&e, &et, &e}}) {
    const PlaneLayout layout = plane_layout(stacks);
    ASSERT_NE(layout, kDistinctLayout);
    auto shared = compute_level_candidates(stacks, layout, 2, p, 3, nullptr);
    auto separate = compute_level_candidates(stacks, kDistinctLayout, 2, p, 3, nullptr);
    ASSERT_TRUE(shared.is_ok() && separate.is_ok());
    for (int k = 0; k < 3; ++k) EXPECT_EQ(shared->planes[k], separate->planes[k]) << "plane " << k;
    EXPECT_EQ(shared->coherent_fraction, separate->coherent_fraction);
  }
}

TEST(CandidateTriples, CancellationStopsTheSearch) {
  ImageF img = testing::procedural(ProceduralKind::kNoise, 32, 32);
  auto r = compute_level_candidates({&img, &img, &img}, true, 1, small_params(), 1, [](double) { return true; });
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace solidtex
