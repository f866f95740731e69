// Synthesis steered by frame fields: sketched fields turn the grain, scale fields stretch it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "field/field_file.h"
#include "field/sketch.h"
#include "field/tensor_field.h"
#include "analysis/analysis.h"
#include "analysis/exemplar.h"
#include "synthesis/synthesizer.h"
#include "testkit/quality.h"
#include "testkit/test_support.h"

namespace solidtex {
namespace {

// A small grain-x table: planes xy = yz = `xy`, zx = `zx`; 3 levels, N = 7.
std::shared_ptr<const Table> grain_table(const ImageF& xy, const ImageF& zx) {
  ExemplarInputs in;
  in.xy = xy;
  in.yz = xy;
  in.zx = zx;
  AnalysisParams ap;
  ap.levels = 3;
  ap.neighborhood = 7;
  ap.candidates = 8;
  ap.pca_dims = 12;
  // as apply_grain_layout("x") suggests: slab bands (SynthesisParams::init_band) read the layout
  // from these, so the end grain is the yz plane, as grain_params() weighs it
  ap.suggested_plane_weights = {1.f, kEndGrainWeight, 1.f};
  return analyze(ExemplarSet::create(std::move(in)).value(), ap).value().table;
}

// Synthesis parameters for grain_table(), end grain (yz) down-weighted as apply_grain_layout
// suggests.
SynthesisParams grain_params() {
  SynthesisParams sp;
  sp.coarse_passes = 2;
  sp.cell_size = 8;
  sp.init_subpart = 16;
  sp.plane_weights = {1.f, kEndGrainWeight, 1.f};
  // Two fine passes, as before the default became one: these tests measure how closely the
  // grain can follow a field. Measured over seeds 1-5, the concentric-circle median error is
  // 8.5 degrees (7.3-10.7) with two passes and 11.3 (9.3-13.4) with the default single pass.
  sp.passes = 2;
  return sp;
}

// Concentric circles around z drawn in the z = 0 plane steer a grain-x exemplar so that z-cuts
// show grain running along the circles.
TEST(TensorFieldSynthesis, ConcentricCirclesMakeTangentialGrain) {
  std::string js = R"({"domain": {"min": [-40, -40, -6], "max": [40, 40, 6], "shortest_side_cells": 6}, "curves": [)";
  for (int r : {10, 20, 30}) {
    js += r == 10 ? "" : ",";
    js += R"({"axis": "x", "plane_normal": [0, 0, 1], "points": [)";
    for (int i = 0; i <= 48; ++i) {
      const double a = 2 * M_PI * i / 48 + 0.01 * r;  // closed loop, last point near the first
      if (i == 48) break;
      js += (i ? "," : "") + std::string("[") + std::to_string(r * std::cos(a)) + "," + std::to_string(r * std::sin(a)) + ",0]";
    }
    js += "]}";
  }
  js += "]}";
  auto sketch = parse_sketch_json(js);
  ASSERT_TRUE(sketch.is_ok()) << sketch.status().to_string();
  auto field = FieldSolver::solve(*sketch).value()->field().value();

  const ImageF stripes = testing::procedural(ProceduralKind::kStripes, 48, 48);
  auto table = grain_table(stripes, transposed(stripes));
  const int side = 72;
  // The median error of one cut moves by several degrees from seed to seed (seeds 1-5 with
  // the end grain at 0.1: 9.6 / 11.0 / 6.4 / 9.2 / 6.4; at 0.3: 12.8 / 8.1 / 7.5 / 9.2 / 6.5;
  // seeds 1-3 with three-plane typicality auto, 0.35: 9.9 / 8.1 / 7.8), so the bound holds for
  // the mean over three volume seeds, not for one.
  double mean_median = 0;
  for (uint32_t seed : {1u, 2u, 3u}) {
    SynthesisParams sp = grain_params();
    sp.seed = seed;
    auto synth = Synthesizer::create(table, field, sp, 0).value();
    auto rgb = synth->synthesize(TargetSet::axis_cut('z', 0, -side / 2, -side / 2, side, side).value()).value();
    ImageF img(side, side, 3);
    for (size_t i = 0; i < rgb.size(); ++i)
      for (int c = 0; c < 3; ++c) img.pixels[i * 3 + size_t(c)] = rgb[i][size_t(c)];

    // Local grain orientation in 13x13 windows on rings of radius 12..30 versus the tangent.
    std::vector<double> errors;
    for (double r : {13.0, 18.0, 23.0, 28.0})
      for (int k = 0; k < 16; ++k) {
        const double a = 2 * M_PI * k / 16;
        const int cx = int(std::lround(side / 2 + r * std::cos(a))), cy = int(std::lround(side / 2 + r * std::sin(a)));
        ImageF win(13, 13, 3);
        for (int y = 0; y < 13; ++y)
          for (int x = 0; x < 13; ++x)
            for (int c = 0; c < 3; ++c) win.at(x, y)[c] = img.at(cx - 6 + x, cy - 6 + y)[c];
        const double grain = dominant_orientation_degrees(win);
        double tangent = std::atan2(std::cos(a), -std::sin(a)) * 180 / M_PI;
        double diff = std::fmod(std::abs(grain - tangent), 180.0);
        errors.push_back(std::min(diff, 180.0 - diff));
      }
    std::sort(errors.begin(), errors.end());
    const double median = errors[errors.size() / 2];
    RecordProperty("median_error_degrees_seed_" + std::to_string(seed), std::to_string(median));
    std::printf("concentric rings, seed %u: median error %.2f degrees\n", seed, median);
    mean_median += median / 3;
  }
  RecordProperty("mean_median_error_degrees", std::to_string(mean_median));
  EXPECT_LE(mean_median, 10.0);
}

TEST(ScaleField, ScaleTwoAlongXDoublesThePeriod) {
  // Stripes varying along x: xy = vertical stripes, zx = horizontal (x is zx's second axis).
  const ImageF horizontal = testing::procedural(ProceduralKind::kStripes, 48, 48);
  auto table = grain_table(transposed(horizontal), horizontal);
  const SynthesisParams sp = grain_params();
  auto period = [&](const char* field) {
    auto synth = Synthesizer::create(table, parse_field_spec(field).value(), sp, 0).value();
    const int w = 120, h = 12;
    auto rgb = synth->synthesize(TargetSet::axis_cut('z', 0, 0, 0, w, h).value()).value();
    ImageF img(w, h, 3);
    for (size_t i = 0; i < rgb.size(); ++i)
      for (int c = 0; c < 3; ++c) img.pixels[i * 3 + size_t(c)] = rgb[i][size_t(c)];
    return dominant_period_x(img);
  };
  const double base = period("identity");
  const double scaled = period("identity;scale:2,1,1");
  RecordProperty("period_scale_1", std::to_string(base));
  RecordProperty("period_scale_2", std::to_string(scaled));
  EXPECT_NEAR(base, 48.0 / 5.0, 48.0 / 5.0 * 0.15);  // the exemplar's own period
  // Measured: the scaled cut's period is 17.2 px at every typicality (0, 0.25, 0.5), 1.77-1.82x
  // the base; the stretch falls ~10% short of 2 whatever the matching, hence the margin.
  EXPECT_NEAR(scaled / base, 2.0, 0.25);
}

}  // namespace
}  // namespace solidtex
