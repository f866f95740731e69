// Output colours by patch vote (ColorRule::kVote; what kAuto, the default, resolves to on every
// table: resolved_color_rule in correction.h).
//
// Why: per-voxel k-coherence (correction.h) leaves each plane's coordinates continuing a
// neighbour's patch only about a fifth of the time, so colouring every voxel from its own
// triple (mean or medoid) makes every cut a mosaic of 1-2 voxel pieces (docs/quality.md, "Why
// cuts are mosaics"). The vote asks the neighbours which exemplar pixel their patches continue
// into the voxel, and copies the one most of them agree on, so cuts show exemplar patches.
//
// Definition, for a voxel p of level l with final triple T(p) and read stencil st (its frame):
// every plane k of non-zero colour weight and in-plane step (a, b) in {-1, 0, 1}^2 gives one
// vote, from the neighbour u = p + st.candidate[k][(a, b)] (the same offsets the correction
// draws its candidate sources from): plane k's exemplar pixel T_k(u) - spacing(l) * (a, b),
// wrapped, weighing w_k / max_j w_j (w: the normalised colour weights). Planes sharing one image
// pool their votes. The pixel whose summed weight minus kVoteColorPull times the squared RGB
// distance of its colour to p's medoid colour (output_color) is largest wins; ties go to the
// lowest (image, y, x). The output is that pixel's RGB in its plane's original exemplar: always
// an exemplar colour, a pure function of the final triples at p's 27 candidate offsets (p and
// its 18 face and edge neighbours under the identity frame) and so of (table, field,
// parameters, seed, voxel). Reads beyond the voxel's own triple are why a
// request synthesizes vote_support() of its target, not only the target.
// Thread-safety: pure functions.
#pragma once

#include <array>
#include <vector>

#include "analysis/table.h"
#include "core/types.h"
#include "synthesis/correction.h"
#include "synthesis/frame_stencils.h"

namespace solidtex {

// A vote's colour distance penalty: 2 makes a pixel 0.7 (of 1 per channel) away from the
// medoid cost as much as one full-weight vote. Measured (docs/quality.md).
inline constexpr float kVoteColorPull = 2.f;

// Plane k's neighbour pixels T_k(u) of the 9 steps, in stencil order ((b + 1) * 3 + (a + 1)).
using VoteSources = std::array<std::array<ExemplarPixel, 9>, 3>;

// The colour of a voxel with final triple `own` and neighbour pixels `sources` at a level of
// `spacing` exemplar pixels per voxel. `w`: normalised colour weights (not all zero).
void vote_color(const Table& table, const PlaneWeights& w, int spacing, const CoordinateTriple& own,
                const VoteSources& sources, float rgb[3]);

// The voxels of level `l` whose final triples the votes of `target` read: each target voxel
// plus its stencil's candidate offsets. Sorted and distinct.
std::vector<Voxel> vote_support(const std::vector<Voxel>& target, const FrameStencils& frames, PyramidLevel l);

}  // namespace solidtex
