// solidtex analyze IMAGE [--yz IMAGE --zx IMAGE] [--mask IMAGE [--mask-yz IMAGE --mask-zx IMAGE]]
//   [--mask-weight W] [--levels auto|L] [--neighborhood 9] [--candidates 12] [--pca-dims 20]
//   [--search-k 24] [--knn-checks 192] [--balance-rounds 3] [--balance-box 24] [--balance-strength 0.025]
//   [--balance-fine-gain 2]
//   [--seed S] [--threads T] [--grain auto|none|x|y|crossed] -o TABLE.stx [--json]
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "analysis/analysis.h"

#include "args.h"
#include "core/byte_io.h"
#include "commands.h"
#include "core/image_io.h"
#include "progress_bar.h"
#include "synthesis/voxel_sampling.h"
#include "synthesis/usage_balance.h"
#include "analysis/table_file.h"

namespace solidtex::cli {
namespace {

Result<std::optional<ImageF>> optional_image(const Args& args, const std::string& flag, const char* field) {
  auto path = args.get(flag);
  if (!path) return std::optional<ImageF>();
  SOLIDTEX_ASSIGN_OR_RETURN(ImageF img, load_image(*path, {}, field));
  return std::optional<ImageF>(std::move(img));
}

}  // namespace

Status run_analyze(const std::vector<std::string>& argv) {
  Args args({"-o", "--yz", "--zx", "--mask", "--mask-yz", "--mask-zx", "--mask-weight", "--levels",
             "--neighborhood", "--candidates", "--pca-dims", "--search-k", "--knn-checks", "--seed", "--threads", "--grain",
             "--balance-rounds", "--balance-box", "--balance-strength", "--balance-fine-gain"},
            {"--json"});
  SOLIDTEX_RETURN_IF_ERROR(args.parse(argv));
  if (args.positionals().size() != 1)
    return Status(StatusCode::kInvalidArgument, "expects exactly one exemplar IMAGE", "image");
  SOLIDTEX_ASSIGN_OR_RETURN(std::string out, args.required("-o"));

  AnalysisParams params;
  // auto (the default) is kAutoLevels, resolved from the exemplar's size before analysis.
  if (const auto v = args.get("--levels"); v && *v != "auto") {
    Result<int> n = args.get_int("--levels", params.levels, 1, 8);
    if (!n) return Status(StatusCode::kInvalidArgument, "is '" + *v + "'; must be auto or an integer in [1, 8]", "--levels");
    params.levels = int(*n);
  }
  SOLIDTEX_ASSIGN_OR_RETURN(params.neighborhood, args.get_int("--neighborhood", params.neighborhood, 3, 15));
  SOLIDTEX_ASSIGN_OR_RETURN(params.candidates, args.get_int("--candidates", params.candidates, 1, 32));
  SOLIDTEX_ASSIGN_OR_RETURN(params.pca_dims, args.get_int("--pca-dims", params.pca_dims, 1, 64));
  SOLIDTEX_ASSIGN_OR_RETURN(int seed, args.get_int("--seed", 1, 0, 1 << 30));
  params.seed = uint32_t(seed);
  SOLIDTEX_ASSIGN_OR_RETURN(params.search_k, args.get_int("--search-k", std::max(params.search_k, params.candidates / 2 + 1),
                                                          params.candidates / 2 + 1, 64));
  SOLIDTEX_ASSIGN_OR_RETURN(params.knn_checks, args.get_int("--knn-checks", params.knn_checks, 16, 100000));
  UsageBalanceParams balance;
  SOLIDTEX_ASSIGN_OR_RETURN(balance.rounds, args.get_int("--balance-rounds", balance.rounds, 0, 8));
  SOLIDTEX_ASSIGN_OR_RETURN(balance.box, args.get_int("--balance-box", balance.box, 8, 64));
  SOLIDTEX_ASSIGN_OR_RETURN(double strength, args.get_double("--balance-strength", balance.strength, 0, 1));
  balance.strength = float(strength);
  SOLIDTEX_ASSIGN_OR_RETURN(double fine_gain, args.get_double("--balance-fine-gain", balance.fine_gain, 0.25, 4));
  balance.fine_gain = float(fine_gain);
  SOLIDTEX_RETURN_IF_ERROR(balance.validate());
  SOLIDTEX_RETURN_IF_ERROR(params.validate());
  SOLIDTEX_ASSIGN_OR_RETURN(int threads, args.get_int("--threads", 0, 0, 1024));
  set_thread_limit(threads);

  ExemplarInputs in;
  SOLIDTEX_ASSIGN_OR_RETURN(in.xy, load_image(args.positionals()[0], {}, "image"));
  SOLIDTEX_ASSIGN_OR_RETURN(in.yz, optional_image(args, "--yz", "yz"));
  SOLIDTEX_ASSIGN_OR_RETURN(in.zx, optional_image(args, "--zx", "zx"));
  SOLIDTEX_ASSIGN_OR_RETURN(in.mask_xy, optional_image(args, "--mask", "mask"));
  SOLIDTEX_ASSIGN_OR_RETURN(in.mask_yz, optional_image(args, "--mask-yz", "mask_yz"));
  SOLIDTEX_ASSIGN_OR_RETURN(in.mask_zx, optional_image(args, "--mask-zx", "mask_zx"));
  const std::string grain = args.get("--grain").value_or("auto");
  Result<std::string> layout = apply_grain_layout(grain, in, params.suggested_plane_weights);
  if (!layout) return layout.status().with_context("--grain");
  if (grain == "auto" && !layout->empty())
    std::fprintf(stderr, "grain: the exemplar is striped along %s; analysing with --grain %s (--grain none to keep it isotropic)\n",
                 layout->c_str(), layout->c_str());
  SOLIDTEX_ASSIGN_OR_RETURN(double mw, args.get_double("--mask-weight", 1.0, 0.0, 10.0));
  in.mask_weight = float(mw);
  SOLIDTEX_ASSIGN_OR_RETURN(ExemplarSet exemplars, ExemplarSet::create(std::move(in)));

  ProgressBar bar;
  SOLIDTEX_ASSIGN_OR_RETURN(AnalysisResult result, analyze(exemplars, params, bar));
  // Usage penalties are calibrated by synthesis, so they are a step after analysis proper.
  const auto balance_start = std::chrono::steady_clock::now();
  SOLIDTEX_ASSIGN_OR_RETURN(result.table, balance_usage(result.table, balance, bar));
  const double balance_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - balance_start).count();
  const std::vector<uint8_t> bytes = encode_table(*result.table);
  SOLIDTEX_RETURN_IF_ERROR(write_file_atomic(out, bytes));

