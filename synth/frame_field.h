// Frame fields: a unit quaternion per point of space giving the local frame (Zhang §3).
// q maps local coordinates to world coordinates: the local x axis is q * (1,0,0) * q^-1.
// Fields are immutable and thread-safe; at() is a pure function of the point, so synthesis
// stays spatially deterministic. Positions are in world units (one unit = one finest voxel).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "status.h"
#include "types.h"

namespace solidtex {

struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
  double dot(const Quat& o) const { return w * o.w + x * o.x + y * o.y + z * o.z; }
  Quat normalized() const;
  Quat conjugate() const { return {w, -x, -y, -z}; }
  static Quat from_axis_angle(double ax, double ay, double az, double radians);
};
Quat operator*(const Quat& a, const Quat& b);

// Row-major 3x3 rotation in float: what synthesis uses per voxel.
struct Rot3 {
  std::array<float, 9> m{1, 0, 0, 0, 1, 0, 0, 0, 1};
  // world = R * local
  void apply(const float local[3], float world[3]) const;
  // local = R^T * world
  void apply_inverse(const float world[3], float local[3]) const;
  static Rot3 from_quat(const Quat& q);
  friend bool operator==(const Rot3&, const Rot3&) = default;
};

class FrameField {
 public:
  virtual ~FrameField() = default;
  virtual Quat at(const WorldPoint& p) const = 0;
  // Human-readable description, e.g. "identity" or "quat:0.92,0,0,0.38".
  virtual std::string describe() const = 0;
  // True when at() is the same everywhere (lets callers hoist per-voxel work).
  virtual bool is_constant() const { return false; }
};

class ConstantField : public FrameField {
 public:
  explicit ConstantField(Quat q) : q_(q.normalized()) {}
  Quat at(const WorldPoint&) const override { return q_; }
  std::string describe() const override;
  bool is_constant() const override { return true; }

 private:
  Quat q_;
};

// A coarse grid of quaternions (corner samples), trilinearly interpolated with the corners'
// signs aligned to the first corner (q and -q are the same rotation), then renormalised.
// Outside the grid the nearest boundary value is used (clamped).
class QuatGridField : public FrameField {
 public:
  // dims >= 2 per axis; `spacing` world units between samples; values x-fastest.
  static Result<std::shared_ptr<const QuatGridField>> create(WorldPoint origin, double spacing,
                                                             std::array<int, 3> dims,
                                                             std::vector<Quat> values);
  Quat at(const WorldPoint& p) const override;
  std::string describe() const override;
  const std::array<int, 3>& dims() const { return dims_; }

 private:
  WorldPoint origin_;
  double spacing_ = 1;
  std::array<int, 3> dims_{};
  std::vector<Quat> values_;
};

// "identity", "quat:W,X,Y,Z", "axis:AX,AY,AZ,DEGREES" or a path to a JSON quaternion grid
// {"origin":[x,y,z],"spacing":s,"dims":[nx,ny,nz],"quaternions":[[w,x,y,z],...]}.
Result<std::shared_ptr<const FrameField>> parse_field_spec(const std::string& spec);

}  // namespace solidtex
