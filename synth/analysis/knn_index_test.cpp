#include "analysis/knn_index.h"

#include <gtest/gtest.h>

#include "analysis/neighborhood.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

// Crossbar lines of a real-looking exemplar: the vectors analysis actually searches.
std::vector<float> lines_of(const ImageF& img, int n, int& dims) {
  dims = line_dims(n, img.channels);
  std::vector<float> v(size_t(img.pixel_count()) * dims);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      gather_line(img, {x, y}, LineAxis::kFirst, n, 1, &v[(size_t(y) * img.width + x) * dims]);
  return v;
}

TEST(KnnIndex, RecallAgainstExactSearchIsHigh) {
  ImageF img = testing::procedural(ProceduralKind::kWood, 64, 64);
  int dims = 0;
  std::vector<float> data = lines_of(img, 9, dims);
  const int count = img.width * img.height;
  KnnParams params;  // the defaults analysis uses
  auto index = KnnIndex::build(data.data(), count, dims, params);
  ASSERT_TRUE(index.is_ok());
  const int k = 24;
  int hits = 0, total = 0;
  std::vector<int> ai, ei;
  std::vector<float> ad, ed;
  for (int q = 0; q < count; q += 17) {
    const float* query = &data[size_t(q) * dims];
    index->search(query, k, ai, ad);
    exact_knn(data.data(), count, dims, query, k, ei, ed);
    ASSERT_EQ(ai.size(), size_t(k));
    // A hit is any returned distance within the exact k-th distance (ties are equivalent).
    for (float d : ad) hits += d <= ed.back() * (1.f + 1e-5f) + 1e-9f;
    total += k;
  }
  const double recall = double(hits) / total;
  RecordProperty("recall", std::to_string(recall));
  EXPECT_GE(recall, 0.9) << "approximate k-NN recall " << recall;
}

TEST(KnnIndex, SameSeedSameNeighbours) {
  ImageF img = testing::procedural(ProceduralKind::kNoise, 48, 40);
  int dims = 0;
  std::vector<float> data = lines_of(img, 7, dims);
  const int count = img.width * img.height;
  KnnParams params;
  params.checks = 32;  // low enough that the tree shape matters
  auto a = KnnIndex::build(data.data(), count, dims, params).value();
  auto b = KnnIndex::build(data.data(), count, dims, params).value();
  std::vector<int> ia, ib;
  std::vector<float> da, db;
  for (int q = 0; q < count; q += 7) {
    a.search(&data[size_t(q) * dims], 10, ia, da);
    b.search(&data[size_t(q) * dims], 10, ib, db);
    ASSERT_EQ(ia, ib) << q;
  }
}

TEST(KnnIndex, ExactSearchFindsItself) {
  std::vector<float> data{0, 0, 1, 1, 5, 5, 2, 2};
  std::vector<int> idx;
  std::vector<float> d;
  exact_knn(data.data(), 4, 2, &data[4], 2, idx, d);
  EXPECT_EQ(idx[0], 2);
  EXPECT_EQ(d[0], 0.f);
  EXPECT_EQ(idx[1], 3);
}

}  // namespace
}  // namespace solidtex
