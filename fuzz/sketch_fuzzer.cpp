// parse_sketch_json and parse_curve_json (field/sketch.h): strict JSON (duplicate keys,
// UTF-8), unknown keys, every point and curve validated. The same text is read as a sketch
// and as one curve ("add a curve" requests, validated against the default domain).
// Checked: an accepted sketch prints (sketch_to_json) to JSON that parses back to the same
// sketch.
#include <cmath>

#include "field/sketch.h"
#include "fuzz_support.h"

using namespace solidtex;

namespace {

bool same(const WorldPoint& a, const WorldPoint& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

void check_round_trip(const Sketch& s) {
  const std::string printed = sketch_to_json(s);
  Result<Sketch> again = parse_sketch_json(printed);
  FUZZ_CHECK(again.is_ok());
  const Sketch& t = *again;
  FUZZ_CHECK(same(t.domain.min, s.domain.min) && same(t.domain.max, s.domain.max));
  FUZZ_CHECK(t.domain.shortest_side_cells == s.domain.shortest_side_cells);
  FUZZ_CHECK(t.curves.size() == s.curves.size() && t.scales.size() == s.scales.size() &&
             t.frames.size() == s.frames.size());
  for (size_t i = 0; i < s.curves.size(); ++i) {
    const SketchCurve &a = s.curves[i], &b = t.curves[i];
    FUZZ_CHECK(a.points.size() == b.points.size() && a.normals.size() == b.normals.size());
    for (size_t k = 0; k < a.points.size(); ++k) FUZZ_CHECK(same(a.points[k], b.points[k]));
    for (size_t k = 0; k < a.normals.size(); ++k) FUZZ_CHECK(same(a.normals[k], b.normals[k]));
    FUZZ_CHECK(a.plane_normal.has_value() == b.plane_normal.has_value());
    if (a.plane_normal) FUZZ_CHECK(same(*a.plane_normal, *b.plane_normal));
    FUZZ_CHECK(a.axis == b.axis && a.weight == b.weight);
  }
  for (size_t i = 0; i < s.scales.size(); ++i) {
    FUZZ_CHECK(same(s.scales[i].point, t.scales[i].point));
    FUZZ_CHECK(s.scales[i].scale == t.scales[i].scale && s.scales[i].weight == t.scales[i].weight);
  }
  for (size_t i = 0; i < s.frames.size(); ++i) {
    // Frames are normalised when parsed, so the printed ones are normalised once more.
    FUZZ_CHECK(same(s.frames[i].point, t.frames[i].point) && s.frames[i].weight == t.frames[i].weight);
    FUZZ_CHECK(std::fabs(s.frames[i].frame.dot(t.frames[i].frame) - 1) < 1e-12);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = fuzz::text(data, size);
  Result<Sketch> sketch = parse_sketch_json(text);
  if (sketch) {
    FUZZ_CHECK(!sketch->curves.empty() || !sketch->frames.empty());
    for (size_t i = 0; i < sketch->curves.size(); ++i)
      FUZZ_CHECK(validate_curve(sketch->curves[i], sketch->domain, int(i)).is_ok());
    check_round_trip(*sketch);
  } else {
    FUZZ_CHECK(!sketch.status().message().empty());
  }
  Result<SketchCurve> curve = parse_curve_json(text, 3);
  if (curve) (void)validate_curve(*curve, SketchDomain{}, 3);
  return 0;
}
