// Usage balancing: per-pixel usage penalties that make synthesis use the whole exemplar.
//
// Why (issue 12): matching concentrates on a few exemplar regions (a few bricks, bright pebble
// highlights) and never picks others, so slices lose the exemplar's variety and structure.
// Kopf et al. 2007 reweight every match by histograms of what the volume has used so far, which
// makes a voxel depend on everything synthesized before it. Here the reweighting is calibrated
// once, after analysis, and stored in the table (Table::with_usage): synthesis stays a pure
// function of (table, field, parameters, seed, voxel). SynthesisParams::balance weighs it.
//
// Calibration, `rounds` times: synthesize a finest `box`^3 block (identity field, default
// parameters, calibration seed, a block position per round) with the penalties so far; at every
// level count how often the final triples the block depends on name each exemplar pixel (per
// distinct image, all planes), blur the counts (Gaussian, `sigma` * sqrt(spacing) exemplar
// pixels, wrapping: coarse levels are smooth), and add  strength * spread * log((c + m/10) / (1.1 m))
// to each pixel's penalty (c its blurred count, m the mean count, spread the image's total
// appearance variance at that level, the match cost's scale); then shift so the least is 0.
// Over-used pixels cost more, neglected ones less; all levels are updated together, so a
// round costs one block synthesis.
//
// Then, in isotropic layouts (one image for all planes, or the crossed layout), the penalties
// of the levels at spacing <= 2 (the two finest) are multiplied by `fine_gain`: structured
// exemplars keep re-using a few regions at the finer levels after calibration, and twice the
// penalty there sharpens bricks, weave and pebbles (256^2 worst-of-four swd -12 %, -12 %, -7 %)
// for marble +5 %, gravel and leopard within 1 % (docs/quality.md). Grain layouts keep gain 1:
// wood_planks' cuts got 3-8 % worse, stripes' and bark's no better.
//
// Cost: `rounds` finest-block syntheses, whatever the exemplar's size (about 1-2 s each on 2 cores).
// Deterministic: fixed seed, positions and summation order; the same bits on any thread count.
#pragma once

#include <memory>

#include "analysis/table.h"
#include "core/interrupter.h"
#include "core/status.h"
#include "synthesis/synthesis_params.h"

namespace solidtex {

struct UsageBalanceParams {
  int rounds = 3;          // calibration rounds per level, [0, 8]; 0 gives no penalties
  float strength = 0.025f; // penalty per unit of log over-use, in appearance spreads, [0, 1]
  float sigma = 3.f;       // blur of the finest level's usage counts, exemplar pixels, [0.5, 32]
  int box = 24;            // calibration block side, finest voxels, [8, 64]
  float fine_gain = 2.f;   // factor on the finer levels' penalties of isotropic layouts (above), [0.25, 4]
  Status validate() const;
};

// `table` with usage penalties calibrated as above (it must have none yet: calibration starts
// from none). Interrupted: kCancelled, progress in percent of the block syntheses.
Result<std::shared_ptr<const Table>> balance_usage(std::shared_ptr<const Table> table, const UsageBalanceParams& params = {},
                                                   Interrupter& interrupter = null_interrupter());

// The final triples of the `box`^3 block at `min` on `level` (identity field, `params`), in
// no particular order: what calibration counts, and what tests and benchmarks measure.
Result<std::vector<CoordinateTriple>> level_triples(std::shared_ptr<const Table> table, const SynthesisParams& params,
                                                    PyramidLevel level, Voxel min, int box,
                                                    Interrupter& interrupter = null_interrupter());

// How unevenly the triples name exemplar pixels: the Kullback-Leibler divergence (nats) of the
// `sigma`-blurred usage counts from uniform use, over the distinct images at `level`. 0 is
// perfectly even. For tests and benchmarks.
double usage_divergence(const Table& table, PyramidLevel level, const std::vector<CoordinateTriple>& triples, float sigma);

}  // namespace solidtex
