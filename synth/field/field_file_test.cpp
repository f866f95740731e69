// The .stf reader's value checks and the grid field on extreme quaternions (fuzz findings of
// fuzz/field_file_fuzzer.cpp, see fuzz/README.md).
#include "field/field_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "field/frame_field.h"
#include "field/sketch.h"

namespace solidtex {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A valid 3x3x3 field: 45 degrees about z everywhere, unit scales.
StoredField small_field() {
  StoredField f;
  f.origin = {0, 0, 0};
  f.spacing = 4;
  f.dims = {3, 3, 3};
  f.nodes.assign(27, Quat::from_axis_angle(0, 0, 1, M_PI / 4));
  f.sketch_json = "{}";
  return f;
}

// decode_field(encode_field(f)): the checksum is valid, so only the value checks can refuse.
Status decode_status(const StoredField& f) { return decode_field(encode_field(f)).status(); }

void expect_refused(const StoredField& f, const std::string& field, const std::string& words) {
  const Status st = decode_status(f);
  EXPECT_EQ(st.code(), StatusCode::kCorrupt) << st.to_string();
  EXPECT_EQ(st.field(), field) << st.to_string();
  EXPECT_NE(st.message().find(words), std::string::npos) << st.to_string();
}

TEST(FieldFile, ValidFieldDecodesAndLoads) {
  const StoredField f = small_field();
  auto back = decode_field(encode_field(f));
  ASSERT_TRUE(back.is_ok()) << back.status().to_string();
  EXPECT_TRUE(QuatGridField::create(back->origin, back->spacing, back->dims, back->nodes, back->log_scales).is_ok());
}

// fuzz/field_file_fuzzer.cpp:41 (FUZZ_CHECK at(origin) == node 0's frame): a checksummed file
// whose node 0 is (1e200, 0, 0, 1e200). Its squared norm overflows to infinity, which passed
// QuatGridField::create's "|q|^2 > 1e-12" test; normalising divided by infinity, leaving the
// zero quaternion, and the field answered the identity at the origin instead of 90 degrees
// about z. The reader now refuses it, and normalisation no longer overflows.
TEST(FieldFile, RefusesHugeQuaternionNode) {
  StoredField f = small_field();
  f.nodes[0] = {1e200, 0, 0, 1e200};
  expect_refused(f, "field.nodes", "stored node 0 (");
  f = small_field();
  f.nodes[26] = {0, 1e-200, 0, 0};  // |q|^2 underflows to 0
  expect_refused(f, "field.nodes", "stored node 26 ");
}

TEST(FieldFile, RefusesNonUnitNonFiniteAndZeroQuaternions) {
  for (const Quat& q : {Quat{0, 0, 0, 0}, Quat{2, 0, 0, 0}, Quat{0.5, 0.5, 0.5, 0.49}, Quat{kNaN, 0, 0, 0},
                        Quat{1, kInf, 0, 0}}) {
    StoredField f = small_field();
    f.nodes[13] = q;
    expect_refused(f, "field.nodes", "stored node 13 ");
  }
  // Rounding of a normalised quaternion is fine.
  StoredField f = small_field();
  f.nodes[13] = Quat{0.3, -0.4, 0.5, 0.7}.normalized();
  EXPECT_TRUE(decode_status(f).is_ok());
}

TEST(FieldFile, RefusesBadOriginSpacingAndCounts) {
  for (double s : {0.0, -4.0, kNaN, kInf, -kInf}) {
    StoredField f = small_field();
    f.spacing = s;
    expect_refused(f, "field.spacing", "is not a finite number > 0");
  }
  for (double o : {kNaN, kInf, -kInf}) {
    StoredField f = small_field();
    f.origin.y = o;
    expect_refused(f, "field.origin", "is not finite");
  }
  for (int c : {-1, 28}) {
    StoredField f = small_field();
    f.singular_nodes = c;
    expect_refused(f, "field.singular_nodes", "outside [0, 27]");
  }
  StoredField f = small_field();
  f.singular_nodes = 27;
  EXPECT_TRUE(decode_status(f).is_ok());
  // A side QuatGridField::create refuses (the payload holds its nodes).
  f = small_field();
  f.dims = {kMaxGridSide + 1, 2, 2};
  f.nodes.assign(size_t(kMaxGridSide + 1) * 4, Quat{});
  expect_refused(f, "field.dims", "1025x2x2 is impossible");
}

TEST(FieldFile, RefusesOutOfRangeLogScales) {
  for (double v : {std::log(4.1), std::log(0.24), kNaN, kInf, -kInf}) {
    StoredField f = small_field();
    f.log_scales.assign(27, {0, 0, 0});
    f.log_scales[3][1] = v;
    expect_refused(f, "field.log_scales", "of node 3 is outside");
  }
  StoredField f = small_field();
  f.log_scales.assign(27, {std::log(kMinScale), 0, std::log(kMaxScale)});
  EXPECT_TRUE(decode_status(f).is_ok());
}

TEST(Quat, NormalizedDoesNotOverflowOrUnderflow) {
  const double h = std::sqrt(0.5);
  for (double m : {1e200, 1e-200, 1e308, 5e-324 * 4}) {
    const Quat q = Quat{m, 0, 0, m}.normalized();
    EXPECT_NEAR(q.w, h, 1e-15) << m;
    EXPECT_EQ(q.x, 0) << m;
    EXPECT_NEAR(q.z, h, 1e-15) << m;
  }
  const Quat big = Quat{-3e250, 4e250, 0, 0}.normalized();
  EXPECT_NEAR(big.w, -0.6, 1e-15);
  EXPECT_NEAR(big.x, 0.8, 1e-15);
  // Zero and non-finite components: the identity, as before.
  for (const Quat& q : {Quat{0, 0, 0, 0}, Quat{kNaN, 0, 0, 1}, Quat{kInf, 1, 0, 0}}) {
    const Quat n = q.normalized();
    EXPECT_TRUE(n.w == 1 && n.x == 0 && n.y == 0 && n.z == 0);
  }
  // Ordinary quaternions: exactly q / |q|.
  const Quat q{0.3, -0.4, 0.5, 0.7};
  const double len = std::sqrt(q.dot(q));
  const Quat n = q.normalized();
  EXPECT_TRUE(n.w == q.w / len && n.x == q.x / len && n.y == q.y / len && n.z == q.z / len);
}

// The grid field itself (as a JSON grid or a direct caller would build it) keeps the rotation
// of huge quaternions.
TEST(QuatGridField, HugeQuaternionsKeepTheirRotation) {
  StoredField f = small_field();
  f.nodes[0] = {1e200, 0, 0, 1e200};
  auto grid = QuatGridField::create(f.origin, f.spacing, f.dims, f.nodes);
  ASSERT_TRUE(grid.is_ok()) << grid.status().to_string();
  const Quat q = (*grid)->at(f.origin);
  EXPECT_NEAR(std::fabs(q.dot(Quat{std::sqrt(0.5), 0, 0, std::sqrt(0.5)})), 1, 1e-12);
}

TEST(Sketch, HugeFrameQuaternionIsNormalised) {
  auto s = parse_sketch_json(R"({"domain": {"min": [0, 0, 0], "max": [4, 4, 4], "shortest_side_cells": 2},
    "curves": [], "frames": [{"point": [1, 1, 1], "quaternion": [1e300, 0, 0, 1e300]}]})");
  ASSERT_TRUE(s.is_ok()) << s.status().to_string();
  ASSERT_EQ(s->frames.size(), 1u);
  EXPECT_NEAR(s->frames[0].frame.w, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(s->frames[0].frame.z, std::sqrt(0.5), 1e-15);
  // Printed and parsed again (fuzz/sketch_fuzzer.cpp's round trip).
  auto again = parse_sketch_json(sketch_to_json(*s));
  ASSERT_TRUE(again.is_ok()) << again.status().to_string();
  EXPECT_NEAR(again->frames[0].frame.dot(s->frames[0].frame), 1, 1e-12);
}

}  // namespace
}  // namespace solidtex
