#include "analysis/exemplar.h"

#include <gtest/gtest.h>

#include <string>

#include "testkit/test_support.h"

namespace solidtex {
namespace {

bool same_pixels(const ImageF& a, const ImageF& b) {
  return a.width == b.width && a.height == b.height && a.channels == b.channels && a.pixels == b.pixels;
}

// Horizontal stripes (along x) that are not symmetric under transposition.
ImageF horizontal_stripes() {
  ImageF img(48, 32, 3);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      float* p = img.at(x, y);
      p[0] = (y / 4) % 2 ? 0.8f : 0.1f;
      p[1] = 0.3f + 0.001f * float(x);
      p[2] = 0.2f;
    }
  return img;
}

TEST(GrainLayout, AutoPutsHorizontalStripesOnGrainX) {
  ExemplarInputs in;
  in.xy = horizontal_stripes();
  std::array<float, 3> w{1.f, 1.f, 1.f};
  const Result<std::string> got = apply_grain_layout("auto", in, w);
  ASSERT_TRUE(got.is_ok()) << got.status().to_string();
  EXPECT_EQ(*got, "x");
  ASSERT_TRUE(in.yz && in.zx);
  EXPECT_TRUE(same_pixels(*in.yz, in.xy));
  EXPECT_TRUE(same_pixels(*in.zx, transposed(in.xy)));
  EXPECT_EQ(w, (std::array<float, 3>{1.f, 0.3f, 1.f}));  // end grain down-weighted
}

TEST(GrainLayout, AutoPutsVerticalStripesOnGrainY) {
  ExemplarInputs in;
  in.xy = transposed(horizontal_stripes());
  std::array<float, 3> w{1.f, 1.f, 1.f};
  EXPECT_EQ(apply_grain_layout("auto", in, w).value(), "y");
  ASSERT_TRUE(in.yz && in.zx);
  EXPECT_TRUE(same_pixels(*in.yz, transposed(in.xy)));  // stripes along world y in the yz plane
  EXPECT_TRUE(same_pixels(*in.zx, in.xy));              // end grain
  EXPECT_EQ(w, (std::array<float, 3>{1.f, 1.f, 0.3f}));
}

TEST(GrainLayout, AutoLeavesIsotropicExemplarsAndThreeImageSetsAlone) {
  std::array<float, 3> w{1.f, 1.f, 1.f};
  ExemplarInputs iso;
  iso.xy = testing::procedural(ProceduralKind::kPebbles, 64, 64);
  EXPECT_EQ(apply_grain_layout("auto", iso, w).value(), "");
  EXPECT_FALSE(iso.yz || iso.zx);
  ExemplarInputs three;
  three.xy = horizontal_stripes();
  three.yz = three.xy;
  three.zx = three.xy;
  EXPECT_EQ(apply_grain_layout("auto", three, w).value(), "");
  EXPECT_EQ(w, (std::array<float, 3>{1.f, 1.f, 1.f}));
  for (const char* off : {"", "none"}) {
    ExemplarInputs striped;
    striped.xy = horizontal_stripes();
    EXPECT_EQ(apply_grain_layout(off, striped, w).value(), "");
    EXPECT_FALSE(striped.yz || striped.zx);
  }
}

TEST(GrainLayout, CrossedGivesYzAndZxTheTransposedExemplar) {
  std::array<float, 3> w{1.f, 0.5f, 1.f};
  ExemplarInputs in;
  in.xy = horizontal_stripes();
  in.mask_xy = testing::procedural(ProceduralKind::kPebbles, in.xy.width, in.xy.height);
  EXPECT_EQ(apply_grain_layout("crossed", in, w).value(), "crossed");
  ASSERT_TRUE(in.yz && in.zx && in.mask_yz && in.mask_zx);
  EXPECT_TRUE(same_pixels(*in.yz, transposed(in.xy)));
  EXPECT_TRUE(same_pixels(*in.zx, transposed(in.xy)));
  EXPECT_TRUE(same_pixels(*in.mask_yz, transposed(*in.mask_xy)));
  EXPECT_TRUE(same_pixels(*in.mask_zx, transposed(*in.mask_xy)));
  EXPECT_EQ(w, (std::array<float, 3>{1.f, 1.f, 1.f}));  // isotropic: no end grain
  ExemplarInputs three;
  three.xy = horizontal_stripes();
  three.yz = three.xy;
  three.zx = three.xy;
  EXPECT_EQ(apply_grain_layout("crossed", three, w).status().field(), "grain");
}

// Synthesis resolves init auto to scatter for crossed sets (isotropic) and to slab for other
// three-plane sets, so the set must recognise the layout, also when rebuilt from a table.
TEST(GrainLayout, ExemplarSetsRecogniseTheCrossedLayout) {
  auto set_for = [](const std::string& grain) {
    ExemplarInputs in;
    in.xy = testing::procedural(ProceduralKind::kBricks, 40, 32);
    std::array<float, 3> w{1.f, 1.f, 1.f};
    EXPECT_TRUE(apply_grain_layout(grain, in, w).is_ok());
    return ExemplarSet::create(std::move(in)).value();
  };
  const ExemplarSet crossed = set_for("crossed");
  EXPECT_TRUE(crossed.crossed());
  EXPECT_FALSE(crossed.shared());
  EXPECT_FALSE(set_for("none").crossed());
  EXPECT_FALSE(set_for("x").crossed());
  EXPECT_FALSE(set_for("y").crossed());
  const auto rebuilt = ExemplarSet::from_matching_images(
      {crossed.plane_ptr(Plane::kXY), crossed.plane_ptr(Plane::kYZ), crossed.plane_ptr(Plane::kZX)}, false);
  EXPECT_TRUE(rebuilt.value().crossed());
}

TEST(GrainLayout, ErrorsNameTheGrain) {
  std::array<float, 3> w{1.f, 1.f, 1.f};
  ExemplarInputs in;
  in.xy = horizontal_stripes();
  const Status unknown = apply_grain_layout("z", in, w).status();
  EXPECT_EQ(unknown.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(unknown.field(), "grain");
  in.yz = in.xy;
  in.zx = in.xy;
  EXPECT_EQ(apply_grain_layout("y", in, w).status().field(), "grain");
}

}  // namespace
}  // namespace solidtex
