// Tensor-aligned correction of one voxel (Zhang §4.3), and the read stencil it uses.
//
// The stencil is the single source of truth for what a correction reads: the correction
// kernel gathers exactly its taps and candidate offsets, and the dependency analysis marks
// exactly the same offsets. Both call build_stencil() with the same rotation, so reads and
// dependency sets agree bit for bit (checked by the instrumented synthesis test).
//
// Neighborhoods: for plane k with exemplar axes (first, second) and offsets i, j in
// [-N/2, N/2], the local offset has `i` on the plane's first axis and `j` on its second
// (xy: (i,j,0), yz: (0,i,j), zx: (j,0,i)); the world sample is p + R * local, in voxels of
// the level. Trilinear levels blend the 8 surrounding voxels (corners of weight exactly 0 are
// not read); the others take the nearest voxel (std::lround on each axis).
//
// Plane-wise matching (CorrectionContext::plane_wise; FinestMatch::kPlane at the finest level):
// the cost is a sum of per-plane terms, so each plane's coordinate is chosen on its own, from
// its current pixel and its sources T_k(u) - h*(a, b), the lowest term winning (equal terms
// to the smaller (y, x)). Every plane then continues a neighbour's patch in that plane. The
// sources are the nine (a, b) in {-1,0,1}^2 (FinestSources::kSquare) or the five with a = 0 or
// b = 0 (kCross, CorrectionContext::cross_sources); every candidate offset is read either way.
//
// Candidate set S(v): the voxel's current triple, plus for every plane k and in-plane step
// (a, b) in {-1,0,1}^2 the N_T table candidates of plane k at T_k(u) - h*(a, b), where
// u = p + lround(R * local(a, b)) (the reduced d-set of §4.3). Matching: each plane's gathered
// N x N x C vector is projected by that plane's PCA basis; a candidate's cost is the sum over
// planes of squared distances to its stored appearance vectors, each plus `typicality` times
// the candidate pixel's typicality penalty (analysis/typicality.h: a pull away from the
// exemplar's mean appearance, against the L2 match's collapse into smooth blobs), plus `balance`
// times its usage penalty where the table has one (synthesis/usage_balance.h). Lowest cost
// wins; equal costs go to the lexicographically smallest triple. No randomness, fixed
// summation order.
//
// Voxel color: the matching color of a triple is the mean over the three planes of that
// level's Gaussian-stack color at T_k (RGB plus mask channel), weighted by the plane weights;
// the output color of a finest-level voxel is, over the original exemplars' RGB, the same mean
// or (ColorRule::kMedoid, the default) the medoid of the three pixels.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "field/frame_field.h"
#include "analysis/table.h"
#include "core/types.h"
#include "synthesis/synthesis_params.h"

