// The local frame and read stencil of every voxel at every pyramid level (Zhang §4.3, §6).
// The finest level uses the frame field at each voxel centre; coarser levels the field
// smoothed over the voxel's footprint (sign-aligned renormalised mean of 8 samples at +-1/4 of
// the voxel's size, log scales averaged). A constant field builds one stencil per level, once.
// reach(level) bounds how far (in voxels, per axis) any stencil offset of that level goes.
// Immutable after make(): thread-safe; per-voxel stencils go into caller-owned scratch.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/status.h"
#include "field/frame_field.h"
#include "synthesis/correction.h"

namespace solidtex {

// World-space centre of voxel v at `level` (one world unit = one finest voxel).
WorldPoint voxel_centre(PyramidLevel level, int levels, const Voxel& v);

class FrameStencils {
 public:
  using Offsets = std::vector<std::array<int8_t, 3>>;

  // `trilinear_levels`: levels below it read trilinearly weighted taps (correction.h).
  static Result<FrameStencils> make(const FrameField& field, int neighborhood, int levels, int trilinear_levels);

  int levels() const { return levels_; }
  bool constant() const { return constant_; }
  int reach(PyramidLevel l) const { return reach_[size_t(l.index)]; }
  // Bounds the candidate offsets (ReadStencil::candidate: one in-plane step) per axis, at every
  // level: what a patch vote (patch_vote.h) reads around a voxel.
  int candidate_reach() const { return candidate_reach_; }

  // The frame of voxel p at level l.
  Rot3 rotation(PyramidLevel l, const Voxel& p) const;
  // The read stencil of p at l: the shared one for constant fields, else built into scratch.
  const ReadStencil& stencil(PyramidLevel l, const Voxel& p, ReadStencil& scratch) const;
  // The distinct voxel offsets p's correction reads at l (stencil_offsets of its stencil).
  const Offsets& offsets(PyramidLevel l, const Voxel& p, ReadStencil& stencil_scratch, Offsets& scratch) const;

 private:
  const FrameField* field_ = nullptr;
  int neighborhood_ = 0;
  int levels_ = 0;
  int trilinear_levels_ = 0;
  bool constant_ = false;
  Rot3 constant_rotation_;
  std::vector<int> reach_;               // per level
  int candidate_reach_ = 1;
  std::vector<ReadStencil> stencils_;    // per level, constant fields only
  std::vector<Offsets> offsets_;         // per level, constant fields only
};

}  // namespace solidtex
