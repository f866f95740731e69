// Frame fields: a unit quaternion per point of space giving the local frame (Zhang §3).
// q maps local coordinates to world coordinates: the local x axis is q * (1,0,0) * q^-1.
// Fields are immutable and thread-safe; at() is a pure function of the point, so synthesis
// stays spatially deterministic. Positions are in world units (one unit = one finest voxel).
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/status.h"
#include "core/types.h"

namespace solidtex {

struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
  double dot(const Quat& o) const { return w * o.w + x * o.x + y * o.y + z * o.z; }
  // Unit length (to rounding) for any finite non-zero components, however large or small (the
  // squared norm does not overflow); the identity for zero and for non-finite components.
  Quat normalized() const;
  Quat conjugate() const { return {w, -x, -y, -z}; }
  static Quat from_axis_angle(double ax, double ay, double az, double radians);
};
Quat operator*(const Quat& a, const Quat& b);

// The local frame map synthesis uses per voxel, row-major floats: M = R * diag(scale) takes
// local offsets (exemplar-aligned) to world offsets; `inv` is its inverse diag(1/scale) * R^T.
// With unit scale it is the rotation of the quaternion.
struct Rot3 {
  std::array<float, 9> m{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<float, 9> inv{1, 0, 0, 0, 1, 0, 0, 0, 1};
  // world = M * local
  // Inline: stencils apply it to every sample of every voxel in varying fields.
  void apply(const float l[3], float w[3]) const {
    for (int r = 0; r < 3; ++r) w[r] = m[size_t(r * 3 + 0)] * l[0] + m[size_t(r * 3 + 1)] * l[1] + m[size_t(r * 3 + 2)] * l[2];
  }
  // local = M^-1 * world
  void apply_inverse(const float w[3], float l[3]) const {
    for (int r = 0; r < 3; ++r)
      l[r] = inv[size_t(r * 3 + 0)] * w[0] + inv[size_t(r * 3 + 1)] * w[1] + inv[size_t(r * 3 + 2)] * w[2];
  }
  static Rot3 from_quat(const Quat& q, const std::array<double, 3>& scale = {1, 1, 1});
  friend bool operator==(const Rot3&, const Rot3&) = default;
};

class FrameField {
 public:
  virtual ~FrameField() = default;
  virtual Quat at(const WorldPoint& p) const = 0;
  // Per-axis scale of the texture along the local frame's axes (Zhang §3, last paragraph;
  // Sheng et al.): 2 along x doubles the texture's period along the local x axis. (0.25, 4].
  virtual std::array<double, 3> scale_at(const WorldPoint&) const { return {1, 1, 1}; }
  // An upper bound of every scale_at() component (bounds dependency sets).
  virtual double max_scale() const { return 1; }
  // Human-readable description, e.g. "identity" or "quat:0.92,0,0,0.38".
  virtual std::string describe() const = 0;
  // True when at() is the same everywhere (lets callers hoist per-voxel work).
  virtual bool is_constant() const { return false; }
};

class ConstantField : public FrameField {
 public:
  explicit ConstantField(Quat q, std::array<double, 3> scale = {1, 1, 1}) : q_(q.normalized()), scale_(scale) {}
  Quat at(const WorldPoint&) const override { return q_; }
  std::array<double, 3> scale_at(const WorldPoint&) const override { return scale_; }
  double max_scale() const override { return std::max({scale_[0], scale_[1], scale_[2], 1.0}); }
  std::string describe() const override;
  bool is_constant() const override { return true; }

 private:
  Quat q_;
  std::array<double, 3> scale_;
};

// A coarse grid of quaternions (corner samples), trilinearly interpolated with the corners'
// signs aligned to the first corner (q and -q are the same rotation), then renormalised.
// Outside the grid the nearest boundary value is used (clamped).
class QuatGridField : public FrameField {
 public:
  // dims >= 2 per axis; `spacing` world units between samples; values x-fastest.
  // `log_scales`: empty (unit scale) or one log-scale triple per node, interpolated trilinearly.
  static Result<std::shared_ptr<const QuatGridField>> create(WorldPoint origin, double spacing,
                                                             std::array<int, 3> dims,
                                                             std::vector<Quat> values,
                                                             std::vector<std::array<double, 3>> log_scales = {});
  Quat at(const WorldPoint& p) const override;
  std::array<double, 3> scale_at(const WorldPoint& p) const override;
  double max_scale() const override { return max_scale_; }
  std::string describe() const override;
  const std::array<int, 3>& dims() const { return dims_; }

 private:
  WorldPoint origin_;
  double spacing_ = 1;
  std::array<int, 3> dims_{};
  std::vector<Quat> values_;
  std::vector<std::array<double, 3>> log_scales_;
  double max_scale_ = 1;
  void cell(const WorldPoint& p, int i0[3], double f[3]) const;
};

inline constexpr double kMinScale = 0.25, kMaxScale = 4.0;
// The most nodes a QuatGridField (and so a .stf file) has along one axis.
inline constexpr int kMaxGridSide = 1024;

// "identity", "quat:W,X,Y,Z", "axis:AX,AY,AZ,DEGREES", optionally followed by
// ";scale:SX,SY,SZ" (constant per-axis scale), or a path to a JSON quaternion grid
// {"origin":[x,y,z],"spacing":s,"dims":[nx,ny,nz],"quaternions":[[w,x,y,z],...]}.
Result<std::shared_ptr<const FrameField>> parse_field_spec(const std::string& spec);

}  // namespace solidtex