namespace solidtex {

// A voxel's matching color (RGB plus mask; channels beyond the table's are 0).
using StateColor = std::array<float, 4>;

struct VoxelState {
  CoordinateTriple triple;
  StateColor color{};
};

struct Tap {
  int8_t dx, dy, dz;
  float weight;
};

struct ReadStencil {
  int n = 0;
  bool trilinear = false;
  std::vector<Tap> taps;            // taps of every sample, sample after sample
  std::vector<uint16_t> begin;      // 3*n*n + 1 offsets into taps
  std::array<std::array<std::array<int8_t, 3>, 9>, 3> candidate{};  // [plane][(b+1)*3+(a+1)]
};

void build_stencil(const Rot3& r, int n, bool trilinear, ReadStencil& out);

// Every distinct voxel offset the stencil reads, in a fixed order.
void stencil_offsets(const ReadStencil& s, std::vector<std::array<int8_t, 3>>& out);

// Colors are weighted means over the planes (weights normalised to sum to 1).
using PlaneWeights = std::array<float, 3>;
PlaneWeights normalised_weights(const std::array<float, 3>& w);
void matching_color(const TableLevel& level, const CoordinateTriple& t, int channels, const PlaneWeights& w, float* out);
// The output color of a finest-level triple under `rule` (synthesis_params.h); the medoid's
// ties go to the lowest plane index, so it is a pure function of (table, triple, weights).
// `w` are normalised weights (not all zero).
void output_color(const Table& table, const CoordinateTriple& t, const PlaneWeights& w, ColorRule rule, float rgb[3]);
// The rule `rule` stands for: kAuto is kVote on every table (one image, crossed, grain layouts:
// docs/quality.md, "Grain layouts vote"). Other rules are themselves. Stored volumes pin
// "auto", so this rule is part of their look (it changed once, for three-plane tables, from
// medoid to vote): a new rule needs a new name.
ColorRule resolved_color_rule(ColorRule rule);
// What `m` stands for on `table`: kAuto is kPlane on tables of three or more levels and
// kTriple on two-level tables (measured: docs/quality.md, "The finest level matches plane by
// plane"); the others are themselves. A function of the table only,
// so voxels stay spatially deterministic; stored volumes pin "auto", so the rule is part of
// their look: a new rule needs a new name.
FinestMatch resolved_finest_match(const Table& table, FinestMatch m);
// The typicality weight `typicality` stands for on `table`: itself when given; auto (absent)
// is kThreePlaneTypicality on tables with three planes that are not the crossed layout (grain
// layouts, three images: the slab-initialised solids of resolved_init), else kTypicality
// (synthesis_params.h). A function of the table only, so voxels stay spatially deterministic.
// Stored volumes pin "auto", so this rule is part of their look: a new rule needs a new name.
float resolved_typicality(const Table& table, std::optional<float> typicality);
// The typicality weight matching uses at level `l`: resolved_typicality(), times
// params.finest_typicality_scale at the finest level (spacing 1). A scale of 1 gives exactly
// the resolved weight, bit for bit (volumes stored before the scale restore with 1).
float level_typicality(const Table& table, PyramidLevel l, const SynthesisParams& params);

// Per-level constants of the correction, precomputed once per synthesizer.
struct CorrectionContext {
  const TableLevel* level = nullptr;
  int n = 0;
  int spacing = 1;
  int channels = 3;
  int dims = 0;                                      // PCA output dims per plane
  std::array<PcaProjection, 3> projection;           // per plane
  PlaneWeights cost_weights{1.f, 1.f, 1.f};          // per-plane matching weights
  int candidates_per_source = 64;                    // table candidates tried per source pixel
  // Each plane's coordinate chosen on its own (FinestMatch::kPlane at the finest level): the
  // table's candidate lists are not read, only each plane's sources and the current triple.
  bool plane_wise = false;
  // Plane-wise sources are the voxel and its four edge neighbours (FinestSources::kCross), not the 3x3.
  bool cross_sources = false;
  PlaneWeights color_weights{1.f / 3, 1.f / 3, 1.f / 3};
  ColorRule color_rule = ColorRule::kMedoid;         // output colors only, resolved (never kAuto)
  float typicality = 0.f;                            // level_typicality()
  // Per plane, every exemplar pixel's penalty added to its match cost: typicality times its
  // typicality penalty plus balance times its usage penalty (float ops in that order); null
  // when both weights are 0 or there is nothing to weigh. Shared by planes sharing an image.
  std::array<std::shared_ptr<const std::vector<float>>, 3> penalty;
  static CorrectionContext make(const Table& table, PyramidLevel l, const SynthesisParams& params);
};

struct CorrectionScratch {
  std::vector<float> gathered;    // 3 * n*n*channels
  std::vector<float> projected;   // 3 * dims
};

namespace detail {
void project_planes(const CorrectionContext& ctx, CorrectionScratch& s);
CoordinateTriple best_candidate(const CorrectionContext& ctx, const CoordinateTriple& current,
                                const std::array<std::array<ExemplarPixel, 9>, 3>& sources, CorrectionScratch& s);
}  // namespace detail

namespace detail {
// The 3 * N * N samples of the stencil, C channels each, sample after sample. C is a
// compile-time constant so the per-sample accumulate and store stay in registers.
template <int C, class Reader>
inline void gather_samples(const ReadStencil& st, Reader& read, float* g) {
  const int samples = 3 * st.n * st.n;
  for (int q = 0; q < samples; ++q) {
    float acc[C] = {};
    for (int t = st.begin[size_t(q)]; t < st.begin[size_t(q) + 1]; ++t) {
      const Tap& tap = st.taps[size_t(t)];
      const StateColor& v = read.color(tap.dx, tap.dy, tap.dz);
      for (int k = 0; k < C; ++k) acc[k] += tap.weight * v[size_t(k)];
    }
    for (int k = 0; k < C; ++k) g[k] = acc[k];
    g += C;
  }
}
}  // namespace detail

// Corrects one voxel. `read.color(dx, dy, dz)` and `read.triple(dx, dy, dz)` return the
// neighbour's matching color and triple at the version the history window names for that offset.
template <class Reader>
CoordinateTriple correct_voxel(const CorrectionContext& ctx, const ReadStencil& st, Reader& read, CorrectionScratch& s) {
  s.gathered.resize(size_t(3) * ctx.n * ctx.n * ctx.channels);
  float* g = s.gathered.data();
  switch (ctx.channels) {
    case 1: detail::gather_samples<1>(st, read, g); break;
    case 2: detail::gather_samples<2>(st, read, g); break;
    case 3: detail::gather_samples<3>(st, read, g); break;
    default: detail::gather_samples<4>(st, read, g); break;
  }
  detail::project_planes(ctx, s);
  const CoordinateTriple current = read.triple(0, 0, 0);
  std::array<std::array<ExemplarPixel, 9>, 3> sources;
  for (int plane = 0; plane < 3; ++plane)
    for (int ab = 0; ab < 9; ++ab) {
      const auto& o = st.candidate[size_t(plane)][size_t(ab)];
      const ExemplarPixel t = read.triple(o[0], o[1], o[2]).at[size_t(plane)];
      const int a = ab % 3 - 1, b = ab / 3 - 1;
      sources[size_t(plane)][size_t(ab)] = {t.x - ctx.spacing * a, t.y - ctx.spacing * b};
    }
  return detail::best_candidate(ctx, current, sources, s);
}

}  // namespace solidtex
