#include "analysis/pca.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace solidtex {
namespace {

constexpr int kDims = 8;
constexpr int kCount = 600;
// Standard deviations along the hidden directions, most significant first.
constexpr std::array<double, kDims> kSigma = {10, 4, 1.6, 0.7, 0.3, 0.12, 0.05, 0.02};

// A small deterministic generator (the same numbers on every platform).
struct Lcg {
  uint64_t s;
  double uniform() {  // [-1, 1)
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return double(s >> 11) / double(uint64_t(1) << 53) * 2.0 - 1.0;
  }
};

struct Synthetic {
  std::array<std::array<double, kDims>, kDims> dirs{};  // orthonormal rows
  std::array<double, kDims> offset{};
  std::vector<float> samples;  // kCount x kDims
  std::array<double, kDims> mean{};
};

Synthetic make_data(uint64_t seed) {
  Synthetic d;
  Lcg rng{seed};
  // Gram-Schmidt on random vectors: a generic orthonormal frame, no axis-aligned shortcut.
  for (int r = 0; r < kDims; ++r) {
    auto& v = d.dirs[size_t(r)];
    for (double& x : v) x = rng.uniform();
    for (int q = 0; q < r; ++q) {
      double dot = 0;
      for (int i = 0; i < kDims; ++i) dot += v[size_t(i)] * d.dirs[size_t(q)][size_t(i)];
      for (int i = 0; i < kDims; ++i) v[size_t(i)] -= dot * d.dirs[size_t(q)][size_t(i)];
    }
    double n = 0;
    for (double x : v) n += x * x;
    for (double& x : v) x /= std::sqrt(n);
  }
  for (int i = 0; i < kDims; ++i) d.offset[size_t(i)] = 3.0 * rng.uniform() + 0.5 * i;
  d.samples.resize(size_t(kCount) * kDims);
  for (int s = 0; s < kCount; ++s) {
    std::array<double, kDims> x = d.offset;
    for (int r = 0; r < kDims; ++r) {
      const double c = kSigma[size_t(r)] * std::sqrt(3.0) * rng.uniform();  // unit-variance uniform
      for (int i = 0; i < kDims; ++i) x[size_t(i)] += c * d.dirs[size_t(r)][size_t(i)];
    }
    for (int i = 0; i < kDims; ++i) d.samples[size_t(s) * kDims + i] = float(x[size_t(i)]);
  }
  for (int s = 0; s < kCount; ++s)
    for (int i = 0; i < kDims; ++i) d.mean[size_t(i)] += d.samples[size_t(s) * kDims + i];
  for (double& m : d.mean) m /= kCount;
  return d;
}

const float* row(const PcaBasis& b, int r) { return &b.basis[size_t(r) * b.input_dims]; }

double dot(const float* a, const std::array<double, kDims>& b) {
  double s = 0;
  for (int i = 0; i < kDims; ++i) s += double(a[i]) * b[size_t(i)];
  return s;
}

TEST(Pca, FindsTheDominantDirectionsInOrder) {
  const Synthetic d = make_data(7);
  auto r = fit_pca(d.samples, kCount, kDims, 4);
  ASSERT_TRUE(r.is_ok()) << r.status().to_string();
  const PcaBasis& b = *r;
  EXPECT_EQ(b.input_dims, kDims);
  EXPECT_EQ(b.output_dims, 4);
  ASSERT_EQ(b.mean.size(), size_t(kDims));
  ASSERT_EQ(b.basis.size(), size_t(4 * kDims));
  // The dominant direction and the next ones, most significant first.
  for (int k = 0; k < 3; ++k)
    EXPECT_GT(std::abs(dot(row(b, k), d.dirs[size_t(k)])), 0.99) << "component " << k;
  // And not merely any direction: the dominant one is orthogonal to the second.
  EXPECT_LT(std::abs(dot(row(b, 0), d.dirs[1])), 0.05);
  // The mean is the sample mean.
  for (int i = 0; i < kDims; ++i) EXPECT_NEAR(b.mean[size_t(i)], d.mean[size_t(i)], 1e-4) << i;
}

TEST(Pca, BasisIsOrthonormalAndSignNormalised) {
  const Synthetic d = make_data(11);
  const PcaBasis b = fit_pca(d.samples, kCount, kDims, kDims).value();
  ASSERT_EQ(b.output_dims, kDims);
  for (int r = 0; r < kDims; ++r) {
    for (int s = 0; s < kDims; ++s) {
      double p = 0;
      for (int i = 0; i < kDims; ++i) p += double(row(b, r)[i]) * row(b, s)[i];
      EXPECT_NEAR(p, r == s ? 1.0 : 0.0, 1e-5) << r << " " << s;
    }
    // Largest |component| positive.
    int arg = 0;
    for (int i = 1; i < kDims; ++i)
      if (std::abs(row(b, r)[i]) > std::abs(row(b, r)[arg])) arg = i;
    EXPECT_GT(row(b, r)[arg], 0.f) << "row " << r;
  }
}

TEST(Pca, ProjectionCentresOnTheMeanAndOrdersByVariance) {
  const Synthetic d = make_data(3);
  const PcaBasis b = fit_pca(d.samples, kCount, kDims, 5).value();
  const PcaProjection p = PcaProjection::of(b);
  EXPECT_EQ(p.input_dims, kDims);
  EXPECT_EQ(p.output_dims, 5);
  std::array<float, kDims> mean{};
  for (int i = 0; i < kDims; ++i) mean[size_t(i)] = float(d.mean[size_t(i)]);
  std::array<float, 5> out{};
  p.project(mean.data(), out.data());
  for (float v : out) EXPECT_NEAR(v, 0.f, 1e-4);
  // The offset alone (mean of the generator) also projects near 0, and a step along the
  // dominant direction projects onto component 0 only.
  std::array<float, kDims> step{};
  for (int i = 0; i < kDims; ++i) step[size_t(i)] = float(d.mean[size_t(i)] + 2.0 * d.dirs[0][size_t(i)]);
  p.project(step.data(), out.data());
  EXPECT_NEAR(std::abs(out[0]), 2.0, 0.02);
  for (int r = 1; r < 5; ++r) EXPECT_NEAR(out[size_t(r)], 0.f, 0.1) << r;
  // Variance of the projected samples falls with the component index, and matches sigma^2.
  std::array<double, 5> var{};
  for (int s = 0; s < kCount; ++s) {
    p.project(&d.samples[size_t(s) * kDims], out.data());
    for (int r = 0; r < 5; ++r) var[size_t(r)] += double(out[size_t(r)]) * out[size_t(r)] / (kCount - 1);
  }
  for (int r = 0; r + 1 < 5; ++r) EXPECT_GT(var[size_t(r)], var[size_t(r) + 1]) << r;
  EXPECT_NEAR(var[0], kSigma[0] * kSigma[0], 0.15 * kSigma[0] * kSigma[0]);
}

TEST(Pca, ProjectionFollowsTheDocumentedSumBitForBit) {
  // out[r] = sum over i ascending of basis_r[i] * (in[i] - mean[i]), in float.
  const Synthetic d = make_data(5);
  const PcaBasis b = fit_pca(d.samples, kCount, kDims, 6).value();
  const PcaProjection p = PcaProjection::of(b);
  std::array<float, 6> out{};
  for (int s = 0; s < 50; ++s) {
    const float* in = &d.samples[size_t(s) * kDims];
    p.project(in, out.data());
    for (int r = 0; r < 6; ++r) {
      volatile float acc = 0.f;  // volatile: no contraction or reordering in the reference
      for (int i = 0; i < kDims; ++i) {
        const volatile float centred = in[i] - b.mean[size_t(i)];
        const volatile float term = row(b, r)[i] * centred;
        acc = acc + term;
      }
      EXPECT_EQ(out[size_t(r)], float(acc)) << "sample " << s << " output " << r;
    }
  }
}

TEST(Pca, FullProjectionPreservesDistances) {
  const Synthetic d = make_data(13);
  const PcaProjection p = PcaProjection::of(fit_pca(d.samples, kCount, kDims, kDims).value());
  std::array<float, kDims> a{}, b{};
  for (int s = 0; s + 1 < 40; ++s) {
    const float* x = &d.samples[size_t(s) * kDims];
    const float* y = &d.samples[size_t(s + 7) * kDims];
    p.project(x, a.data());
    p.project(y, b.data());
    double in = 0, outd = 0;
    for (int i = 0; i < kDims; ++i) {
      in += double(x[i] - y[i]) * (x[i] - y[i]);
      outd += double(a[size_t(i)] - b[size_t(i)]) * (a[size_t(i)] - b[size_t(i)]);
    }
    EXPECT_NEAR(std::sqrt(outd), std::sqrt(in), 1e-4 * (1 + std::sqrt(in))) << s;
  }
}

TEST(Pca, FittingIsDeterministicBitForBit) {
  const Synthetic d = make_data(17);
  const PcaBasis a = fit_pca(d.samples, kCount, kDims, 5).value();
  const PcaBasis b = fit_pca(d.samples, kCount, kDims, 5).value();
  EXPECT_TRUE(a == b);
  // A different data set gives a different basis (operator== is not vacuous).
  const PcaBasis c = fit_pca(make_data(18).samples, kCount, kDims, 5).value();
  EXPECT_FALSE(a == c);
}

TEST(Pca, OutputDimsAreClampedToTheInput) {
  // pca.h: "output_dims is clamped to dims".
  const Synthetic d = make_data(19);
  const PcaBasis big = fit_pca(d.samples, kCount, kDims, kDims + 5).value();
  EXPECT_EQ(big.output_dims, kDims);
  EXPECT_EQ(big.basis.size(), size_t(kDims * kDims));
  EXPECT_TRUE(big == fit_pca(d.samples, kCount, kDims, kDims).value());
  const PcaBasis one = fit_pca(d.samples, kCount, kDims, 1).value();
  EXPECT_EQ(one.output_dims, 1);
  EXPECT_EQ(one.basis.size(), size_t(kDims));
  // Truncation keeps the leading rows unchanged.
  for (int i = 0; i < kDims; ++i) EXPECT_EQ(one.basis[size_t(i)], big.basis[size_t(i)]);
}

TEST(Pca, BadArgumentsAreInvalid) {
  const Synthetic d = make_data(23);
  auto expect_invalid = [](const Result<PcaBasis>& r, const char* what) {
    ASSERT_FALSE(r.is_ok()) << what;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument) << what;
    EXPECT_NE(r.status().message().find("sample"), std::string::npos) << what << ": " << r.status().to_string();
  };
  expect_invalid(fit_pca({}, 0, kDims, 4), "count 0");
  expect_invalid(fit_pca(std::vector<float>(d.samples.begin(), d.samples.begin() + kDims), 1, kDims, 4), "count 1");
  expect_invalid(fit_pca(d.samples, kCount + 1, kDims, 4), "samples shorter than count * dims");
  expect_invalid(fit_pca(d.samples, kCount - 1, kDims, 4), "samples longer than count * dims");
  expect_invalid(fit_pca(d.samples, kCount, 0, 4), "dims 0");
  expect_invalid(fit_pca(d.samples, -3, -kDims, 4), "negative count and dims");
}

}  // namespace
}  // namespace solidtex
