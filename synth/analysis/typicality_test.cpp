#include "analysis/typicality.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace solidtex {
namespace {

// Rows of 2 coefficients: `flat` copies of the mean (0, 0) and the four points (+-a, 0), (0, +-b).
std::vector<float> two_dim_cloud(int flat, float a, float b) {
  std::vector<float> v;
  for (int i = 0; i < flat; ++i) v.insert(v.end(), {0.f, 0.f});
  v.insert(v.end(), {a, 0.f, -a, 0.f, 0.f, b, 0.f, -b});
  return v;
}

TEST(Typicality, PenaltyIsLargestAtTheMeanAndZeroAtTheMostDistinctivePixel) {
  const std::vector<float> v = two_dim_cloud(6, 10.f, 1.f);
  const std::vector<float> pen = typicality_penalty(v, 2);
  ASSERT_EQ(pen.size(), 10u);
  for (float p : pen) EXPECT_GE(p, 0.f);
  EXPECT_EQ(*std::min_element(pen.begin(), pen.end()), 0.f);
  // The mean-like (flat) pixels carry the largest penalty, all equal.
  for (int i = 0; i < 6; ++i) EXPECT_EQ(pen[size_t(i)], *std::max_element(pen.begin(), pen.end()));
  // Symmetric points are penalised alike.
  EXPECT_EQ(pen[6], pen[7]);
  EXPECT_EQ(pen[8], pen[9]);
}

TEST(Typicality, CoefficientsAreHalfWhitened) {
  // Coefficient 0 spreads 10x wider than coefficient 1 (100x the variance). Unweighted, a
  // pixel far out on coefficient 0 (a brightness extreme) would be 100x as distinctive as one
  // equally far, in its own spread, on coefficient 1; whitened, equal; half-whitened, 10x.
  const std::vector<float> v = two_dim_cloud(6, 10.f, 1.f);
  const std::vector<float> pen = typicality_penalty(v, 2);
  const double top = pen[0];
  const double e_a = top - pen[6], e_b = top - pen[8];
  ASSERT_GT(e_b, 0.0);
  EXPECT_NEAR(e_a / e_b, 10.0, 1e-3);
}

TEST(Typicality, ConstantCoefficientsAndEmptyInputAreHarmless) {
  std::vector<float> v = {1.f, 5.f, 2.f, 5.f, 3.f, 5.f};  // coefficient 1 never varies
  const std::vector<float> pen = typicality_penalty(v, 2);
  ASSERT_EQ(pen.size(), 3u);
  for (float p : pen) EXPECT_TRUE(std::isfinite(p));
  EXPECT_GT(pen[1], pen[0]);  // the middle pixel is the mean
  EXPECT_EQ(pen[0], pen[2]);
  EXPECT_TRUE(typicality_penalty({}, 4).empty());
  const std::vector<float> same(12, 0.5f);  // every pixel alike: nothing is distinctive
  for (float p : typicality_penalty(same, 3)) EXPECT_EQ(p, 0.f);
}

}  // namespace
}  // namespace solidtex
