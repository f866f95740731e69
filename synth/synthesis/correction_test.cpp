// best_candidate's pruning (own-plane cost once per source, cheapest source first, lower-bound
// skips) must pick exactly what evaluating every candidate in full would: the same triple, for
// every plane weighting, typicality and candidate budget. Output colors: mean and medoid.
#include "synthesis/correction.h"

#include <gtest/gtest.h>

#include <limits>

#include "analysis/analysis.h"
#include "core/hash.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

std::shared_ptr<const Table> table_of(ProceduralKind kind, bool three_images) {
  ExemplarInputs in;
  in.xy = testing::procedural(kind, 40, 40);
  if (three_images) {
    in.yz = testing::procedural(ProceduralKind::kStripes, 40, 40);
    in.zx = transposed(in.xy);
  }
  AnalysisParams p;
  p.levels = 2;
  p.neighborhood = 5;
  p.candidates = 8;
  p.pca_dims = 10;
  return analyze(ExemplarSet::create(std::move(in)).value(), p).value().table;
}

// Every candidate, every plane summed in order, no pruning: the definition.
CoordinateTriple reference(const CorrectionContext& ctx, const CoordinateTriple& current,
                           const std::array<std::array<ExemplarPixel, 9>, 3>& sources, const CorrectionScratch& s) {
  const TableLevel& level = *ctx.level;
  float best = std::numeric_limits<float>::infinity();
  CoordinateTriple best_t{};
  auto consider = [&](CoordinateTriple t) {
    float cost = 0.f;
    for (int k = 0; k < 3; ++k) {
      const PlaneAppearance& app = *level.planes[size_t(k)];
      t.at[size_t(k)] = {ImageF::wrap(t.at[size_t(k)].x, app.stack.width), ImageF::wrap(t.at[size_t(k)].y, app.stack.height)};
      const size_t pixel = size_t(t.at[size_t(k)].y) * app.stack.width + size_t(t.at[size_t(k)].x);
      const float* q = s.projected.data() + size_t(k) * ctx.dims;
      const float* a = &app.projected[pixel * size_t(ctx.dims)];
      float acc[4] = {0.f, 0.f, 0.f, 0.f};
      int r = 0;
      for (; r + 4 <= ctx.dims; r += 4)
        for (int j = 0; j < 4; ++j) acc[j] += (q[r + j] - a[r + j]) * (q[r + j] - a[r + j]);
      for (; r < ctx.dims; ++r) acc[0] += (q[r] - a[r]) * (q[r] - a[r]);
      float dk = (acc[0] + acc[1]) + (acc[2] + acc[3]);
      if (ctx.typicality > 0.f) dk += ctx.typicality * app.typicality[pixel];
      cost += ctx.cost_weights[size_t(k)] * dk;
    }
    if (cost < best || (cost == best && t < best_t)) {
      best = cost;
      best_t = t;
    }
  };
  consider(current);
  for (int k = 0; k < 3; ++k) {
    const PlaneCandidates& pc = level.candidates->planes[size_t(k)];
    for (const ExemplarPixel& raw : sources[size_t(k)]) {
      const auto list = pc.at({ImageF::wrap(raw.x, pc.width), ImageF::wrap(raw.y, pc.height)});
      for (size_t c = 0; c < std::min(list.size(), size_t(ctx.candidates_per_source)); ++c) consider(list[c]);
    }
  }
  return best_t;
}

