#include "analysis/orientation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/image_io.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

// Gray sinusoidal stripes whose crests run at `degrees` from x, period 8 pixels.
ImageF stripes_at(double degrees, int size = 64) {
  ImageF img(size, size, 3);
  const double a = degrees * M_PI / 180.0;
  const double nx = -std::sin(a), ny = std::cos(a);  // across the stripes
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float v = float(0.5 + 0.4 * std::sin(2 * M_PI * (nx * x + ny * y) / 8.0));
      float* p = img.at(x, y);
      p[0] = p[1] = p[2] = v;
    }
  return img;
}

TEST(StripeOrientation, FindsTheDirectionAndCoherenceOfStripes) {
  for (double deg : {0.0, 30.0, -45.0, 90.0, 75.0}) {
    SCOPED_TRACE(deg);
    const StripeOrientation o = estimate_stripe_orientation(stripes_at(deg));
    double diff = std::fmod(std::abs(o.degrees - deg), 180.0);
    diff = std::min(diff, 180.0 - diff);
    EXPECT_LT(diff, 2.0) << o.degrees;
    EXPECT_GT(o.coherence, 0.9);
  }
}

TEST(StripeOrientation, IsotropicAndBlankImagesHaveLowCoherence) {
  for (ProceduralKind kind : {ProceduralKind::kNoise, ProceduralKind::kPebbles, ProceduralKind::kSpots, ProceduralKind::kBricks})
    EXPECT_LT(estimate_stripe_orientation(testing::procedural(kind, 96, 96)).coherence, kAutoGrainMinCoherence);
  const StripeOrientation blank = estimate_stripe_orientation(ImageF(16, 16, 3));
  EXPECT_EQ(blank.coherence, 0.0);
  EXPECT_EQ(auto_grain_layout(blank), std::string());
}

TEST(StripeOrientation, AutoGrainPicksTheAxisOfStrongStripesOnly) {
  EXPECT_EQ(auto_grain_layout({5.0, 0.9}), std::string("x"));
  EXPECT_EQ(auto_grain_layout({-88.0, 0.9}), std::string("y"));
  EXPECT_EQ(auto_grain_layout({90.0, 0.9}), std::string("y"));
  EXPECT_EQ(auto_grain_layout({45.0, 0.95}), std::string());  // diagonal: no axis to put it on
  EXPECT_EQ(auto_grain_layout({0.0, 0.4}), std::string());     // weakly oriented
}

// Grain hidden under fine isotropic detail: stripes 8 px apart under +-0.6 pixel noise (at
// the pixel scale alone its coherence is about 0.3: the blurred scales find it).
TEST(StripeOrientation, SeesStripesUnderFineNoise) {
  ImageF img = stripes_at(90.0);
  uint32_t h = 12345;
  for (float& v : img.pixels) {
    h = h * 1664525u + 1013904223u;
    v += 1.2f * (float(h >> 8) / float(1 << 24) - 0.5f);
  }
  const StripeOrientation o = estimate_stripe_orientation(img);
  EXPECT_GE(o.coherence, kAutoGrainMinCoherence);
  EXPECT_EQ(auto_grain_layout(o), std::string("y")) << o.coherence << " " << o.degrees;
}

// The shared exemplars: the striped and grained ones are given a grain automatically, along
// the axis their stripes run on; the isotropic ones are not.
TEST(StripeOrientation, SharedExemplarsGetTheGrainTheyShow) {
  if (testing::exemplar_path("stripes_dunes.png").empty())
    GTEST_SKIP() << "../shared/data/exemplars is absent: real-exemplar test skipped";
  for (const char* name : {"bricks.png", "gravel.png", "leopard.png", "marble_pink.png", "pebbles.png",
                           "stripes_dunes.png", "tree_bark.png", "weave_burlap.png", "wood_grain.png", "wood_planks.png"}) {
    SCOPED_TRACE(name);
    const StripeOrientation o = estimate_stripe_orientation(load_image(testing::exemplar_path(name)).value());
    const std::string n = name;
    const char* want = n == "tree_bark.png" ? "y" : n == "stripes_dunes.png" || n.rfind("wood", 0) == 0 ? "x" : "";
    EXPECT_EQ(auto_grain_layout(o), std::string(want)) << o.coherence << " " << o.degrees;
  }
}

}  // namespace
}  // namespace solidtex
