#include "synthesis/dependency.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "field/frame_field.h"

namespace solidtex {
namespace {

struct Inputs {
  std::shared_ptr<const FrameField> field;
  FrameStencils stencils;
  std::vector<LevelSchedule> schedules;
};

Inputs make_setup(const std::string& field, Scheme scheme, int n, int levels, int passes, int cell) {
  Inputs s;
  s.field = parse_field_spec(field).value();
  SynthesisParams p;
  p.scheme = scheme;
  p.passes = passes;
  p.coarse_passes = 2;
  p.cell_size = cell;
  s.stencils = FrameStencils::make(*s.field, n, levels, p.trilinear_levels).value();
  for (int l = 0; l < levels; ++l) s.schedules.push_back(LevelSchedule::make(l, levels, p));
  return s;
}

std::vector<LevelDependencies> analyze(const Inputs& s, const TargetSet& t, VoxelCache* cache, bool per_voxel) {
  DependencyInputs in{&s.schedules, &s.stencils, cache};
  in.per_voxel = per_voxel;
  LatchedInterrupter stop(null_interrupter());
  auto r = analyze_dependencies(in, t, PyramidLevel{s.stencils.levels() - 1}, stop);
  EXPECT_TRUE(r.is_ok()) << r.status().to_string();
  return r.is_ok() ? std::move(*r) : std::vector<LevelDependencies>{};
}

// Every level's every version, voxel for voxel, and the counts the synthesizer reports.
void expect_identical(const std::vector<LevelDependencies>& a, const std::vector<LevelDependencies>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t l = 0; l < a.size(); ++l) {
    SCOPED_TRACE("level " + std::to_string(l));
    EXPECT_EQ(a[l].box.lo, b[l].box.lo);
    EXPECT_EQ(a[l].box.hi, b[l].box.hi);
    EXPECT_EQ(a[l].corrections, b[l].corrections);
    EXPECT_EQ(a[l].needed_final, b[l].needed_final);
    EXPECT_EQ(a[l].cache_hits, b[l].cache_hits);
    ASSERT_EQ(a[l].needed.size(), b[l].needed.size());
    for (size_t v = 0; v < a[l].needed.size(); ++v) {
      SCOPED_TRACE("version " + std::to_string(v));
      EXPECT_EQ(a[l].needed[v].count(), b[l].needed[v].count());
      EXPECT_EQ(a[l].needed[v].bricks(), b[l].needed[v].bricks());
      ASSERT_EQ(a[l].needed[v].to_vector(), b[l].needed[v].to_vector());
    }
  }
}

// Each coarser level's final version is asked for exactly the parents of the finer version 0.
void expect_parents_match(const std::vector<LevelDependencies>& d) {
  for (size_t l = 1; l < d.size(); ++l) {
    std::set<Voxel> parents;
    for (const Voxel& p : d[l].needed[0].to_vector()) parents.insert(parent_of(p));
    std::vector<Voxel> finals = d[l - 1].needed.back().to_vector();
    finals.insert(finals.end(), d[l - 1].cache_hits.begin(), d[l - 1].cache_hits.end());
    EXPECT_EQ(std::set<Voxel>(finals.begin(), finals.end()), parents) << "level " << l;
    EXPECT_EQ(int64_t(parents.size()), d[l - 1].needed_final) << "level " << l;
  }
}

std::vector<TargetSet> targets() {
  std::vector<TargetSet> t;
  t.push_back(TargetSet::axis_cut('z', -3, -9, 5, 13, 11).value());  // straddles brick boundaries
  t.push_back(TargetSet::axis_cut('x', 17, -20, -1, 9, 14).value());
  t.push_back(TargetSet::plane_cut({-5, 3, 2}, {0.6, 0.8, 0}, {-0.48, 0.36, 0.8}, 12, 10).value());  // oblique
  t.push_back(TargetSet::box({-7, 6, -2}, 5, 4, 6).value());
  t.push_back(TargetSet::points({{0, 0, 0}, {-31.2, 4, 9}, {40, -17.5, -8}, {7.6, 7.4, -0.4}, {-8, -8, -8}}).value());
  return t;
}

TEST(Dependency, BrickPathMatchesPerVoxelPathForEverySchemeAndTarget) {
  for (Scheme scheme : {Scheme::kPlain, Scheme::kSubpass, Scheme::kGrid, Scheme::kDualGrid}) {
    // Identity, a turned frame, and a stretched one whose offsets reach past a whole brick.
    for (const char* field : {"identity", "axis:1,2,3,37", "axis:0,1,1,20;scale:1.6,1,0.7"}) {
      const int passes = scheme == Scheme::kPlain || scheme == Scheme::kSubpass ? 1 : 2;
      const Inputs s = make_setup(field, scheme, 5, 3, passes, 6);
      ASSERT_TRUE(s.stencils.constant());
      for (const TargetSet& t : targets()) {
        SCOPED_TRACE(std::string(scheme_name(scheme)) + " " + field + " bounds " + std::to_string(t.bounds().lo.x) +
                     "," + std::to_string(t.bounds().lo.y) + "," + std::to_string(t.bounds().lo.z));
        const auto ref = analyze(s, t, nullptr, true);
        const auto got = analyze(s, t, nullptr, false);
        expect_identical(ref, got);
        expect_parents_match(got);
      }
    }
  }
}

TEST(Dependency, BrickPathMatchesPerVoxelPathWithCachedVoxels) {
  for (Scheme scheme : {Scheme::kSubpass, Scheme::kDualGrid}) {
    SCOPED_TRACE(scheme_name(scheme));
    const Inputs s = make_setup("identity", scheme, 5, 3, 2, 8);
    for (const TargetSet& t : targets()) {
      // Cache every third final voxel of the finest level and a patch of the coarser ones.
      VoxelCache cache(3, 64 << 20);
      const std::vector<LevelDependencies> cold = analyze(s, t, nullptr, true);
      for (int l = 0; l < 3; ++l) {
        std::vector<Voxel> some;
        const std::vector<Voxel> all = cold[size_t(l)].needed.back().to_vector();
        for (size_t i = 0; i < all.size(); i += 3) some.push_back(all[i]);
        cache.insert(PyramidLevel{l}, some, std::vector<CoordinateTriple>(some.size()));
      }
      const auto ref = analyze(s, t, &cache, true);
      const auto got = analyze(s, t, &cache, false);
      EXPECT_GT(ref.back().cache_hits.size(), 0u);
      expect_identical(ref, got);
      expect_parents_match(got);
    }
  }
}

TEST(Dependency, LargerStencilsAndCellsMatchToo) {
  // The paper's N = 9 with M = 12 cells (not a divisor of the brick side).
  for (Scheme scheme : {Scheme::kGrid, Scheme::kDualGrid}) {
    SCOPED_TRACE(scheme_name(scheme));
    const Inputs s = make_setup("identity", scheme, 9, 3, 2, 12);
    const TargetSet t = TargetSet::axis_cut('y', 4, -30, -20, 40, 24).value();
    expect_identical(analyze(s, t, nullptr, true), analyze(s, t, nullptr, false));
  }
}

}  // namespace
}  // namespace solidtex
