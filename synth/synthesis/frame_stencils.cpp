#include "synthesis/frame_stencils.h"

#include <cmath>

namespace solidtex {
namespace {

Rot3 smoothed_frame(const FrameField& field, const WorldPoint& c, int level, int levels) {
  if (level == levels - 1) return Rot3::from_quat(field.at(c), field.scale_at(c));
  const double r = 0.25 * double(stack_spacing(PyramidLevel{level}, levels));
  Quat acc{0, 0, 0, 0}, ref{};
  std::array<double, 3> log_scale{0, 0, 0};
  for (int k = 0; k < 8; ++k) {
    const WorldPoint q{c.x + ((k & 1) ? r : -r), c.y + ((k & 2) ? r : -r), c.z + ((k & 4) ? r : -r)};
    Quat f = field.at(q);
    if (k == 0) ref = f;
    if (f.dot(ref) < 0) f = {-f.w, -f.x, -f.y, -f.z};
    acc = {acc.w + f.w, acc.x + f.x, acc.y + f.y, acc.z + f.z};
    const auto sc = field.scale_at(q);
    for (int a = 0; a < 3; ++a) log_scale[size_t(a)] += std::log(sc[size_t(a)]) / 8;
  }
  return Rot3::from_quat(acc.normalized(), {std::exp(log_scale[0]), std::exp(log_scale[1]), std::exp(log_scale[2])});
}

}  // namespace

WorldPoint voxel_centre(PyramidLevel level, int levels, const Voxel& v) {
  const double s = double(stack_spacing(level, levels));
  return {(v.x + 0.5) * s - 0.5, (v.y + 0.5) * s - 0.5, (v.z + 0.5) * s - 0.5};
}

Result<FrameStencils> FrameStencils::make(const FrameField& field, int neighborhood, int levels, int trilinear_levels) {
  FrameStencils f;
  f.field_ = &field;
  f.neighborhood_ = neighborhood;
  f.levels_ = levels;
  f.trilinear_levels_ = trilinear_levels;
  // A local offset of at most N/2 on two axes reaches N/2 * sqrt(2) * scale voxels.
  const int base_reach = int(std::ceil((neighborhood / 2) * std::sqrt(2.0) * field.max_scale()));
  if (base_reach + 1 > 120) return Status(StatusCode::kInvalidArgument, "field scales reach too far", "field");
  f.candidate_reach_ = int(std::ceil(std::sqrt(2.0) * field.max_scale()));
  f.constant_ = field.is_constant();
  if (f.constant_) f.constant_rotation_ = Rot3::from_quat(field.at({0, 0, 0}), field.scale_at({0, 0, 0}));
  for (int l = 0; l < levels; ++l) {
    f.reach_.push_back(base_reach + 1);
    ReadStencil st;
    Offsets offs;
    if (f.constant_) {
      build_stencil(f.constant_rotation_, neighborhood, l < trilinear_levels, st);
      stencil_offsets(st, offs);
    }
    f.stencils_.push_back(std::move(st));
    f.offsets_.push_back(std::move(offs));
  }
  return f;
}

Rot3 FrameStencils::rotation(PyramidLevel l, const Voxel& p) const {
  return constant_ ? constant_rotation_ : smoothed_frame(*field_, voxel_centre(l, levels_, p), l.index, levels_);
}

const ReadStencil& FrameStencils::stencil(PyramidLevel l, const Voxel& p, ReadStencil& scratch) const {
  if (constant_) return stencils_[size_t(l.index)];
  build_stencil(rotation(l, p), neighborhood_, l.index < trilinear_levels_, scratch);
  return scratch;
}

const FrameStencils::Offsets& FrameStencils::offsets(PyramidLevel l, const Voxel& p, ReadStencil& stencil_scratch,
                                                      Offsets& scratch) const {
  if (constant_) return offsets_[size_t(l.index)];
  stencil_offsets(stencil(l, p, stencil_scratch), scratch);
  return scratch;
}

}  // namespace solidtex
