// build_stencil / stencil_offsets: the read stencil of a correction (correction.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "synthesis/correction.h"

namespace solidtex {
namespace {

using Offset = std::array<int, 3>;

// The plane's local offset for in-plane (i, j), as correction.h documents it:
// xy: (i, j, 0), yz: (0, i, j), zx: (j, 0, i).
Offset local(int plane, int i, int j) {
  switch (plane) {
    case 0: return {i, j, 0};
    case 1: return {0, i, j};
    default: return {j, 0, i};
  }
}

Offset of(const Tap& t) { return {t.dx, t.dy, t.dz}; }

// An exactly integral rotation matrix (Rot3::from_quat leaves ~1e-8 residues).
Rot3 exact(const std::array<float, 9>& m) {
  Rot3 r;
  r.m = m;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) r.inv[size_t(a * 3 + b)] = m[size_t(b * 3 + a)];
  return r;
}

// World position of sample (plane, i, j) under r, in floats as build_stencil computes it.
std::array<float, 3> world(const Rot3& r, int plane, int i, int j) {
  const Offset l = local(plane, i, j);
  const float lf[3] = {float(l[0]), float(l[1]), float(l[2])};
  std::array<float, 3> w{};
  r.apply(lf, w.data());
  return w;
}

// The sample index of (plane, i, j): planes in order, then j, then i, each in [-h, h].
int sample(int n, int plane, int i, int j) {
  const int h = n / 2;
  return plane * n * n + (j + h) * n + (i + h);
}

void expect_well_formed(const ReadStencil& s, int n, bool trilinear) {
  EXPECT_EQ(s.n, n);
  EXPECT_EQ(s.trilinear, trilinear);
  ASSERT_EQ(s.begin.size(), size_t(3 * n * n + 1));
  EXPECT_EQ(s.begin.front(), 0);
  EXPECT_EQ(size_t(s.begin.back()), s.taps.size());
  for (size_t q = 0; q + 1 < s.begin.size(); ++q) {
    const int count = s.begin[q + 1] - s.begin[q];
    EXPECT_GE(count, 1) << "sample " << q;
    EXPECT_LE(count, trilinear ? 8 : 1) << "sample " << q;
  }
}

TEST(Stencil, IdentityGivesTheAxisAlignedPlanes) {
  for (const int n : {5, 7, 9}) {
    for (const bool trilinear : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "n " << n << " trilinear " << trilinear);
      ReadStencil s;
      build_stencil(Rot3{}, n, trilinear, s);
      expect_well_formed(s, n, trilinear);
      // Integral sample positions: one tap of weight exactly 1 each, even when trilinear.
      ASSERT_EQ(s.taps.size(), size_t(3 * n * n));
      const int h = n / 2;
      for (int plane = 0; plane < 3; ++plane) {
        std::set<Offset> seen;
        for (int j = -h; j <= h; ++j)
          for (int i = -h; i <= h; ++i) {
            const int q = sample(n, plane, i, j);
            ASSERT_EQ(s.begin[size_t(q)], q);
            const Tap& t = s.taps[size_t(q)];
            EXPECT_EQ(of(t), local(plane, i, j)) << "plane " << plane << " i " << i << " j " << j;
            EXPECT_EQ(t.weight, 1.f);
            EXPECT_LE(std::abs(t.dx), h);
            EXPECT_LE(std::abs(t.dy), h);
            EXPECT_LE(std::abs(t.dz), h);
            seen.insert(of(t));
          }
        EXPECT_EQ(seen.size(), size_t(n * n)) << "plane " << plane;
        // Point symmetric, and flat along the plane's normal axis.
        const int normal = (plane + 2) % 3;
        for (const Offset& o : seen) {
          EXPECT_TRUE(seen.count({-o[0], -o[1], -o[2]}));
          EXPECT_EQ(o[size_t(normal)], 0);
        }
      }
      // Candidate offsets are the in-plane unit steps.
      for (int plane = 0; plane < 3; ++plane)
        for (int ab = 0; ab < 9; ++ab) {
          const auto& c = s.candidate[size_t(plane)][size_t(ab)];
          EXPECT_EQ((Offset{c[0], c[1], c[2]}), local(plane, ab % 3 - 1, ab / 3 - 1)) << plane << " " << ab;
        }
    }
  }
}

