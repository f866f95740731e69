// Sketches (Zhang §3): a domain and an ordered list of curves from which a frame field is
// solved (tensor_field.h). JSON schema: proto/sketch.schema.json. Unknown keys are errors;
// every validation error names the curve and point ("curves[2].points[5]").
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/status.h"
#include "field/frame_field.h"
#include "core/types.h"

namespace solidtex {

struct SketchDomain {
  WorldPoint min{0, 0, 0};      // world units (one unit = one finest voxel by default)
  WorldPoint max{64, 64, 64};
  int shortest_side_cells = 24;  // grid cells along the domain's shortest side, [2, 256]
};

struct SketchCurve {
  std::vector<WorldPoint> points;          // polyline, >= 2 distinct points, inside the domain
  std::vector<WorldPoint> normals;         // per-point surface normals (curve on a surface), or
  std::optional<WorldPoint> plane_normal;  // one reference-plane normal (curve inside the volume)
  std::optional<int> axis;                 // 0/1/2: the frame axis (x/y/z) that follows the tangent
  double weight = 100.0;                   // w of Eq. 2, (0, 1e6]
};

// A per-axis texture scale at a point (Zhang §3, last paragraph): interpolated harmonically
// (in log space) like the frames. Scales along the local frame's x, y, z, each in [0.25, 4].
struct ScalePoint {
  WorldPoint point;
  std::array<double, 3> scale{1, 1, 1};
  double weight = 100.0;
};

// An explicit frame at a point (e.g. principal-curvature frames of a mesh): a soft constraint
// like a curve sample. The quaternion's sign is taken as given (the producer keeps
// neighbouring frames' signs consistent), so the set is solved in one go.
struct SketchFrame {
  WorldPoint point;
  Quat frame;            // unit after parsing
  double weight = 100.0;  // (0, 1e6]
};

struct Sketch {
  SketchDomain domain;
  std::vector<SketchFrame> frames;  // optional; solved first, in one batch
  std::vector<SketchCurve> curves;  // at least one curve or one frame
  std::vector<ScalePoint> scales;  // optional
};

Result<Sketch> parse_sketch_json(const std::string& text);
// The JSON form parse_sketch_json reads back (numbers printed to round-trip doubles).
std::string sketch_to_json(const Sketch& sketch);
// One curve object as found in "curves" (also the body of "add a curve" requests).
Result<SketchCurve> parse_curve_json(const std::string& text, int index);
Status validate_curve(const SketchCurve& c, const SketchDomain& d, int index);

}  // namespace solidtex
