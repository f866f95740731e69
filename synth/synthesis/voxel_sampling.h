// How plane cuts and points sample the finest voxels, and which sampling suits an exemplar.
//
// Nearest voxels skip and repeat along a tilted plane or surface: jaggies, which on smooth, blob-like
// exemplars cost more than anything (rotating a z cut by 37 degrees that way raised its swd
// 40-48 %, bicubically 1-4 %). Catmull-Rom resampling (target.h) removes them but attenuates
// 1-voxel detail, and a solid's cuts carry that detail where the exemplar does. Which costs
// more is a property of the exemplar: the share of its fine contrast that is 1-pixel detail
// (fine_detail_share). Measured on the ten shared exemplars (docs/quality.md, "Oblique cuts"),
// cubic made every oblique 256^2 cut with a share <= 0.40 better and every one with a share
// >= 0.46 worse, so `auto` picks cubic below kCubicMaxFineDetailShare, between the two.
//
// Everything here is a pure function of its arguments; thread-safe.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/status.h"
#include "synthesis/synthesis_params.h"

namespace solidtex {

class Table;
struct ImageF;

enum class VoxelSampling {
  kNearest,  // the voxel nearest each sample's position
  kCubic,    // Catmull-Rom resampling of the 4x4x4 voxels around it (target.h)
};

// "nearest" | "cubic" | "auto"; nullopt is auto: preferred_voxel_sampling of the volume's
// exemplar(s). Errors name `field`.
Result<std::optional<VoxelSampling>> parse_voxel_sampling(const std::string& name, const std::string& field);
const char* voxel_sampling_name(VoxelSampling s);

// e0 / (e0 + e1), where e_k is the mean square of band k of the image's Laplacian pyramid
// (2 x 2 box means, pixel-repeated upsampling, as ../shared/tools/texmetric.py builds it) over
// its sRGB-encoded RGB: the share of contrast between 1- and 4-pixel scales that lives at the
// finest. In [0, 1]; 0 for images without detail or smaller than 4 x 4.
double fine_detail_share(const ImageF& linear_rgb);
// Over a table's three planes, each plane's band energies weighted by its suggested plane
// weight (a shared or grain table: its one image's share).
double fine_detail_share(const Table& table);

inline constexpr double kCubicMaxFineDetailShare = 0.43;
// With patch-vote colours (ColorRule::kVote) cuts are exemplar patches, not single-voxel
// mosaics, and cubic resampling pays up to more detail: better on bricks (0.51) and marble
// (0.46), still worse on weave (0.59), tree_bark (0.58) and wood_grain (0.68) (docs/quality.md).
inline constexpr double kCubicMaxFineDetailShareVote = 0.55;
// kCubic when fine_detail_share(table) is below the threshold of the table's resolved colour
// rule (`color`, resolved_color_rule), else kNearest.
VoxelSampling preferred_voxel_sampling(const Table& table, ColorRule color);
// Of a volume of several tables (a region volume): kCubic only when every table prefers it,
// so that an exemplar with 1-voxel detail keeps it.
VoxelSampling preferred_voxel_sampling(const std::vector<std::shared_ptr<const Table>>& tables, ColorRule color);

}  // namespace solidtex
