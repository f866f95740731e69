#include "analysis/exemplar.h"

#include <cmath>
#include <string>

#include "analysis/candidate_triples.h"
#include "analysis/orientation.h"

namespace solidtex {
namespace {

Status check_values(const ImageF& img, const char* field) {
  for (const float v : img.pixels)
    if (!(std::fabs(v) <= kMaxExemplarValue))  // also false for NaN
      return Status(StatusCode::kInvalidArgument,
                    "has a pixel value of " + std::to_string(v) + "; values must be finite with magnitude at most 65504",
                    field);
  return Status::ok();
}

Status check_exemplar(const ImageF& img, const char* field) {
  if (img.empty()) return Status(StatusCode::kInvalidArgument, "image is empty", field);
  if (img.channels != 3) return Status(StatusCode::kInvalidArgument, "expected linear RGB (3 channels)", field);
  if (img.width < kMinExemplarSide || img.height < kMinExemplarSide)
    return Status(StatusCode::kInvalidArgument,
                  "is " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                      "; exemplars need at least " + std::to_string(kMinExemplarSide) + " pixels per side",
                  field);
  return check_values(img, field);
}

Result<std::shared_ptr<const ImageF>> matching_image(const ImageF& rgb, const std::optional<ImageF>& mask,
                                                     float weight, const char* mask_field) {
  if (!mask) return std::make_shared<const ImageF>(rgb);
  SOLIDTEX_RETURN_IF_ERROR(check_values(*mask, mask_field));
  if (mask->width != rgb.width || mask->height != rgb.height)
    return Status(StatusCode::kInvalidArgument,
                  "is " + std::to_string(mask->width) + "x" + std::to_string(mask->height) +
                      " but its exemplar is " + std::to_string(rgb.width) + "x" + std::to_string(rgb.height),
                  mask_field);
  auto out = std::make_shared<ImageF>(rgb.width, rgb.height, 4);
  for (int64_t i = 0; i < rgb.pixel_count(); ++i) {
    const float* m = &mask->pixels[size_t(i) * mask->channels];
    float lum = mask->channels >= 3 ? 0.2126f * m[0] + 0.7152f * m[1] + 0.0722f * m[2] : m[0];
    for (int c = 0; c < 3; ++c) out->pixels[size_t(i) * 4 + c] = rgb.pixels[size_t(i) * 3 + c];
    out->pixels[size_t(i) * 4 + 3] = lum * weight;
  }
  return std::shared_ptr<const ImageF>(std::move(out));
}

}  // namespace

namespace {

bool is_crossed(const std::array<std::shared_ptr<const ImageF>, 3>& planes) {
  // A symmetric exemplar (E = E transposed) under a grain layout is not crossed (its planes
  // all equal E): it keeps slabs.
  return plane_layout({planes[0].get(), planes[1].get(), planes[2].get()}) == kCrossedLayout;
}

}  // namespace

Result<ExemplarSet> ExemplarSet::create(ExemplarInputs in) {
  SOLIDTEX_RETURN_IF_ERROR(check_exemplar(in.xy, "xy"));
  if (in.yz.has_value() != in.zx.has_value())
    return Status(StatusCode::kInvalidArgument, "give both the yz and zx exemplars or neither",
                  in.yz ? "zx" : "yz");
  if (!(in.mask_weight >= 0.f && in.mask_weight <= 10.f))
    return Status(StatusCode::kInvalidArgument, "must be in [0, 10]", "mask_weight");
  const bool three = in.yz.has_value();
  if (three) {
    SOLIDTEX_RETURN_IF_ERROR(check_exemplar(*in.yz, "yz"));
    SOLIDTEX_RETURN_IF_ERROR(check_exemplar(*in.zx, "zx"));
  }
  if (!in.mask_xy && (in.mask_yz || in.mask_zx))
    return Status(StatusCode::kInvalidArgument, "plane masks need the xy mask too", "mask");
  if (in.mask_xy && three && !(in.mask_yz && in.mask_zx))
    return Status(StatusCode::kInvalidArgument,
                  "with three exemplars, every plane needs a mask (all planes must match the same channels)",
                  in.mask_yz ? "mask_zx" : "mask_yz");
  if (in.mask_xy && !three && (in.mask_yz || in.mask_zx))
    return Status(StatusCode::kInvalidArgument, "a single exemplar takes a single mask", "mask");

  ExemplarSet set;
  set.has_mask_ = in.mask_xy.has_value();
  SOLIDTEX_ASSIGN_OR_RETURN(auto xy, matching_image(in.xy, in.mask_xy, in.mask_weight, "mask"));
  if (!three) {
    set.planes_ = {xy, xy, xy};
  } else {
    SOLIDTEX_ASSIGN_OR_RETURN(auto yz, matching_image(*in.yz, in.mask_yz, in.mask_weight, "mask_yz"));
    SOLIDTEX_ASSIGN_OR_RETURN(auto zx, matching_image(*in.zx, in.mask_zx, in.mask_weight, "mask_zx"));
    set.planes_ = {xy, yz, zx};
  }
  set.crossed_ = is_crossed(set.planes_);
  return set;
}

Result<ExemplarSet> ExemplarSet::from_matching_images(std::array<std::shared_ptr<const ImageF>, 3> planes,
                                                      bool has_mask) {
  const int want = has_mask ? 4 : 3;
  for (int k = 0; k < 3; ++k) {
    if (!planes[k] || planes[k]->empty() || planes[k]->channels != want ||
        planes[k]->width < kMinExemplarSide || planes[k]->height < kMinExemplarSide)
      return Status(StatusCode::kCorrupt, std::string("stored exemplar for plane ") +
                                              plane_name(plane_from_index(k)) + " is invalid");
  }
  ExemplarSet set;
  set.planes_ = std::move(planes);
  set.has_mask_ = has_mask;
  set.crossed_ = is_crossed(set.planes_);
  return set;
}

Result<std::string> apply_grain_layout(const std::string& grain, ExemplarInputs& in,
                                       std::array<float, 3>& suggested_plane_weights) {
  if (grain.empty() || grain == "none") return std::string();
  std::string layout = grain;
  if (grain == "auto") {
    if (in.yz || in.zx) return std::string();
    layout = auto_grain_layout(estimate_stripe_orientation(in.xy));
    if (layout.empty()) return layout;
  } else if (grain != "x" && grain != "y" && grain != "crossed") {
    return Status(StatusCode::kInvalidArgument, "unknown grain '" + grain + "' (auto, none, x, y, crossed)", "grain");
  }
  if (in.yz || in.zx) return Status(StatusCode::kInvalidArgument, "cannot be combined with yz/zx exemplars", "grain");
  if (layout == "crossed") {
    in.yz = transposed(in.xy);
    in.zx = in.yz;
    if (in.mask_xy) in.mask_yz = in.mask_zx = transposed(*in.mask_xy);
    suggested_plane_weights = {1.f, 1.f, 1.f};
    return layout;
  }
  // The plane that holds both of the grain's cross axes shows end grain: E, down-weighted.
  const bool along_x = layout == "x";
  (along_x ? in.zx : in.yz) = transposed(in.xy);
  (along_x ? in.yz : in.zx) = in.xy;
  if (in.mask_xy) {
    (along_x ? in.mask_zx : in.mask_yz) = transposed(*in.mask_xy);
    (along_x ? in.mask_yz : in.mask_zx) = in.mask_xy;
  }
  suggested_plane_weights = along_x ? std::array<float, 3>{1.f, kEndGrainWeight, 1.f}
                                    : std::array<float, 3>{1.f, 1.f, kEndGrainWeight};
  return layout;
}

}  // namespace solidtex
