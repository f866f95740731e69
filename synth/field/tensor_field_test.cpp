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
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) about "literal" + std::string.
    s += i ? ",[" : "[";
    s += std::to_string(radius * std::cos(a));
    s += ',';
    s += std::to_string(radius * std::sin(a));
    s += ",0]";
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

// Records what an operation reports and asks it to stop at the `stop_at`-th poll (0: never).
class RecordingInterrupter : public Interrupter {
 public:
  explicit RecordingInterrupter(int stop_at = 0) : stop_at_(stop_at) {}
  void start(const char*) override { ++starts; }
  void end() override { ++ends; }
  bool was_interrupted(int percent) override {
    percents.push_back(percent);
    return stop_at_ > 0 && int(percents.size()) >= stop_at_;
  }
  std::vector<int> percents;
  int starts = 0, ends = 0;

 private:
  int stop_at_;
};

bool same_nodes(const FieldSolver& a, const FieldSolver& b) {
  if (a.nodes().size() != b.nodes().size()) return false;
  for (size_t i = 0; i < a.nodes().size(); ++i) {
    const Quat &p = a.nodes()[i], &q = b.nodes()[i];
    if (p.w != q.w || p.x != q.x || p.y != q.y || p.z != q.z) return false;
  }
  return true;
}

TEST(TensorField, SolveReportsProgressAcrossItsSteps) {
  auto sketch = parse_sketch_json(arc_sketch(8, 20, 12, true)).value();
  sketch.scales = {{{0, 0, 0}, {2, 1, 1}, 100.0}};
  RecordingInterrupter rec;
  FieldSolveStats st;
  auto solved = FieldSolver::solve(sketch, &st, rec);
  ASSERT_TRUE(solved.is_ok()) << solved.status().to_string();
  EXPECT_EQ(rec.starts, 1);
  EXPECT_EQ(rec.ends, 1);
  // Polled inside the conjugate-gradient loops, not just between the three steps.
  EXPECT_GT(rec.percents.size(), 30u);
  ASSERT_FALSE(rec.percents.empty());
  EXPECT_EQ(rec.percents.front(), 0);
  for (size_t i = 1; i < rec.percents.size(); ++i) ASSERT_GE(rec.percents[i], rec.percents[i - 1]) << i;
  EXPECT_GE(rec.percents.back(), 66);  // the scales, the last of 3 steps, start at 66%
  EXPECT_LT(rec.percents.back(), 100);
  // The interrupter changes nothing in the result.
  auto plain = FieldSolver::solve(sketch).value();
  EXPECT_TRUE(same_nodes(**solved, *plain));
  EXPECT_EQ((*solved)->log_scales(), plain->log_scales());
}

TEST(TensorField, CancellationStopsTheSolve) {
  const Sketch sketch = parse_sketch_json(arc_sketch(8, 20, 12, true)).value();
  RecordingInterrupter never;
  ASSERT_TRUE(FieldSolver::solve(sketch, nullptr, never).is_ok());
  const size_t polls = never.percents.size();
  ASSERT_GT(polls, 10u);
  // Before the first solve, inside the first CG loop, and late in the last one.
  for (size_t stop_at : {size_t(1), size_t(3), polls - 1}) {
    RecordingInterrupter stop{int(stop_at)};
    auto r = FieldSolver::solve(sketch, nullptr, stop);
    ASSERT_FALSE(r.is_ok()) << stop_at;
    EXPECT_EQ(r.status().code(), StatusCode::kCancelled) << stop_at;
    EXPECT_EQ(stop.percents.size(), stop_at) << "polled again after asking to stop";
    EXPECT_EQ(stop.starts, 1);
    EXPECT_EQ(stop.ends, 1);
  }
}

TEST(TensorField, CancelledIncrementalUpdateLeavesTheSolverAsItWas) {
  const Sketch both = parse_sketch_json(arc_sketch(8, 20, 12, true)).value();
  Sketch first = both;
  first.curves.resize(1);
  auto solver = FieldSolver::solve(first).value();
  auto reference = FieldSolver::solve(first).value();
  ASSERT_TRUE(same_nodes(*solver, *reference));
  RecordingInterrupter stop(5);
  const Status st = solver->add_curve(both.curves[1], 1, nullptr, stop);
  EXPECT_EQ(st.code(), StatusCode::kCancelled);
  EXPECT_EQ(solver->curve_count(), 1);
  EXPECT_TRUE(same_nodes(*solver, *reference));
  // An invalid curve is refused without a trace too.
  SketchCurve bad = both.curves[1];
  bad.points[1] = {1000, 0, 0};
  EXPECT_EQ(solver->add_curve(bad, 1).field(), "curves[1].points[1]");
  // ... so the same update done afterwards is exactly the one never interrupted.
  ASSERT_TRUE(solver->add_curve(both.curves[1], 1).is_ok());
  ASSERT_TRUE(reference->add_curve(both.curves[1], 1).is_ok());
  EXPECT_EQ(solver->curve_count(), 2);
  EXPECT_TRUE(same_nodes(*solver, *reference));
}

TEST(TensorField, NodeLimitIsCheckedBeforeAllocatingAndNamesTheField) {
  SketchDomain d;
  d.min = {0, 0, 0};
  d.max = {8, 8, 8};
  d.shortest_side_cells = 8;  // 9^3 = 729 nodes
  EXPECT_TRUE(FieldSolver::create(d, 729).is_ok());
  auto over = FieldSolver::create(d, 728);
  ASSERT_FALSE(over.is_ok());
  EXPECT_EQ(over.status().code(), StatusCode::kUnprocessable);
  EXPECT_EQ(over.status().field(), "domain.shortest_side_cells");
  EXPECT_NE(over.status().message().find("729 nodes; the limit is 728"), std::string::npos) << over.status().message();

  // 2200000001 x 3 x 3 nodes: more than an int holds along x, rejected rather than overflowed.
  d.max = {1.1e9, 1, 1};
  d.shortest_side_cells = 2;
  auto wide = FieldSolver::create(d);
  ASSERT_FALSE(wide.is_ok());
  EXPECT_EQ(wide.status().code(), StatusCode::kTooLarge);
  EXPECT_EQ(wide.status().field(), "domain.shortest_side_cells");
  EXPECT_NE(wide.status().message().find("19800000009 nodes"), std::string::npos) << wide.status().message();
  // More nodes than an int64 holds.
  d.max = {1e150, 1, 1};
  d.shortest_side_cells = 256;
  auto vast = FieldSolver::create(d);
  EXPECT_EQ(vast.status().code(), StatusCode::kTooLarge);
  EXPECT_NE(vast.status().message().find("about 1.69e+157 nodes"), std::string::npos) << vast.status().message();
  // An extent that is not a finite number.
  d.min = {-1e308, 0, 0};
  d.max = {1e308, 1, 1};
  auto inf = FieldSolver::create(d);
  EXPECT_EQ(inf.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(inf.status().field(), "domain");

  // solve() passes the limit on.
  const Sketch sketch = parse_sketch_json(arc_sketch(8, 20, 12, false)).value();
  auto limited = FieldSolver::solve(sketch, nullptr, null_interrupter(), 100);
  EXPECT_EQ(limited.status().code(), StatusCode::kUnprocessable);
  EXPECT_EQ(limited.status().field(), "domain.shortest_side_cells");
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
