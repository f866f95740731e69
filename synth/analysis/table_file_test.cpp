#include "analysis/table_file.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "analysis/analysis.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

std::shared_ptr<const Table> small_table(bool with_mask) {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kBricks, 24, 20);
  if (with_mask) {
    in.yz = testing::procedural(ProceduralKind::kWood, 16, 16);
    in.zx = testing::procedural(ProceduralKind::kStripes, 16, 24);
    in.mask_xy = testing::procedural(ProceduralKind::kNoise, 24, 20);
    in.mask_yz = testing::procedural(ProceduralKind::kNoise, 16, 16);
    in.mask_zx = testing::procedural(ProceduralKind::kNoise, 16, 24);
  }
  AnalysisParams p;
  p.levels = 2;
  p.neighborhood = 5;
  p.candidates = 4;
  p.pca_dims = 6;
  auto set = ExemplarSet::create(std::move(in)).value();
  return analyze(set, p).value().table;
}

TEST(TableFile, RoundTripIsExact) {
  for (bool mask : {false, true}) {
    auto t = small_table(mask);
    auto bytes = encode_table(*t);
    auto back = decode_table(bytes);
    ASSERT_TRUE(back.is_ok()) << back.status().to_string();
    EXPECT_EQ(encode_table(**back), bytes);
    EXPECT_EQ((*back)->params(), t->params());
    EXPECT_EQ((*back)->exemplars().has_mask(), mask);
    for (int l = 0; l < t->levels(); ++l)
      for (int k = 0; k < 3; ++k) {
        const auto& a = t->level(PyramidLevel{l});
        const auto& b = (*back)->level(PyramidLevel{l});
        EXPECT_EQ(a.candidates->planes[k], b.candidates->planes[k]);
        EXPECT_EQ(a.planes[k]->projected, b.planes[k]->projected);  // derived data reproduced
        EXPECT_EQ(a.planes[k]->stack, b.planes[k]->stack);
      }
  }
}

// Usage penalties (version 3) come back bit for bit; a table without them is still written as
// version 2, which older builds read.
TEST(TableFile, UsagePenaltiesRoundTripAndTablesWithoutThemStayVersion2) {
  for (bool mask : {false, true}) {
    auto t = small_table(mask);
    EXPECT_FALSE(t->has_usage());
    EXPECT_EQ(encode_table(*t)[8], 2);
    UsagePenalties usage(size_t(t->levels()));
    for (int l = 0; l < t->levels(); ++l)
      for (int k = 0; k < t->distinct_images(); ++k) {
        auto& u = usage[size_t(l)].emplace_back(size_t(t->level(PyramidLevel{l}).planes[size_t(k)]->stack.pixel_count()));
        for (size_t i = 0; i < u.size(); ++i) u[i] = 0.25f * float((i * 7 + size_t(l) + size_t(k)) % 13);
      }
    auto with = t->with_usage(usage);
    ASSERT_TRUE(with.is_ok()) << with.status().to_string();
    ASSERT_TRUE((*with)->has_usage());
    auto bytes = encode_table(**with);
    EXPECT_EQ(bytes[8], kTableFormatVersion);
    auto back = decode_table(bytes);
    ASSERT_TRUE(back.is_ok()) << back.status().to_string();
    EXPECT_EQ((*back)->usage(), usage);
    EXPECT_EQ(encode_table(**back), bytes);
    // Planes sharing an image share its penalties.
    const auto& level = (*back)->level(PyramidLevel{0});
    EXPECT_EQ(level.planes[1]->usage, level.planes[mask ? 1 : 0]->usage);
    // Wrong sizes and negative values are refused, naming what is wrong.
    auto bad = usage;
    bad[0][0].pop_back();
    EXPECT_EQ(t->with_usage(bad).status().code(), StatusCode::kCorrupt);
    bad = usage;
    bad[0][0][3] = -1.f;
    EXPECT_NE(t->with_usage(bad).status().message().find(">= 0"), std::string::npos);
  }
}

TEST(TableFile, DamagedFilesFailCleanly) {
  auto bytes = encode_table(*small_table(false));
  // Truncations at many points, including inside the header.
  for (size_t cut : {size_t(0), size_t(5), size_t(31), size_t(32), bytes.size() / 2, bytes.size() - 1}) {
    std::vector<uint8_t> t(bytes.begin(), bytes.begin() + cut);
    auto r = decode_table(t);
    ASSERT_FALSE(r.is_ok()) << cut;
    EXPECT_EQ(r.status().code(), StatusCode::kCorrupt) << r.status().to_string();
  }
  // A flipped bit anywhere in the payload is caught by the checksum.
  for (size_t at : {size_t(40), bytes.size() / 3, bytes.size() - 2}) {
    auto c = bytes;
    c[at] ^= 0x10;
    auto r = decode_table(c);
    EXPECT_EQ(r.status().code(), StatusCode::kCorrupt) << at;
    EXPECT_NE(r.status().message().find("checksum"), std::string::npos);
  }
  // Another format version is refused with a message that says so.
  auto v = bytes;
  v[8] = uint8_t(kTableFormatVersion + 1);
  auto r = decode_table(v);
  EXPECT_EQ(r.status().code(), StatusCode::kVersionMismatch);
  EXPECT_NE(r.status().message().find("version"), std::string::npos);
  auto magic = bytes;
  magic[0] = 'X';
  EXPECT_EQ(decode_table(magic).status().code(), StatusCode::kCorrupt);
}

TEST(TableFile, SaveAndLoadThroughTheFileSystem) {
  auto t = small_table(false);
  const std::string path = (std::filesystem::temp_directory_path() / "solidtex_table_test.stx").string();
  ASSERT_TRUE(save_table(path, *t).is_ok());
  auto back = load_table(path);
  ASSERT_TRUE(back.is_ok());
  EXPECT_EQ(encode_table(**back), encode_table(*t));
  EXPECT_EQ(load_table(path + ".missing").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace solidtex