TEST(Stencil, QuarterTurnAboutZRotatesTheTaps) {
  // R: (x, y, z) -> (-y, x, z). The xy plane maps onto itself turned by 90 degrees, yz onto
  // the zx plane's offsets and zx onto the yz plane's.
  const Rot3 rz = exact({0, -1, 0, 1, 0, 0, 0, 0, 1});
  const int n = 7, h = n / 2;
  ReadStencil id, rot;
  build_stencil(Rot3{}, n, true, id);
  for (const bool trilinear : {false, true}) {
    SCOPED_TRACE(trilinear ? "trilinear" : "nearest");
    build_stencil(rz, n, trilinear, rot);
    expect_well_formed(rot, n, trilinear);
    ASSERT_EQ(rot.taps.size(), size_t(3 * n * n));
    std::array<std::set<Offset>, 3> sets_id, sets_rot;
    for (int plane = 0; plane < 3; ++plane)
      for (int j = -h; j <= h; ++j)
        for (int i = -h; i <= h; ++i) {
          const int q = sample(n, plane, i, j);
          const Offset l = local(plane, i, j);
          const Offset want{-l[1], l[0], l[2]};
          EXPECT_EQ(of(rot.taps[size_t(q)]), want) << "plane " << plane << " i " << i << " j " << j;
          EXPECT_EQ(rot.taps[size_t(q)].weight, 1.f);
          sets_rot[size_t(plane)].insert(of(rot.taps[size_t(q)]));
          sets_id[size_t(plane)].insert(of(id.taps[size_t(q)]));
        }
    EXPECT_EQ(sets_rot[0], sets_id[0]);
    EXPECT_EQ(sets_rot[1], sets_id[2]);
    EXPECT_EQ(sets_rot[2], sets_id[1]);
    // Two spot checks of (i, j, 0) -> (-j, i, 0).
    EXPECT_EQ(of(rot.taps[size_t(sample(n, 0, 3, 0))]), (Offset{0, 3, 0}));
    EXPECT_EQ(of(rot.taps[size_t(sample(n, 0, 0, 2))]), (Offset{-2, 0, 0}));
    // Candidates turn too: xy step (a, b) -> (-b, a, 0).
    for (int ab = 0; ab < 9; ++ab) {
      const int a = ab % 3 - 1, b = ab / 3 - 1;
      const auto& c = rot.candidate[0][size_t(ab)];
      EXPECT_EQ((Offset{c[0], c[1], c[2]}), (Offset{-b, a, 0})) << ab;
    }
  }
}

TEST(Stencil, QuarterTurnFromQuaternionMatchesTheExactOneWhenNearest) {
  // from_quat's matrix is integral only up to float rounding; nearest sampling must not care.
  const Rot3 q = Rot3::from_quat(Quat::from_axis_angle(0, 0, 1, M_PI / 2));
  const Rot3 e = exact({0, -1, 0, 1, 0, 0, 0, 0, 1});
  ReadStencil a, b;
  build_stencil(q, 9, false, a);
  build_stencil(e, 9, false, b);
  ASSERT_EQ(a.taps.size(), b.taps.size());
  for (size_t t = 0; t < a.taps.size(); ++t) EXPECT_EQ(of(a.taps[t]), of(b.taps[t])) << t;
  EXPECT_EQ(a.candidate, b.candidate);
}

