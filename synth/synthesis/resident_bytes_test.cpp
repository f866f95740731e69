#include "synthesis/resident_bytes.h"

#include <gtest/gtest.h>
#include <malloc.h>
#include <tbb/global_control.h>

#include <cstdlib>

#include "analysis/analysis.h"
#include "analysis/table_file.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

// Bytes the allocator has handed out and not taken back (heap and mmapped blocks). Everything
// below runs on this thread (parallelism 1), so the main arena sees every retained block.
int64_t heap_in_use() {
  const struct mallinfo2 m = mallinfo2();
  return int64_t(m.uordblks) + int64_t(m.hblkhd);
}

void expect_near_measured(int64_t counted, int64_t measured, const char* what, double slack = 8192) {
  SCOPED_TRACE(what);
  EXPECT_GT(measured, 0);
  // Within 5% and a few KiB of slack for allocator rounding and small side objects.
  EXPECT_NEAR(double(counted), double(measured), 0.05 * double(measured) + slack)
      << "counted " << counted << " bytes, the allocator holds " << measured;
}

class ResidentBytesTest : public ::testing::Test {
 protected:
  void SetUp() override { serial_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1); }
  void TearDown() override { serial_.reset(); }

  static std::vector<uint8_t> table_file(bool grain_x) {
    ExemplarInputs in;
    in.xy = testing::procedural(ProceduralKind::kWood, 40, 40);
    AnalysisParams p;
    p.levels = 3;
    p.neighborhood = 5;
    p.candidates = 4;
    p.pca_dims = 8;
    if (grain_x) {
      in.yz = in.xy;
      in.zx = transposed(in.xy);
    }
    auto set = ExemplarSet::create(std::move(in)).value();
    return encode_table(*analyze(set, p).value().table);
  }

  std::unique_ptr<tbb::global_control> serial_;
};

TEST_F(ResidentBytesTest, TableBytesAreWhatTheDecodedTableHolds) {
  for (const bool grain_x : {false, true}) {
    SCOPED_TRACE(grain_x ? "three planes" : "one shared plane");
    const std::vector<uint8_t> file = table_file(grain_x);
    malloc_trim(0);
    const int64_t before = heap_in_use();
    auto table = decode_table(file).value();
    const int64_t measured = heap_in_use() - before;
    expect_near_measured(table_resident_bytes(*table), measured, "table");
  }
}

TEST_F(ResidentBytesTest, SynthesizerStateIsWhatCreateAllocates) {
  auto table = decode_table(table_file(true)).value();
  for (const std::string spec : {"identity", "axis:0,0,1,30"}) {
    SCOPED_TRACE(spec);
    auto field = parse_field_spec(spec).value();
    SynthesisParams params;
    params.plane_weights = table->params().suggested_plane_weights;
    const int64_t before = heap_in_use();
    auto s = Synthesizer::create(table, field, params, 0).value();
    const int64_t measured = heap_in_use() - before;
    // Tens of KB in many small blocks: a looser absolute slack.
    expect_near_measured(synthesizer_state_bytes(*s), measured, "synthesizer", 16384);
  }
}

TEST_F(ResidentBytesTest, GridFieldBytesBoundItsNodes) {
  const std::array<int, 3> dims{20, 16, 12};
  std::vector<Quat> nodes(size_t(dims[0] * dims[1] * dims[2]), Quat{});
  std::vector<std::array<double, 3>> scales(nodes.size(), {0.1, 0, 0});
  const int64_t before = heap_in_use();
  auto field = QuatGridField::create({0, 0, 0}, 2.0, dims, nodes, scales).value();
  const int64_t measured = heap_in_use() - before;
  expect_near_measured(field_resident_bytes(*field), measured, "field with scales");
  EXPECT_LT(field_resident_bytes(*parse_field_spec("identity").value()), 1024);
}

TEST_F(ResidentBytesTest, VoxelCacheBytesAreWhatItHolds) {
  // Scattered bricks, one voxel each: every brick is a full allocation, nothing is shared.
  VoxelCache cache(2, int64_t(1) << 30);
  std::vector<Voxel> voxels;
  for (int i = 0; i < 400; ++i) voxels.push_back({i * 4096 - 800000, (i % 7) * 100000, -(i % 13) * 70000});
  const std::vector<CoordinateTriple> triples(voxels.size());
  const int64_t before = heap_in_use();
  cache.insert(PyramidLevel{0}, voxels, triples);
  cache.insert(PyramidLevel{1}, voxels, triples);
  const int64_t measured = heap_in_use() - before;
  const auto c = cache.counters();
  EXPECT_EQ(c.bricks, 800);
  EXPECT_EQ(c.bytes, 800 * VoxelCache::brick_bytes(1));
  expect_near_measured(c.bytes, measured, "voxel cache");
  // Eviction gives it back.
  cache.set_budget_bytes(100 * VoxelCache::brick_bytes(1));
  EXPECT_LE(cache.counters().bytes, 90 * VoxelCache::brick_bytes(1));
  EXPECT_LT(heap_in_use() - before, 100 * VoxelCache::brick_bytes(1) + 400 * 8 * 2 + 16384);
}

}  // namespace
}  // namespace solidtex
