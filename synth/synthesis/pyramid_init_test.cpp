#include "synthesis/pyramid_init.h"

#include <gtest/gtest.h>

#include "analysis/analysis.h"
#include "analysis/exemplar.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

// slab_subpart_sides reads the layout from the table's suggested plane weights only.
std::shared_ptr<const Table> table_weighing(std::array<float, 3> weights) {
  ExemplarInputs in;
  in.xy = testing::procedural(ProceduralKind::kStripes, 24, 24);
  AnalysisParams p;
  p.levels = 1;
  p.neighborhood = 5;
  p.candidates = 2;
  p.pca_dims = 4;
  p.suggested_plane_weights = weights;
  return analyze(ExemplarSet::create(std::move(in)).value(), p).value().table;
}

TEST(PyramidInit, SlabBandsRunAcrossTheGrainOfTheSlabPlane) {
  SynthesisParams params;
  params.init_subpart = 32;
  params.init_band = 8;
  // grain x: yz is the end grain, zx the long-grain plane the slabs cross (normal y)
  EXPECT_EQ(slab_subpart_sides(*table_weighing({1.f, kEndGrainWeight, 1.f}), params), (std::array<int, 3>{32, 8, 32}));
  // grain y: zx is the end grain, yz the crossed plane (normal x)
  EXPECT_EQ(slab_subpart_sides(*table_weighing({1.f, 1.f, kEndGrainWeight}), params), (std::array<int, 3>{8, 32, 32}));
  // yz and zx alike (one image, three equal images): both are crossed
  EXPECT_EQ(slab_subpart_sides(*table_weighing({1.f, 1.f, 1.f}), params), (std::array<int, 3>{8, 8, 32}));
  params.init_band = 0;  // cubic subparts, as volumes stored before bands restore
  EXPECT_EQ(slab_subpart_sides(*table_weighing({1.f, kEndGrainWeight, 1.f}), params), (std::array<int, 3>{32, 32, 32}));
}

TEST(PyramidInit, BandIsZeroOrAnEvenSideOfAtLeastEight) {
  for (int ok : {0, 8, 12, 256}) {
    SynthesisParams p;
    p.init_band = ok;
    EXPECT_TRUE(p.validate().is_ok()) << ok;
  }
  for (int bad : {-2, 2, 6, 9, 258}) {
    SynthesisParams p;
    p.init_band = bad;
    EXPECT_EQ(p.validate().field(), "init_band") << bad;
  }
}

}  // namespace
}  // namespace solidtex