TEST(Stencil, TrilinearBlendsTheSurroundingVoxelsAndNearestRoundsEachAxis) {
  const Rot3 r = Rot3::from_quat(Quat::from_axis_angle(0.3, -0.5, 0.8, 0.7));
  const int n = 9, h = n / 2;
  ReadStencil nearest, tri;
  build_stencil(r, n, false, nearest);
  build_stencil(r, n, true, tri);
  expect_well_formed(nearest, n, false);
  expect_well_formed(tri, n, true);
  EXPECT_EQ(nearest.taps.size(), size_t(3 * n * n));
  EXPECT_GT(tri.taps.size(), 4 * nearest.taps.size());  // a generic rotation hits few lattice points
  EXPECT_EQ(nearest.candidate, tri.candidate);          // candidates are always rounded
  for (int plane = 0; plane < 3; ++plane)
    for (int ab = 0; ab < 9; ++ab) {
      const auto w = world(r, plane, ab % 3 - 1, ab / 3 - 1);
      const auto& c = tri.candidate[size_t(plane)][size_t(ab)];
      EXPECT_EQ((Offset{c[0], c[1], c[2]}),
                (Offset{int(std::lround(w[0])), int(std::lround(w[1])), int(std::lround(w[2]))}))
          << plane << " " << ab;
    }
  int multi = 0;
  for (int plane = 0; plane < 3; ++plane)
    for (int j = -h; j <= h; ++j)
      for (int i = -h; i <= h; ++i) {
        const int q = sample(n, plane, i, j);
        const auto w = world(r, plane, i, j);
        // Nearest: exactly the rounded position, weight 1.
        const Tap& nt = nearest.taps[size_t(nearest.begin[size_t(q)])];
        EXPECT_EQ(of(nt), (Offset{int(std::lround(w[0])), int(std::lround(w[1])), int(std::lround(w[2]))}));
        EXPECT_EQ(nt.weight, 1.f);
        // Trilinear: corners of the enclosing cell, positive weights summing to 1, whose
        // weighted mean is the sample position; the nearest voxel is one of them.
        double sum = 0, cx = 0, cy = 0, cz = 0;
        std::set<Offset> corners;
        for (int t = tri.begin[size_t(q)]; t < tri.begin[size_t(q) + 1]; ++t) {
          const Tap& tp = tri.taps[size_t(t)];
          EXPECT_GT(tp.weight, 0.f);
          for (int a = 0; a < 3; ++a) {
            const int o = of(tp)[size_t(a)];
            EXPECT_TRUE(o == int(std::floor(w[size_t(a)])) || o == int(std::floor(w[size_t(a)])) + 1);
          }
          EXPECT_TRUE(corners.insert(of(tp)).second) << "corner read twice";
          sum += tp.weight;
          cx += tp.weight * tp.dx;
          cy += tp.weight * tp.dy;
          cz += tp.weight * tp.dz;
        }
        multi += corners.size() > 1;
        EXPECT_NEAR(sum, 1.0, 1e-5);
        EXPECT_NEAR(cx, w[0], 1e-4);
        EXPECT_NEAR(cy, w[1], 1e-4);
        EXPECT_NEAR(cz, w[2], 1e-4);
        EXPECT_TRUE(corners.count(of(nt))) << "plane " << plane << " i " << i << " j " << j;
      }
  EXPECT_GT(multi, 3 * n * n - 3 * 3);  // a generic rotation puts only the centres on lattice points
}

TEST(Stencil, ReachStaysWithinHalfWidthTimesRootTwo) {
  // |R * local| <= h*sqrt(2) for in-plane offsets, so no tap is further than ceil(h*sqrt(2))
  // on any axis (the synthesizer's reach bound, and LevelStore::Neighborhood's +-8 for n <= 11).
  const int n = 11, h = n / 2;
  const int bound = int(std::ceil(h * std::sqrt(2.0)));
  ASSERT_LE(bound, 8);
  for (int k = 0; k < 20; ++k) {
    const Rot3 r =
        Rot3::from_quat(Quat::from_axis_angle(std::sin(k * 1.3), std::cos(k * 0.7), 0.2 + k * 0.1, 0.37 * k));
    for (const bool trilinear : {false, true}) {
      ReadStencil s;
      build_stencil(r, n, trilinear, s);
      for (const Tap& t : s.taps) {
        ASSERT_LE(std::abs(t.dx), bound) << k;
        ASSERT_LE(std::abs(t.dy), bound) << k;
        ASSERT_LE(std::abs(t.dz), bound) << k;
      }
    }
  }
}

TEST(Stencil, OffsetsListEveryReadVoxelExactlyOnce) {
  const int n = 7;
  const Rot3 rots[] = {Rot3{}, exact({0, -1, 0, 1, 0, 0, 0, 0, 1}),
                       Rot3::from_quat(Quat::from_axis_angle(1, 2, 3, 0.9))};
  for (const Rot3& r : rots)
    for (const bool trilinear : {false, true}) {
      ReadStencil s;
      build_stencil(r, n, trilinear, s);
      std::vector<std::array<int8_t, 3>> offsets;
      stencil_offsets(s, offsets);
      std::set<std::array<int8_t, 3>> listed(offsets.begin(), offsets.end());
      EXPECT_EQ(listed.size(), offsets.size()) << "an offset is listed twice";
      std::set<std::array<int8_t, 3>> read;
      read.insert({0, 0, 0});  // the voxel's own current triple
      for (const Tap& t : s.taps) read.insert({t.dx, t.dy, t.dz});
      for (const auto& plane : s.candidate)
        for (const auto& o : plane) read.insert(o);
      EXPECT_EQ(listed, read);
      // A fixed order: the same stencil lists the same sequence.
      std::vector<std::array<int8_t, 3>> again{{9, 9, 9}};
      ReadStencil s2;
      build_stencil(r, n, trilinear, s2);
      stencil_offsets(s2, again);
      EXPECT_EQ(again, offsets);
    }
  // Identity: the three planes share the axis lines, so 3n^2 - 3n + 1 distinct voxels.
  ReadStencil s;
  build_stencil(Rot3{}, n, false, s);
  std::vector<std::array<int8_t, 3>> offsets;
  stencil_offsets(s, offsets);
  EXPECT_EQ(offsets.size(), size_t(3 * n * n - 3 * n + 1));
}

