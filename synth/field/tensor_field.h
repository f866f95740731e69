// Smooth 3D frame fields from sketched curves (Zhang §3, Eq. 1-2).
//
// The domain is a grid of nodes (spacing = shortest side / shortest_side_cells). Each curve is
// sampled every half cell; at a sample the frame is (tangent, normal, tangent x normal) with the
// curve's axis label choosing which frame axis follows the tangent (e_a = t, e_{a+1} = n,
// e_{a+2} = t x n: right-handed). Unlabelled curves rotate the current field minimally so
// that whichever of its +-x, +-y, +-z is closest to the tangent aligns with it (the first curve,
// with no field yet, uses x). Quaternion signs: the first curve starts with w >= 0 and stays
// continuous along itself; later samples take the sign closest to the current field.
// Each sample softly constrains the trilinear interpolation of its cell's corners with weight w
// (default 100); the field minimises sum over grid edges ||q_i - q_j||^2 + sum w^2 ||q(p) - qbar||^2, i.e. solves (L + sum w^2 b b^T) Q = sum w^2 b qbar
// (L the grid's combinatorial Laplacian) for the four components by preconditioned conjugate
// gradients (relative tolerance 1e-13), warm-started from the previous solution. Choice: the paper writes the smoothness term as ||L Q||^2, whose normal
// equations are a bi-Laplacian; its minimiser and ours both satisfy Eq. 1 (Delta q = 0) away
// from the curves, and ours is well conditioned enough for sub-second updates at 32^3 (the
// bi-Laplacian took minutes at 80x80x16), which is what interactive sketching needs.
// Nodes whose solution vanishes (|q| < 1e-9) copy a neighbour's frame and count as singular.
// Adding a curve re-solves the same system with the new constraints: the result is exactly the
// full solve with all curves.
// Long operations take an Interrupter (core/interrupter.h), polled before every linear solve
// and at every conjugate-gradient iteration; when it asks to stop they return kCancelled and
// leave the solver as it was before the call. Grid sizes are checked before anything is
// allocated (create()).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/interrupter.h"
#include "core/status.h"
#include "field/frame_field.h"
#include "field/sketch.h"

namespace solidtex {

struct FieldSolveStats {
  double seconds = 0;
  double residual = 0;        // ||A Q - b|| / ||b|| over the four components
  int singular_nodes = 0;
  int constrained_nodes = 0;
  int nodes = 0;
};

class FieldSolver {
 public:
  // The most grid nodes any solver accepts, whatever the caller's own limit.
  static constexpr int64_t kMaxNodes = 2'000'000;

  // An empty field over `domain`. Errors, all before anything is allocated: kInvalidArgument
  // for an empty or non-finite domain or shortest_side_cells outside [2, 256]; kTooLarge when
  // the grid would exceed kMaxNodes, kUnprocessable when it would exceed `max_nodes` (both
  // naming "domain.shortest_side_cells"). Grid dimensions are computed overflow-free, so an
  // extreme aspect (e.g. max [1.1e9, 1, 1]) is just a grid with too many nodes.
  static Result<std::unique_ptr<FieldSolver>> create(const SketchDomain& domain, int64_t max_nodes = kMaxNodes);
  ~FieldSolver();

  // The incremental operations below leave the solver unchanged when they fail (invalid input
  // or cancellation), so a caller may keep using it.
  // Adds a validated curve and re-solves. `index` is only used in error messages.
  Status add_curve(const SketchCurve& curve, int index, FieldSolveStats* stats = nullptr,
                   Interrupter& interrupter = null_interrupter());
  // Adds explicit frames (signs as given) in one batch and re-solves once; a first batch
  // counts as the field's first "curve" (later unlabelled curves align to it).
  Status add_frames(const std::vector<SketchFrame>& frames, FieldSolveStats* stats = nullptr,
                    Interrupter& interrupter = null_interrupter());
  // Sets the sparse scale points (replacing earlier ones) and solves the log-scale field.
  Status set_scales(const std::vector<ScalePoint>& scales, Interrupter& interrupter = null_interrupter());
  // Solves a whole sketch: the frames, every curve in order, then the scales. Progress is
  // reported as the share of those steps done; `stats` describes the last linear solve, with
  // `seconds` the whole solve (grid set-up excluded). Errors as create() and the steps above.
  static Result<std::unique_ptr<FieldSolver>> solve(const Sketch& sketch, FieldSolveStats* stats = nullptr,
                                                    Interrupter& interrupter = null_interrupter(),
                                                    int64_t max_nodes = kMaxNodes);

  // The normalised field (trilinear, sign-aligned corners). Requires at least one curve.
  Result<std::shared_ptr<const QuatGridField>> field() const;
  // Normalised node quaternions, x fastest.
  const std::vector<Quat>& nodes() const;
  // Per-node log scales (x fastest), empty when the sketch has no scale points.
  const std::vector<std::array<double, 3>>& log_scales() const;
  std::array<int, 3> dims() const;
  WorldPoint origin() const;
  double spacing() const;
  int curve_count() const;

 private:
  FieldSolver();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Constraint frame of a curve sample, exposed for tests: right-handed frame with axis `axis`
// along `tangent` and the next axis along the part of `normal` orthogonal to it.
Quat frame_from_tangent_normal(const WorldPoint& tangent, const WorldPoint& normal, int axis);
// Angle in degrees between the rotations of two quaternions.
double rotation_angle_degrees(const Quat& a, const Quat& b);

}  // namespace solidtex