  if (args.has("--json")) {
    nlohmann::json j;
    j["table"] = out;
    j["seconds"] = result.seconds;
    j["balance_seconds"] = balance_seconds;
    j["table_bytes"] = bytes.size();
    j["shared_exemplar"] = exemplars.shared();
    j["grain"] = *layout;
    j["channels"] = exemplars.channels();
    // What its oblique cuts' resample auto will be (synthesis/voxel_sampling.h).
    j["fine_detail_share"] = fine_detail_share(*result.table);
    j["cut_resample"] = voxel_sampling_name(preferred_voxel_sampling(*result.table, SynthesisParams{}.color));
    nlohmann::json levels = nlohmann::json::array();
    for (const LevelReport& r : result.levels)
      levels.push_back({{"level", r.level},
                        {"spacing", r.spacing},
                        {"mean_crossbar_error", r.mean_crossbar_error},
                        {"random_crossbar_error", r.random_crossbar_error},
                        {"error_ratio", r.random_crossbar_error > 0 ? r.mean_crossbar_error / r.random_crossbar_error : 0.0},
                        {"coherent_fraction", r.coherent_fraction}});
    j["levels"] = levels;
    j["params"] = {{"levels", result.table->params().levels},       {"neighborhood", params.neighborhood},
                   {"candidates", params.candidates}, {"pca_dims", params.pca_dims},
                   {"search_k", params.search_k},     {"knn_checks", params.knn_checks},
                   {"seed", params.seed},             {"balance_rounds", balance.rounds},
                   {"balance_box", balance.box},      {"balance_strength", balance.strength},
                   {"balance_fine_gain", balance.fine_gain}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "wrote " << out << " (" << bytes.size() << " bytes) in " << result.seconds << " s + "
              << balance_seconds << " s usage balancing\n";
    for (const LevelReport& r : result.levels)
      std::cout << "  level " << r.level << " (h=" << r.spacing << "): crossbar error " << r.mean_crossbar_error
                << " vs random " << r.random_crossbar_error << "\n";
  }
  return Status::ok();
}

}  // namespace solidtex::cli
