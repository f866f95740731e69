// The exemplar images synthesis matches against: one per sectional plane (xy, yz, zx), or a
// single image shared by all three. Each plane's *matching image* is its linear RGB plus, when
// a feature mask is given (Zhang §4: high intensity marks feature curves), one more channel
// holding mask luminance times `mask_weight`. All planes have the same channel count.
// Immutable after construction; safe to share between threads.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "core/image.h"
#include "core/status.h"
#include "core/types.h"

namespace solidtex {

inline constexpr int kMinExemplarSide = 8;
// Largest |value| of an exemplar or mask pixel (the largest half float): larger values overflow
// the squared neighborhood distances of matching to infinity.
inline constexpr float kMaxExemplarValue = 65504.f;

struct ExemplarInputs {
  ImageF xy;                          // required; linear RGB
  std::optional<ImageF> yz, zx;       // both or neither; absent means "use xy for every plane"
  std::optional<ImageF> mask_xy;      // feature masks, same size as their exemplar
  std::optional<ImageF> mask_yz, mask_zx;  // required with yz/zx when mask_xy is given
  float mask_weight = 1.0f;           // scale of the mask channel relative to color, [0, 10]
};

// The suggested plane weight of a grain layout's end-grain plane, which the exemplar cannot
// show. 0.3 since grain layouts vote (docs/quality.md, "Grain layouts vote"): with votes, every
// grain exemplar's worst cut and z cut scored better than with medoids at 0.1 (other long-grain
// cuts moved both ways: wood_planks y 0.200 -> 0.210); tables analysed before keep their 0.1.
inline constexpr float kEndGrainWeight = 0.3f;

// Grain layouts (shared by `solidtex analyze --grain` and the service's `grain` parameter).
// "x": an anisotropic exemplar whose stripes run along its x axis, for a solid whose grain
// runs along world x: xy = E, zx = E transposed (consistent in 3D), yz = E (the end grain
// the exemplar cannot show, so the returned suggested plane weights give it kEndGrainWeight).
// "y": stripes along the exemplar's y axis, grain along world y: xy = E, yz = E transposed,
// zx = E (end grain, kEndGrainWeight).
// "auto" (the default): "x" or "y" when the exemplar is strongly striped along that axis
// (orientation.h: auto_grain_layout), isotropic otherwise, and isotropic whenever yz/zx
// are given. "" and "none": isotropic, every plane the same exemplar.
// "crossed": isotropic too, xy = E and yz = zx = E transposed. Plane k's second axis is plane
// k+1's first axis, so with one image every crossbar matches the exemplar's vertical profiles
// against its horizontal ones; crossed makes two of the three crossbars compare like with
// like (no layout fixes all three), which keeps the structure of exemplars whose directions
// differ (lit stones, brick courses, weaves: docs/quality.md). Three distinct images lose the
// cyclic symmetry that lets analysis search one plane; yz and zx, holding E transposed, share
// E's searches (candidate_triples.h), so about 1.4x the analysis time.
// Returns the layout applied: "", "x", "y" or "crossed". Fails for an explicit layout with yz/zx.
Result<std::string> apply_grain_layout(const std::string& grain, ExemplarInputs& inputs,
                                       std::array<float, 3>& suggested_plane_weights);

class ExemplarSet {
 public:
  // Validates sizes and mask consistency; errors name the offending input.
  static Result<ExemplarSet> create(ExemplarInputs inputs);
  // Rebuilds a set from stored matching images (table files); `shared` if one image serves all.
  static Result<ExemplarSet> from_matching_images(std::array<std::shared_ptr<const ImageF>, 3> planes,
                                                  bool has_mask);

  const ImageF& plane(Plane p) const { return *planes_[index_of(p)]; }
  const std::shared_ptr<const ImageF>& plane_ptr(Plane p) const { return planes_[index_of(p)]; }
  // True when one image is used for all three planes (then analysis exploits the symmetry).
  bool shared() const { return planes_[0] == planes_[1] && planes_[1] == planes_[2]; }
  // The crossed layout (apply_grain_layout): yz and zx are xy transposed, pixel for pixel.
  // An isotropic set like shared(); known from the images themselves, so stored tables say it too.
  bool crossed() const { return crossed_; }
  bool has_mask() const { return has_mask_; }
  int channels() const { return planes_[0]->channels; }  // 3 or 4 (with mask)

 private:
  std::array<std::shared_ptr<const ImageF>, 3> planes_;
  bool has_mask_ = false;
  bool crossed_ = false;
};

}  // namespace solidtex
