// Benchmark: frame-field solve and incremental update times. Prints one JSON object.
// Grids of 24^3 and 48^3 nodes' cells with 1, 5 and 20 curves (random-looking but fixed arcs):
// "solve" solves all curves from scratch; "add_curve" is the time to add the last curve to a
// field that already holds the others (the interactive case).
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <iostream>

#include "core/hash.h"
#include "field/tensor_field.h"

using namespace solidtex;

int main() {
  nlohmann::json runs = nlohmann::json::array();
  for (int cells : {24, 32, 48}) {
    for (int curves : {1, 5, 20}) {
      Sketch sk;
      sk.domain = {{0, 0, 0}, {96, 96, 96}, cells};
      for (int c = 0; c < curves; ++c) {
        SketchCurve cv;
        const double cx = 20 + 56 * hash_unit(hash_u64(c, 1)), cy = 20 + 56 * hash_unit(hash_u64(c, 2));
        const double cz = 10 + 76 * hash_unit(hash_u64(c, 3)), r = 6 + 12 * hash_unit(hash_u64(c, 4));
        for (int i = 0; i < 12; ++i) {
          const double a = 2.0 * i / 11;
          cv.points.push_back({cx + r * std::cos(a), cy + r * std::sin(a), cz});
        }
        cv.plane_normal = WorldPoint{0, 0, 1};
        if (c == 0) cv.axis = 0;
        sk.curves.push_back(cv);
      }
      FieldSolveStats full, incremental;
      const auto t0 = std::chrono::steady_clock::now();
      auto solver = FieldSolver::solve(sk, &full).value();
      const double solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      Sketch first = sk;
      first.curves.pop_back();
      double add_seconds = 0;
      if (!first.curves.empty()) {
        auto partial = FieldSolver::solve(first).value();
        const auto t1 = std::chrono::steady_clock::now();
        if (!partial->add_curve(sk.curves.back(), curves - 1, &incremental).is_ok()) return 1;
        add_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      } else {
        add_seconds = solve_seconds;
      }
      const auto d = solver->dims();
      runs.push_back({{"cells", cells},
                      {"nodes", int64_t(d[0]) * d[1] * d[2]},
                      {"curves", curves},
                      {"solve_seconds", solve_seconds},
                      {"add_curve_seconds", add_seconds},
                      {"residual", full.residual},
                      {"singular_nodes", full.singular_nodes}});
    }
  }
  std::cout << nlohmann::json{{"benchmark", "field"}, {"runs", runs}}.dump() << "\n";
  return 0;
}