TEST(Stencil, OffsetsIncludeCandidateSourcesAndTheVoxelItself) {
  // correct_voxel reads read(0, 0, 0) and every candidate offset besides the taps; a
  // hand-made stencil whose candidates are not among its taps shows each is listed.
  ReadStencil s;
  s.n = 1;
  s.taps = {Tap{1, 2, 3, 0.5f}, Tap{1, 2, 3, 0.5f}, Tap{-1, 0, 0, 1.f}, Tap{0, 4, 0, 1.f}};
  s.begin = {0, 2, 3, 4};
  for (auto& plane : s.candidate)
    for (auto& o : plane) o = {2, 2, 2};
  s.candidate[1][4] = {-5, 4, 0};
  std::vector<std::array<int8_t, 3>> offsets;
  stencil_offsets(s, offsets);
  const std::set<std::array<int8_t, 3>> got(offsets.begin(), offsets.end());
  EXPECT_EQ(got.size(), offsets.size());
  EXPECT_EQ(got, (std::set<std::array<int8_t, 3>>{{0, 0, 0}, {1, 2, 3}, {-1, 0, 0}, {0, 4, 0}, {2, 2, 2}, {-5, 4, 0}}));
}

TEST(Stencil, OffsetsAreSortedAndUniqueForNarrowAndWideReaches) {
  // Narrow stencils dedup through a bitmap over their box, wide ones (box > 2^16 voxels) by
  // sorting: both give the same lexicographic order the dependency analysis relies on.
  for (const int spread : {3, 120}) {
    ReadStencil s;
    s.n = 1;
    s.taps = {Tap{int8_t(spread), int8_t(-spread), 1, 1.f}, Tap{-2, 1, int8_t(spread), 1.f},
              Tap{int8_t(-spread), 0, 0, 1.f}, Tap{-2, 1, int8_t(spread), 1.f}, Tap{0, 0, 0, 1.f}};
    s.begin = {0, 2, 4, 5};
    for (auto& plane : s.candidate)
      for (auto& o : plane) o = {1, int8_t(spread), -1};
    std::vector<std::array<int8_t, 3>> offsets{{7, 7, 7}};
    stencil_offsets(s, offsets);
    std::set<std::array<int8_t, 3>> want{{0, 0, 0}, {1, int8_t(spread), -1}};
    for (const Tap& t : s.taps) want.insert({t.dx, t.dy, t.dz});
    const std::vector<std::array<int8_t, 3>> sorted(want.begin(), want.end());
    EXPECT_EQ(offsets, sorted) << "spread " << spread;
  }
}

TEST(Stencil, BuildIsDeterministicAndReusesTheOutput) {
  const Rot3 r = Rot3::from_quat(Quat::from_axis_angle(0.2, 0.9, -0.4, 2.1), {1.5, 1, 0.5});
  ReadStencil a, b;
  build_stencil(Rot3{}, 9, true, b);  // stale content must be replaced
  build_stencil(r, 7, true, a);
  build_stencil(r, 7, true, b);
  ASSERT_EQ(a.taps.size(), b.taps.size());
  EXPECT_EQ(a.begin, b.begin);
  EXPECT_EQ(a.candidate, b.candidate);
  for (size_t t = 0; t < a.taps.size(); ++t) {
    EXPECT_EQ(of(a.taps[t]), of(b.taps[t]));
    EXPECT_EQ(a.taps[t].weight, b.taps[t].weight);
  }
}

}  // namespace
}  // namespace solidtex
