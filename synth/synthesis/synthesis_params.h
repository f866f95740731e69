// Parameters of solid synthesis: a plain struct validated once; errors name the field.
// Defaults follow Zhang et al. §6 (3 unbarriered passes at the coarsest level, grid cells of
// M = 12, s^3 = 8 subpasses) except for the passes at finer levels: one, not two, chosen by
// measurement (bench/bench_quality.py at 96^2 over the shared exemplars: median worst swd over
// Embark's 2.64 -> 2.29, lowest sharpness 0.28 -> 0.53, and about a tenth of the voxels).
// With one pass the dual-grid scheme is its grid pass; passes >= 2 add the shifted-cell passes.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "core/status.h"

namespace solidtex {

// How many table candidates per source pixel the correction considers (Zhang §4.3 uses all
// N_T). kCoherent is our shortcut: the first 4 (the best by crossbar error), plus the current
// triple; it keeps the coherent proposals that dominate the result at a third of the cost.
enum class Matcher { kPaper, kCoherent };
Result<Matcher> parse_matcher(const std::string& name);
const char* matcher_name(Matcher m);

enum class Scheme {
  kPlain,     // P plain passes, every voxel updated per step, no barriers
  kSubpass,   // P passes of s^3 subpasses, no barriers (Lefebvre-Hoppe / Dong et al.)
  kGrid,      // subpasses + grid barriers: outside p's M^3 cell, read version 0
  kDualGrid,  // ceil(P/2) grid passes, then floor(P/2) passes on cells shifted by M/2 whose
              // barrier version is the grid passes' final version (Zhang §5.3)
};

// How the coarsest level's version 0 is made (pyramid_init.h).
enum class Init {
  kAuto,     // scatter for one shared exemplar and for the crossed layout (isotropic), slab for
             // three planes (grain layouts, three images), each measured best there (docs/quality.md)
  kSlab,     // Zhang §4.1: candidate slabs (exemplar xy thickened along z) tiled per subpart;
             // in isotropic solids it leaves streaks along z in x and y cuts that one fine pass
             // does not remove; with a grain along x its slabs are planks along the grain
  kScatter,  // every coarsest voxel a hashed exemplar pixel's best candidate triple: no axis is special
};
Result<Init> parse_init(const std::string& name);
const char* init_name(Init i);

// How a finest-level voxel's output color is made from its triple's three exemplar pixels.
enum class ColorRule {
  kMean,    // the plane-weighted mean (Zhang et al.): where the three pixels disagree it is a
            // color none of them has, which blurs edges and flattens contrast
  kMedoid,  // the pixel whose plane-weighted squared color distance to the other two is least:
            // always an exemplar color (docs/quality.md: worst swd 3-10 % lower on 4 of 5 exemplars)
  kVote,    // the exemplar pixel the voxel's neighbours' patches continue into it most often
            // (synthesis/patch_vote.h): reads the final triples one step around the voxel
  kAuto,    // kVote on every table: one image, crossed, grain layouts (whose end-grain weight
            // rose to 0.3 with it), as measured (docs/quality.md, "Patch votes", "Grain layouts
            // vote"); resolved_color_rule()
};
Result<ColorRule> parse_color_rule(const std::string& name);
const char* color_rule_name(ColorRule c);

// What the finest level's correction chooses from the candidate set S(v) (correction.h).
enum class FinestMatch {
  kTriple,  // whole candidate triples (Zhang §4.3): each plane's coordinate comes with the two
            // others the table stored beside it, so a voxel continues one plane's patch and the
            // other two planes' coordinates start anew (cuts are mosaics of 1-2 voxel pieces)
  kPlane,   // each plane's coordinate on its own: the current one or a neighbour's in that plane
            // continued into the voxel, whichever matches that plane's neighbourhood best (2D
            // k-coherence in every plane). The three pixels may then disagree: the output color
            // rule (vote) picks one, and their mean, the matching color, feeds only the finest
            // level's own later passes (one by default), nothing finer
  kAuto,    // resolved_finest_match() (correction.h)
};
Result<FinestMatch> parse_finest_match(const std::string& name);
const char* finest_match_name(FinestMatch m);

// Which neighbours' patches plane-wise matching (FinestMatch::kPlane) continues into a voxel, in
// each plane besides the voxel's own pixel. Triples ignore it.
enum class FinestSources {
  kSquare,  // the 3x3 around the voxel in that plane: eight neighbours
  kCross,   // its four edge neighbours only: fewer, nearer proposals. Over nine samples the
            // stones' axis cuts 5 % better, the worst of four -1 % on average, but pebbles'
            // oblique / axis 1.17 -> 1.21, past the issue's 1.2 (docs/quality.md, "Plane-wise
            // matching from the edge neighbours only"), so it is not the default
};
Result<FinestSources> parse_finest_sources(const std::string& name);
const char* finest_sources_name(FinestSources s);

Result<Scheme> parse_scheme(const std::string& name);
const char* scheme_name(Scheme s);

// The typicality auto resolves to (resolved_typicality in correction.h): one image and the
// crossed layout (isotropic solids) take kTypicality; three planes (grain layouts, three
// images) take kThreePlaneTypicality, measured best there (docs/quality.md, "Grain layouts
// match less typically").
inline constexpr float kTypicality = 0.5f;
inline constexpr float kThreePlaneTypicality = 0.35f;
// The finest level's share of the typicality weight (SynthesisParams::finest_typicality_scale):
// 0.7 measured best there on one image (0.5 -> 0.35) and within noise on three planes
// (docs/quality.md, "The finest level matches less typically").
inline constexpr float kFinestTypicalityScale = 0.7f;

struct SynthesisParams {
  Scheme scheme = Scheme::kDualGrid;
  Matcher matcher = Matcher::kPaper;
  int coarse_passes = 3;     // plain passes at the coarsest level (never barriered), [0, 8]
  int passes = 1;            // correction passes at every finer level, [0, 8]
  int subpass_size = 2;      // s: s^3 subpasses per pass for subpass/grid schemes, {1, 2}
  // s at the finest level, {1, 2}. 1 (the default; volumes stored before restore with 2): each
  // pass is one step updating every voxel from its neighbours' previous values, so a cut's
  // finest voxels depend on the upsampled level only, not on chains of earlier subpasses. Chosen
  // by measurement (README, Speed): a 256^2 cut next to a cached one 3.9 -> 0.3 s, a cold one
  // 5.3 -> 3.9 s, worst swd at 96^2 within seed noise of s = 2 and sharper.
  int finest_subpass_size = 1;
  int cell_size = 12;        // M: grid cell side in voxels of the level, [4, 64]
  // Auto by default, chosen by measurement (docs/quality.md): isotropic solids' x and y cuts
  // lose the slabs' streaks along z; grained solids keep their slabs. Volumes pin it, and
  // volumes stored before restore with kSlab. It depends on the table only, so it is stable.
  Init init = Init::kAuto;
  // Output colors: auto by default (docs/quality.md: "Patch votes"); volumes stored before it
  // was pinned restore with kMean, volumes pinned to medoid keep it. Matching colors (the
  // coarser levels' neighbourhoods) stay plane-weighted means, so every rule has the same triples.
  ColorRule color = ColorRule::kAuto;
  // How the finest level's correction picks (FinestMatch): auto by default; volumes pin it, and
  // volumes stored before restore with kTriple (bit for bit what they were made with).
  FinestMatch finest_match = FinestMatch::kAuto;
  // Plane-wise matching's sources (FinestSources): square by default; volumes pin it.
  FinestSources finest_sources = FinestSources::kSquare;
  int init_subpart = 32;     // K: coarsest-level voxels per slab-initialisation subpart side, even, [8, 256]
  // B: the subparts' side (coarsest-level voxels) along the slabs' across-grain axis instead of
  // K, even, 0 or [8, 256]; 0 keeps K (cubic subparts). The slabs extrude the xy exemplar along
  // z; the long-grain plane they cross (zx for grain x, yz for grain y; both when the table's
  // yz and zx weigh alike) sees that extrusion as streaks, which the correction keeps wherever
  // no subpart seam lies within a neighbourhood's reach across that plane's normal (y for
  // grain x, x for grain y). Bands of 8, the default, put a seam in every coarsest
  // neighbourhood's reach there, and their seams run along the grain, so the slab plane's cuts
  // keep their grain (docs/quality.md, "Slab bands across the grain": stripes_dunes' y cut
  // 0.308 -> 0.244 swd over nine samples, its z cut 0.221 -> 0.250). Volumes pin it; volumes
  // stored before restore with 0 (bit for bit the cubic subparts). Scatter ignores it.
  int init_band = 8;
  int trilinear_levels = 2;  // the coarsest this-many levels sample neighborhoods trilinearly, [0, 8]
  uint32_t seed = 1;         // hashed with (voxel, level) wherever synthesis needs randomness
  // Relative weight of each plane (xy, yz, zx) in matching costs and voxel colors, [0, 1],
  // not all zero. Zhang §6.1: a plane whose exemplar conflicts with the others in 3D (e.g.
  // the end grain of a wood exemplar) is best given a small weight.
  std::array<float, 3> plane_weights{1.f, 1.f, 1.f};
  // Weight of the typicality penalty in matching costs (analysis/typicality.h), [0, 4]: how
  // hard matches are pulled away from the exemplar's mean appearance. 0 is plain L2 matching
  // (Zhang et al.), whose slices collapse into smooth blobs; 0.5 keeps pebbles, veins and
  // weave crisp (bench/bench_quality.py); much above 1 favours extremes and noise. Absent is
  // auto, the default: resolved_typicality() (correction.h) picks per table. Volumes pin it;
  // volumes stored before auto keep the 0.5 they pinned.
  std::optional<float> typicality;
  // The finest level's (spacing 1) typicality weight as a multiple of the resolved `typicality`,
  // [0, 1]. The finest level adds pixel-scale detail, where a strong pull away from the mean
  // appearance turns edges into speckle (gravel's dark specks, marble's vein clusters): 0.7,
  // the default, measured best (docs/quality.md, "The finest level matches less typically").
  // Volumes pin it; volumes stored before it restore with 1 (the same weight at every level).
  float finest_typicality_scale = kFinestTypicalityScale;
  // Weight of the table's usage penalties in matching costs (synthesis/usage_balance.h), [0, 4]:
  // 1 applies them as calibrated (exemplar regions the matching over-uses cost more, regions
  // it neglects less: Kopf et al.'s histogram matching as a fixed function of the table);
  // 0 ignores them. Tables analysed before usage balancing have none, so it changes nothing.
  float balance = 1.f;

  Status validate() const;
};

}  // namespace solidtex
