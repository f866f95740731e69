// Per-region exemplars (Zhang Fig. 15; Gorla's multitexturing): a volume made of several
// solid textures, one per region, with a label function choosing the region of each finest
// voxel (by its centre). Each region is synthesized by its own Synthesizer as if it filled
// space, and a voxel takes the color of its region's texture. So every voxel, including those
// next to a region boundary, is exactly what its region's synthesizer alone gives: spatially
// deterministic, whatever the request. Thread-safe like Synthesizer.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mesh/mesh_distance.h"
#include "synthesis/synthesizer.h"

namespace solidtex {

struct RegionLabel {
  enum class Kind { kHalfSpace, kBox, kSurfaceShell };
  Kind kind = Kind::kHalfSpace;
  WorldPoint normal{1, 0, 0};  // half-space: label 1 where normal . p >= offset, else 0
  double offset = 0;
  WorldPoint min, max;         // box: label 1 inside [min, max], else 0
  double distance = 0;         // surface shell: label 1 within `distance` of the surface, else 0
  std::shared_ptr<const SurfaceDistance> surface;  // required by kSurfaceShell (set after parse)

  int label_of(const WorldPoint& p) const;
  // "halfspace:NX,NY,NZ,D", "box:X0,Y0,Z0,X1,Y1,Z1" or "surface:D" (world units); a surface
  // label still needs its `surface` (a placed mesh) before use.
  static Result<RegionLabel> parse(const std::string& spec);
};

class RegionVolume {
 public:
  // regions[k] synthesizes label k; the label function yields 0 or 1, so two regions.
  static Result<std::shared_ptr<RegionVolume>> create(std::vector<std::shared_ptr<Synthesizer>> regions,
                                                      RegionLabel label);
  // Linear RGB per target sample; `stats` (optional) receives one entry per region.
  Result<std::vector<std::array<float, 3>>> synthesize(const TargetSet& target,
                                                       Interrupter& interrupter = null_interrupter(),
                                                       std::vector<SynthesisStats>* stats = nullptr,
                                                       const SynthesisOptions& options = {});

 private:
  std::vector<std::shared_ptr<Synthesizer>> regions_;
  RegionLabel label_;
};

}  // namespace solidtex
