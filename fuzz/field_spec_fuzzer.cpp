// parse_field_spec (field/frame_field.h) on the inline forms only: "identity", "quat:W,X,Y,Z",
// "axis:AX,AY,AZ,DEG", each optionally followed by ";scale:SX,SY,SZ". Anything else is taken
// as a file path and opened, which a harness must never do, so the first byte picks a prefix
// that keeps the spec inline whatever follows:
//   0: "identity;scale:" + rest   (the spec before the first ";scale:" is exactly "identity")
//   1: "quat:" + rest             2: "axis:" + rest
// Checked: an accepted spec is a constant field of finite unit quaternions with scales in
// [0.25, 4], and its frame matrices (Rot3, what synthesis uses per voxel) are finite.
#include <cmath>

#include "field/frame_field.h"
#include "fuzz_support.h"

using namespace solidtex;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kPrefixes[3] = {"identity;scale:", "quat:", "axis:"};
  const std::string spec = kPrefixes[data[0] % 3] + fuzz::text(data + 1, size - 1);
  auto field = parse_field_spec(spec);
  if (!field) {
    FUZZ_CHECK(!field.status().message().empty());
    return 0;
  }
  const FrameField& f = **field;
  FUZZ_CHECK(f.is_constant());
  FUZZ_CHECK(!f.describe().empty());
  const WorldPoint p{1, 2, 3};
  const Quat q = f.at(p);
  FUZZ_CHECK(std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z));
  FUZZ_CHECK(std::fabs(q.dot(q) - 1) < 1e-9);
  const std::array<double, 3> s = f.scale_at(p);
  for (double v : s) FUZZ_CHECK(v >= kMinScale && v <= kMaxScale);
  FUZZ_CHECK(f.max_scale() >= 1 && f.max_scale() <= kMaxScale);
  const Rot3 r = Rot3::from_quat(q, s);
  for (int i = 0; i < 9; ++i) FUZZ_CHECK(std::isfinite(r.m[size_t(i)]) && std::isfinite(r.inv[size_t(i)]));
  return 0;
}
