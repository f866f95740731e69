// Benchmark: texturing meshes lazily. Prints one JSON object.
//   bench_surface TABLE.stx MESH_DIR [--resolutions 512,1024] [--synthesize-up-to N]
// For bunny, fertility, horse and armadillo at each resolution (placement: bounding box
// enlarged by 25% per side, longest side = resolution voxels), plain, subpass and dual-grid:
// vertices, distinct target voxels, the placed bounding box's voxels, the dependency sets
// (voxels and corrections over all levels, and per level), their fraction of the bounding
// box, and -- when the dual-grid correction count is at most --synthesize-up-to (default
// 40M) -- the wall time of the actual synthesis (fresh cache each time).
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstring>
#include <iostream>

#include "core/image_io.h"
#include "mesh/mesh.h"
#include "core/number_list.h"
#include "synthesis/synthesizer.h"
#include "analysis/table_file.h"

using namespace solidtex;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: bench_surface TABLE.stx MESH_DIR [--resolutions 512,1024] [--synthesize-up-to N]\n";
    return 2;
  }
  std::vector<int> resolutions{512, 1024};
  int64_t synth_limit = 40'000'000;
  for (int i = 3; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--resolutions") == 0) {
      resolutions.clear();
      const std::string s = argv[i + 1];
      size_t n = size_t(std::count(s.begin(), s.end(), ',') + 1);
      auto values = parse_number_list(s, n, "--resolutions");
      if (!values) {
        std::cerr << values.status().to_string() << "\n";
        return 2;
      }
      for (double v : *values) resolutions.push_back(int(v));
    } else if (std::strcmp(argv[i], "--synthesize-up-to") == 0) {
      synth_limit = std::atoll(argv[i + 1]);
    }
  }
  auto table = load_table(argv[1]);
  if (!table) {
    std::cerr << table.status().to_string() << "\n";
    return 1;
  }
  const std::string dir = argv[2];
  nlohmann::json runs = nlohmann::json::array();
  for (const char* name : {"bunny.off", "fertility.off", "horse.ply", "armadillo.obj"}) {
    auto bytes = read_file_bytes(dir + "/" + name, int64_t(1) << 30);
    if (!bytes) {
      std::cerr << "skipping " << name << ": " << bytes.status().to_string() << "\n";
      continue;
    }
    auto mesh = decode_mesh(*bytes);
    if (!mesh) {
      std::cerr << name << ": " << mesh.status().to_string() << "\n";
      return 1;
    }
    for (int res : resolutions) {
      auto fitted = fit_placement(mesh->bounds(), res, 0.25);
      if (!fitted) {
        std::cerr << name << ": " << fitted.status().to_string() << "\n";
        return 1;
      }
      const Placement placement = *fitted;
      std::vector<WorldPoint> world;
      for (const auto& v : mesh->vertices) world.push_back(placement.apply(v));
      auto points = TargetSet::points(world);
      if (!points) {
        std::cerr << name << ": " << points.status().to_string() << "\n";
        return 1;
      }
      const TargetSet target = std::move(*points);
      const int64_t bounding = bounding_voxels(mesh->bounds(), placement);
      for (Scheme scheme : {Scheme::kPlain, Scheme::kSubpass, Scheme::kDualGrid}) {
        SynthesisParams p;
        p.scheme = scheme;
        p.plane_weights = (*table)->params().suggested_plane_weights;
        auto created = Synthesizer::create(*table, parse_field_spec("identity").value(), p, int64_t(4) << 30);
        if (!created) {
          std::cerr << created.status().to_string() << "\n";
          return 1;
        }
        auto synth = *created;
        SynthesisStats deps;
        SynthesisOptions only;
        only.dependencies_only = true;
        only.use_cache = false;
        if (auto r = synth->synthesize(target, null_interrupter(), &deps, only); !r) {
          std::cerr << r.status().to_string() << "\n";
          return 1;
        }
        nlohmann::json levels = nlohmann::json::array();
        for (const auto& l : deps.levels) levels.push_back({{"level", l.level}, {"voxels", l.voxels}, {"corrections", l.corrections}});
        nlohmann::json run = {{"mesh", name},
                              {"resolution", res},
                              {"scheme", scheme_name(scheme)},
                              {"vertices", int64_t(mesh->vertices.size())},
                              {"target_voxels", int64_t(target.voxels.size())},
                              {"bounding_voxels", bounding},
                              {"voxels", deps.voxels},
                              {"corrections", deps.corrections},
                              {"fraction_of_bounding_box", double(deps.voxels) / double(bounding)},
                              {"dependency_seconds", deps.dependency_seconds},
                              {"levels", levels}};
        if (deps.corrections <= synth_limit) {
          SynthesisStats s;
          const auto t0 = std::chrono::steady_clock::now();
          if (!synth->synthesize(target, null_interrupter(), &s)) return 1;
          run["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          run["corrections_per_second"] = double(s.corrections) / s.seconds;
        } else {
          run["seconds"] = nullptr;  // above --synthesize-up-to: sets measured, not synthesized
        }
        std::cerr << name << " " << res << " " << scheme_name(scheme) << ": " << deps.voxels << " voxels, "
                  << deps.corrections << " corrections" << (run["seconds"].is_null() ? "" : ", " + run["seconds"].dump() + " s") << "\n";
        runs.push_back(run);
      }
    }
  }
  std::cout << nlohmann::json{{"benchmark", "surface"}, {"table", argv[1]}, {"runs", runs}}.dump(2) << "\n";
  return 0;
}