TEST(Correction, PrunedSearchPicksWhatTheFullSearchPicks) {
  int64_t cases = 0, moved = 0;
  for (const bool three : {false, true}) {
    const auto table = table_of(ProceduralKind::kPebbles, three);
    for (const float typicality : {0.f, 0.5f, 3.f})
      for (const Matcher matcher : {Matcher::kPaper, Matcher::kCoherent})
        for (const std::array<float, 3> weights : {std::array<float, 3>{1, 1, 1}, std::array<float, 3>{1, 0.1f, 0.6f}})
          for (int l = 0; l < table->levels(); ++l) {
            SynthesisParams params;
            params.typicality = typicality;
            params.matcher = matcher;
            params.plane_weights = weights;
            const CorrectionContext ctx = CorrectionContext::make(*table, PyramidLevel{l}, params);
            const int w = table->exemplars().plane(Plane::kXY).width;
            for (uint64_t trial = 0; trial < 60; ++trial) {
              auto rnd = [&](uint64_t salt) { return hash_u64(trial, salt, uint64_t(l) * 7 + (three ? 1 : 0), 0x5eed); };
              CorrectionScratch s;
              s.projected.resize(size_t(3) * ctx.dims);
              // Queries near a real pixel's appearance (so the search has a clear winner to
              // find) plus noise, and some far from everything.
              for (int k = 0; k < 3; ++k) {
                const PlaneAppearance& app = *table->level(PyramidLevel{l}).planes[size_t(k)];
                const size_t pixel = rnd(10 + k) % (app.projected.size() / size_t(ctx.dims));
                for (int r = 0; r < ctx.dims; ++r) {
                  const float noise = float(hash_unit(rnd(100 + k * 64 + r)) - 0.5) * (trial % 3 == 0 ? 4.f : 0.3f);
                  s.projected[size_t(k) * ctx.dims + r] = app.projected[pixel * size_t(ctx.dims) + r] + noise;
                }
              }
              CoordinateTriple current;
              std::array<std::array<ExemplarPixel, 9>, 3> sources;
              for (int k = 0; k < 3; ++k) {
                current.at[size_t(k)] = {int(rnd(20 + k) % uint64_t(3 * w)) - w, int(rnd(30 + k) % uint64_t(3 * w)) - w};
                for (int ab = 0; ab < 9; ++ab) {
                  // Mostly one source repeated (coherent neighbours), sometimes scattered.
                  const uint64_t h = (rnd(200 + k * 9 + ab) % 4 == 0) ? rnd(300 + k * 9 + ab) : rnd(40 + k);
                  sources[size_t(k)][size_t(ab)] = {int(h % uint64_t(w)), int((h >> 20) % uint64_t(w)) - w};
                }
              }
              const CoordinateTriple want = reference(ctx, current, sources, s);
              const CoordinateTriple got = detail::best_candidate(ctx, current, sources, s);
              ASSERT_EQ(got, want) << "level " << l << " typicality " << typicality << " trial " << trial;
              ++cases;
              moved += !(want == current);
            }
          }
  }
  EXPECT_EQ(cases, 2 * 3 * 2 * 2 * 2 * 60);
  EXPECT_GT(moved, cases / 2);  // the searches mostly pick a candidate, not the current triple
}

// Output colors: the medoid is always one of the triple's three exemplar pixels, the one whose
// weighted squared distance to the others over its own weight is least (lowest plane on ties);
// a plane of weight 0 is never output; the mean is the weighted mean.
TEST(Correction, OutputColorMedoidIsTheTriplesMostCentralExemplarPixel) {
  const auto table = table_of(ProceduralKind::kPebbles, true);
  const ExemplarSet& e = table->exemplars();
  const int w = e.plane(Plane::kXY).width;
  int64_t picked[3] = {0, 0, 0};
  for (const std::array<float, 3> raw : {std::array<float, 3>{1, 1, 1}, std::array<float, 3>{1, 1, 0.1f},
                                         std::array<float, 3>{0, 1, 1}}) {
    const PlaneWeights pw = normalised_weights(raw);
    for (uint64_t trial = 0; trial < 300; ++trial) {
      CoordinateTriple t;
      for (int k = 0; k < 3; ++k)
        t.at[size_t(k)] = {int(hash_u64(trial, k, 1, 7) % uint64_t(w)), int(hash_u64(trial, k, 2, 7) % uint64_t(w))};
      const float* px[3] = {e.plane(Plane::kXY).wrapped(t.at[0].x, t.at[0].y), e.plane(Plane::kYZ).wrapped(t.at[1].x, t.at[1].y),
                            e.plane(Plane::kZX).wrapped(t.at[2].x, t.at[2].y)};
      float mean[3], medoid[3];
      output_color(*table, t, pw, ColorRule::kMean, mean);
      output_color(*table, t, pw, ColorRule::kMedoid, medoid);
      for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(mean[c], pw[0] * px[0][c] + pw[1] * px[1][c] + pw[2] * px[2][c]);
      double spread[3];
      int want = -1;
      for (int i = 0; i < 3; ++i) {
        spread[i] = 0;
        for (int j = 0; j < 3; ++j)
          for (int c = 0; c < 3; ++c) spread[i] += pw[size_t(j)] * double(px[i][c] - px[j][c]) * double(px[i][c] - px[j][c]);
        if (pw[size_t(i)] > 0 && (want < 0 || spread[i] / pw[size_t(i)] < spread[want] / pw[size_t(want)] - 1e-9)) want = i;
      }
      int got = -1;
      for (int i = 0; i < 3 && got < 0; ++i)
        if (medoid[0] == px[i][0] && medoid[1] == px[i][1] && medoid[2] == px[i][2]) got = i;
      ASSERT_GE(got, 0) << "the medoid is not one of the triple's exemplar colors (trial " << trial << ")";
      ASSERT_GT(pw[size_t(got)], 0.f);
      // Equal colors make several planes valid answers; compare spreads, not indices.
      EXPECT_NEAR(spread[got] / pw[size_t(got)], spread[want] / pw[size_t(want)], 1e-6);
      ++picked[want];
    }
  }
  for (int i = 0; i < 3; ++i) EXPECT_GT(picked[i], 30) << "plane " << i << " is (almost) never the medoid";
}

}  // namespace
}  // namespace solidtex
