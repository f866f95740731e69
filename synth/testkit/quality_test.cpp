// The quality measures must see what users see: blur and missing variety. Energy alone cannot
// (it rewards blur); coverage and sharpness can.
#include "testkit/quality.h"

#include <gtest/gtest.h>

#include "testkit/test_support.h"

namespace solidtex {
namespace {

TEST(Quality, ACropOfTheExemplarIsAsSharpAndCoversIt) {
  const ImageF ex = testing::procedural(ProceduralKind::kSpots, 48, 48);
  const ImageF cut = toroidal_crop(ex, 7, 11, 48, 48);  // the whole exemplar, shifted (toroidal)
  EXPECT_NEAR(sharpness_ratio(cut, ex), 1.0, 0.1);
  // Not zero: the exemplar's neighborhoods across its wrap-around seam fall outside the cut.
  EXPECT_LT(coverage(cut, ex, 5, 2), 1e-3);
}

TEST(Quality, BlurIsSeenByCoverageAndSharpnessButRewardedByEnergy) {
  const ImageF ex = testing::procedural(ProceduralKind::kSpots, 48, 48);
  const ImageF sharp = toroidal_crop(ex, 7, 11, 48, 48);
  const ImageF blur = gaussian_blur(sharp, 2.0);
  EXPECT_LT(sharpness_ratio(blur, ex), 0.6);
  EXPECT_GT(coverage(blur, ex, 5, 2), 4 * coverage(sharp, ex, 5, 2));
  // The reason for the two-sided measures: a flat image (the exemplar's mean everywhere) shows
  // nothing of the exemplar, and only coverage and sharpness say so.
  ImageF flat(48, 48, 3);
  for (int c = 0; c < 3; ++c) {
    double m = 0;
    for (int64_t i = 0; i < ex.pixel_count(); ++i) m += ex.pixels[size_t(i) * 3 + size_t(c)];
    for (int64_t i = 0; i < flat.pixel_count(); ++i) flat.pixels[size_t(i) * 3 + size_t(c)] = float(m / double(ex.pixel_count()));
  }
  EXPECT_LT(sharpness_ratio(flat, ex), 0.01);
  EXPECT_GT(coverage(flat, ex, 5, 2), coverage(blur, ex, 5, 2));
  // ... while energy prefers the flat image to the blurred one: it rewards blur.
  EXPECT_LT(neighborhood_energy(flat, ex, 5, 2), neighborhood_energy(blur, ex, 5, 2));
  RecordProperty("energy_sharp", std::to_string(neighborhood_energy(sharp, ex, 5, 2)));
  RecordProperty("energy_blur", std::to_string(neighborhood_energy(blur, ex, 5, 2)));
  RecordProperty("energy_flat", std::to_string(neighborhood_energy(flat, ex, 5, 2)));
}

}  // namespace
}  // namespace solidtex
