// Benchmark: exemplar analysis time and peak memory. Prints one JSON object. `total_seconds` is
// what an analysis job costs (issue 12's "analysis of a 128^2 exemplar <= 5 s"): the analysis
// proper (`seconds`) plus the usage-balance calibration (`balance_seconds`) that every table
// the CLI and the service write goes through.
//   bench_analysis SIZE [IMAGE]   (procedural wood of SIZE^2 when IMAGE is absent)
// Run each size in its own process (scripts/run-benchmarks.sh) so peak RSS is per size.
#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include <chrono>
#include <iostream>

#include "analysis/analysis.h"
#include "core/image_io.h"
#include "testkit/procedural_exemplar.h"
#include "analysis/table_file.h"
#include "synthesis/usage_balance.h"

int main(int argc, char** argv) {
  using namespace solidtex;
  if (argc < 2) {
    std::cerr << "usage: bench_analysis SIZE [IMAGE]\n";
    return 2;
  }
  const int size = std::atoi(argv[1]);
  ExemplarInputs in;
  std::string source = "procedural:wood";
  if (argc > 2) {
    auto img = load_image(argv[2]);
    if (!img) {
      std::cerr << img.status().to_string() << "\n";
      return 1;
    }
    in.xy = std::move(img).value();
    source = argv[2];
  } else {
    in.xy = make_procedural_exemplar({ProceduralKind::kWood, size, size, 1}).value();
  }
  auto set = ExemplarSet::create(std::move(in));
  if (!set) {
    std::cerr << set.status().to_string() << "\n";
    return 1;
  }
  AnalysisParams params;  // defaults: levels auto (from the exemplar's size), N = 9, N_T = 12, 20 PCA dims
  auto r = analyze(*set, params);
  if (!r) {
    std::cerr << r.status().to_string() << "\n";
    return 1;
  }
  const auto balance_start = std::chrono::steady_clock::now();
  auto balanced = balance_usage(r->table);
  if (!balanced) {
    std::cerr << balanced.status().to_string() << "\n";
    return 1;
  }
  const double balance_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - balance_start).count();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  nlohmann::json j;
  j["benchmark"] = "analysis";
  j["source"] = source;
  j["width"] = set->plane(Plane::kXY).width;
  j["height"] = set->plane(Plane::kXY).height;
  j["levels"] = r->table->params().levels;
  j["seconds"] = r->seconds;
  j["balance_seconds"] = balance_seconds;
  j["total_seconds"] = r->seconds + balance_seconds;
  j["peak_rss_mb"] = double(ru.ru_maxrss) / 1024.0;
  // What the service admits analyses by (--max-request-mb): it should not be far below the peak.
  j["estimated_mb"] = double(estimate_analysis_bytes(*set, params)) / double(1 << 20);
  j["table_bytes"] = encode_table(**balanced).size();
  nlohmann::json lv = nlohmann::json::array();
  for (const auto& l : r->levels) lv.push_back({{"level", l.level}, {"ratio_to_random", l.mean_crossbar_error / l.random_crossbar_error}});
  j["crossbar_error_ratio"] = lv;
  std::cout << j.dump() << "\n";
  return 0;
}
