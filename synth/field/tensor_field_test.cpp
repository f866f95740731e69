#include "field/tensor_field.h"

#include <gtest/gtest.h>

#include <cmath>

#include "field/field_file.h"
#include "field/sketch.h"

namespace solidtex {
namespace {

std::string arc_sketch(int cells, double radius, int points, bool second_curve) {
  std::string s = R"({"domain": {"min": [-40, -40, -8], "max": [40, 40, 8], "shortest_side_cells": )" +
                  std::to_string(cells) + R"(}, "curves": [{"points": [)";
  for (int i = 0; i < points; ++i) {
    const double a = 0.5 * M_PI * i / (points - 1);
    s += (i ? "," : "") + std::string("[") + std::to_string(radius * std::cos(a)) + "," +
         std::to_string(radius * std::sin(a)) + ",0]";
  }
  s += R"(], "plane_normal": [0, 0, 1], "axis": "x"})";
  if (second_curve) s += R"(, {"points": [[-30, -20, 2], [-10, -30, 2]], "plane_normal": [0, 0, 1]})";
  return s + "]}";
}

TEST(TensorField, FramesAtConstraintPointsFollowTheSketch) {
  auto sketch = parse_sketch_json(arc_sketch(8, 25, 40, false));
  ASSERT_TRUE(sketch.is_ok()) << sketch.status().to_string();
  FieldSolveStats st;
  auto solver = FieldSolver::solve(*sketch, &st);
  ASSERT_TRUE(solver.is_ok()) << solver.status().to_string();
  auto field = (*solver)->field().value();
  EXPECT_LT(st.residual, 1e-8);
  double worst = 0;
  const auto& pts = sketch->curves[0].points;
  for (size_t i = 1; i + 1 < pts.size(); ++i) {
    const WorldPoint t{pts[i + 1].x - pts[i - 1].x, pts[i + 1].y - pts[i - 1].y, 0};
    const Quat want = frame_from_tangent_normal(t, {0, 0, 1}, 0);
    worst = std::max(worst, rotation_angle_degrees(field->at(pts[i]), want));
  }
  RecordProperty("worst_degrees", std::to_string(worst));
  EXPECT_LE(worst, 2.0);
}

TEST(TensorField, StraightLineGivesTheConstantField) {
  auto sketch = parse_sketch_json(
      R"({"domain": {"min": [0, 0, 0], "max": [32, 32, 32], "shortest_side_cells": 8},
          "curves": [{"points": [[4, 4, 4], [28, 20, 12]], "plane_normal": [0, 0, 1], "axis": "y"}]})");
  ASSERT_TRUE(sketch.is_ok()) << sketch.status().to_string();
  auto solver = FieldSolver::solve(*sketch).value();
  const Quat want = frame_from_tangent_normal({24, 16, 8}, {0, 0, 1}, 1);
  for (const Quat& q : solver->nodes()) ASSERT_LT(rotation_angle_degrees(q, want), 1e-4);
}

TEST(TensorField, IncrementalUpdateEqualsFullSolve) {
  auto both = parse_sketch_json(arc_sketch(8, 20, 12, true)).value();
  Sketch first = both;
  first.curves.resize(1);
  auto incremental = FieldSolver::solve(first).value();
  FieldSolveStats st;
  ASSERT_TRUE(incremental->add_curve(both.curves[1], 1, &st).is_ok());
  auto full = FieldSolver::solve(both).value();
  double worst = 0;
  for (size_t i = 0; i < full->nodes().size(); ++i) {
    const Quat& a = incremental->nodes()[i];
    const Quat& b = full->nodes()[i];
    worst = std::max({worst, std::abs(a.w - b.w), std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
  }
  EXPECT_LE(worst, 1e-6);
  // The second (unlabelled) curve actually changed the field near it.
  auto one = FieldSolver::solve(first).value();
  const auto f1 = one->field().value(), f2 = full->field().value();
  EXPECT_GT(rotation_angle_degrees(f1->at({-20, -25, 2}), f2->at({-20, -25, 2})), 1.0);
}

TEST(TensorField, MalformedSketchesNameTheProblem) {
  const std::string dom = R"({"domain": {"min": [0,0,0], "max": [10,10,10]}, "curves": [)";
  struct Case {
    std::string json;
    std::string field;
  };
  const Case cases[] = {
      {dom + R"({"points": [[1,1,1],[2,2,2]], "plane_normal": [0,0,1], "color": 3}]})", "curves[0].color"},
      {dom + R"({"points": [[1,1,1],[1,1,1]], "plane_normal": [0,0,1]}]})", "curves[0].points[1]"},
      {dom + R"({"points": [[1,1,1],[1,1,5]], "plane_normal": [0,0,1]}]})", "curves[0].points[0]"},  // tangent || normal
      {dom + R"({"points": [[1,1,1],[20,2,2]], "plane_normal": [0,0,1]}]})", "curves[0].points[1]"},  // outside
      {dom + R"({"points": [[1,1,1],[2,2,2]]}]})", "curves[0]"},
      {dom + R"({"points": [[1,1,1],[2,2,2]], "normals": [[0,0,1]]}]})", "curves[0].normals"},
      {dom + R"({"points": [[1,1,1],[2,"a",2]], "plane_normal": [0,0,1]}]})", "curves[0].points[1]"},
      {dom + R"({"points": [[1,1,1],[2,2,2]], "plane_normal": [0,0,1], "axis": "w"}]})", "curves[0].axis"},
      {dom + "]}", "curves"},
      {R"({"domain": {"min": [0,0,0], "max": [0,10,10]}, "curves": []})", "domain.max"},
      {"{not json", "sketch"},
  };
  for (const Case& c : cases) {
    auto r = parse_sketch_json(c.json);
    ASSERT_FALSE(r.is_ok()) << c.json;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(r.status().field(), c.field) << r.status().to_string();
  }
  auto nan = parse_sketch_json(dom + R"({"points": [[1,1,1],[2,2,2]], "plane_normal": [0,0,1], "weight": -1}]})");
  EXPECT_EQ(nan.status().field(), "curves[0].weight");
}

TEST(TensorField, SketchedScalesInterpolateBetweenPoints) {
  auto sketch = parse_sketch_json(
      R"({"domain": {"min": [0, 0, 0], "max": [40, 20, 20], "shortest_side_cells": 5},
          "curves": [{"points": [[5, 10, 10], [35, 10, 10]], "plane_normal": [0, 0, 1]}],
          "scales": [{"point": [0, 10, 10], "scale": [1, 1, 1]}, {"point": [40, 10, 10], "scale": [4, 1, 0.5]}]})");
  ASSERT_TRUE(sketch.is_ok()) << sketch.status().to_string();
  auto field = FieldSolver::solve(*sketch).value()->field().value();
  const auto a = field->scale_at({0, 10, 10}), b = field->scale_at({40, 10, 10}), mid = field->scale_at({20, 10, 10});
  EXPECT_NEAR(a[0], 1.0, 0.02);
  EXPECT_NEAR(b[0], 4.0, 0.08);
  EXPECT_NEAR(b[2], 0.5, 0.01);
  EXPECT_GT(mid[0], 1.3);  // harmonic in log space: between the two
  EXPECT_LT(mid[0], 3.0);
  EXPECT_NEAR(mid[1], 1.0, 1e-6);
  EXPECT_NEAR(field->max_scale(), 4.0, 0.08);
  auto bad = parse_sketch_json(
      R"({"domain": {"min": [0, 0, 0], "max": [8, 8, 8]}, "curves": [{"points": [[1,1,1],[2,2,2]], "plane_normal": [0,0,1]}],
          "scales": [{"point": [1, 1, 1], "scale": [9, 1, 1]}]})");
  EXPECT_EQ(bad.status().field(), "scales[0].scale");
}

TEST(FieldFile, RoundTripAndDamage) {
  auto solver = FieldSolver::solve(parse_sketch_json(arc_sketch(6, 20, 6, false)).value()).value();
  StoredField f{solver->origin(), solver->spacing(), solver->dims(), 0, solver->nodes(), {}, "{}"};
  auto bytes = encode_field(f);
  auto back = decode_field(bytes);
  ASSERT_TRUE(back.is_ok());
  EXPECT_EQ(back->nodes.size(), f.nodes.size());
  EXPECT_EQ(back->nodes[5].x, f.nodes[5].x);
  EXPECT_EQ(back->sketch_json, "{}");
  auto cut = bytes;
  cut.resize(cut.size() - 3);
  EXPECT_EQ(decode_field(cut).status().code(), StatusCode::kCorrupt);
  auto flip = bytes;
  flip[100] ^= 1;
  EXPECT_EQ(decode_field(flip).status().code(), StatusCode::kCorrupt);
}

}  // namespace
}  // namespace solidtex
