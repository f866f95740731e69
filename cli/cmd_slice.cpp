// solidtex slice TABLE.stx (--axis x|y|z --at K --origin U,V | --plane OX,OY,OZ,UX,UY,UZ,VX,VY,VZ [--resample auto|nearest|cubic])
//   --size W,H [--scheme plain|subpass|grid|dual-grid] [--field identity|quat:W,X,Y,Z|axis:..|FILE]
//   [--seed S] [--threads T] [--passes P] [--coarse-passes P] [--cell M] -o OUT.png [--stats STATS.json]
//   [--reference REF.png] (axis cuts: the exemplar of the cut's plane, oriented as the cut)
#include <nlohmann/json.hpp>

#include <fstream>
#include <iostream>

#include "args.h"
#include "core/byte_io.h"
#include "commands.h"
#include "core/image_io.h"
#include "progress_bar.h"
#include "testkit/quality.h"
#include "synthesis/region_volume.h"
#include "synthesis/synthesizer.h"
#include "analysis/table_file.h"

namespace solidtex::cli {

nlohmann::json stats_json(const SynthesisStats& s) {
  nlohmann::json levels = nlohmann::json::array();
  for (const LevelStats& l : s.levels)
    levels.push_back({{"level", l.level},
                      {"voxels", l.voxels},
                      {"corrections", l.corrections},
                      {"cache_hits", l.cache_hits},
                      {"needed_final", l.needed_final},
                      {"seconds", l.seconds}});
  return {{"levels", levels},
          {"voxels", s.voxels},
          {"corrections", s.corrections},
          {"seconds", s.seconds},
          {"dependency_seconds", s.dependency_seconds},
          {"corrections_per_second", s.seconds > 0 ? double(s.corrections) / s.seconds : 0.0},
          {"store_bytes", s.store_bytes},
          {"estimated_bytes", s.estimated_bytes},
          {"support_voxels", s.support_voxels}};
}

// The cut the options name, checked before any table loads; built once the tables are known
// (--resample auto, the default, takes their preferred_voxel_sampling).
struct CutArgs {
  int width = 0, height = 0;
  bool plane = false;
  std::vector<double> plane_vectors;      // --plane: origin, u, v
  std::optional<VoxelSampling> resample;  // --plane only; nullopt: auto
  char axis = 'z';
  int at = 0;
  std::vector<double> origin{0, 0};
};

Result<CutArgs> parse_cut(const Args& args) {
  CutArgs c;
  SOLIDTEX_ASSIGN_OR_RETURN(auto size, args.get_list("--size", 2));
  c.width = int(size[0]);
  c.height = int(size[1]);
  if (size[0] != c.width || size[1] != c.height) return Status(StatusCode::kInvalidArgument, "must be integers", "--size");
  if (args.has("--plane")) {
    if (args.has("--axis") || args.has("--at") || args.has("--origin"))
      return Status(StatusCode::kInvalidArgument, "give either --plane or --axis/--at/--origin", "--plane");
    c.plane = true;
    SOLIDTEX_ASSIGN_OR_RETURN(c.plane_vectors, args.get_list("--plane", 9));
    if (args.has("--resample")) {
      SOLIDTEX_ASSIGN_OR_RETURN(std::string name, args.required("--resample"));
      SOLIDTEX_ASSIGN_OR_RETURN(c.resample, parse_voxel_sampling(name, "--resample"));
    }
    return c;
  }
  if (args.has("--resample")) return Status(StatusCode::kInvalidArgument, "applies to --plane cuts only", "--resample");
  SOLIDTEX_ASSIGN_OR_RETURN(std::string axis, args.required("--axis"));
  if (axis.size() != 1) return Status(StatusCode::kInvalidArgument, "must be x, y or z", "--axis");
  c.axis = axis[0];
  SOLIDTEX_ASSIGN_OR_RETURN(c.at, args.get_int("--at", 0, -(1 << 28), 1 << 28));
  if (args.has("--origin")) {
    SOLIDTEX_ASSIGN_OR_RETURN(c.origin, args.get_list("--origin", 2));
  }
  return c;
}

// `preferred`: the sampling auto stands for.
Result<TargetSet> build_cut(const CutArgs& c, VoxelSampling preferred) {
  if (!c.plane) return TargetSet::axis_cut(c.axis, c.at, int(c.origin[0]), int(c.origin[1]), c.width, c.height);
  const auto& p = c.plane_vectors;
  return TargetSet::plane_cut({p[0], p[1], p[2]}, {p[3], p[4], p[5]}, {p[6], p[7], p[8]}, c.width, c.height, c.resample,
                              preferred);
}

// The exemplar an axis cut's plane was synthesized from, in the cut's pixel orientation:
// axis z shows plane xy (x right, y down), axis x plane yz (y right, z down), and axis y plane
// zx with its axes swapped (x right, z down; zx's first axis is z). So a cut along a y grain
// shows the grain the way its plane's image (E transposed) runs, and should be judged against it.
ImageF axis_cut_exemplar(const Table& table, char axis) {
  const Plane plane = axis == 'z' ? Plane::kXY : axis == 'x' ? Plane::kYZ : Plane::kZX;
  const ImageF& image = table.exemplars().plane(plane);
  ImageF rgb(image.width, image.height, 3);
  for (int64_t i = 0; i < image.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) rgb.pixels[size_t(i) * 3 + size_t(c)] = image.pixels[size_t(i) * image.channels + size_t(c)];
  return axis == 'y' ? transposed(rgb) : rgb;
}

Status run_slice(const std::vector<std::string>& argv) {
  Args args({"-o", "--axis", "--at", "--origin", "--plane", "--resample", "--size", "--scheme", "--field", "--seed", "--threads",
             "--stats", "--passes", "--coarse-passes", "--cell", "--cache-mb", "--plane-weights", "--matcher", "--region-table", "--regions",
             "--typicality", "--finest-typicality-scale", "--balance", "--init", "--init-band", "--color", "--finest-match", "--finest-sources",
             "--finest-subpass-size", "--reference"},
            {"--energy"});
  SOLIDTEX_RETURN_IF_ERROR(args.parse(argv));
  if (args.positionals().size() != 1)
    return Status(StatusCode::kInvalidArgument, "expects exactly one TABLE.stx", "table");
  SOLIDTEX_ASSIGN_OR_RETURN(std::string out, args.required("-o"));
  SOLIDTEX_ASSIGN_OR_RETURN(const CutArgs cut, parse_cut(args));
  if (cut.plane && args.has("--reference"))
    return Status(StatusCode::kInvalidArgument, "applies to axis cuts only", "--reference");
  SynthesisParams params;
  if (auto s = args.get("--scheme")) {
    SOLIDTEX_ASSIGN_OR_RETURN(params.scheme, parse_scheme(*s));
  }
  if (auto i = args.get("--init")) {
    SOLIDTEX_ASSIGN_OR_RETURN(params.init, parse_init(*i));
  }
  if (auto c = args.get("--color")) {
    SOLIDTEX_ASSIGN_OR_RETURN(params.color, parse_color_rule(*c));
  }
  if (auto f = args.get("--finest-match")) {
    SOLIDTEX_ASSIGN_OR_RETURN(params.finest_match, parse_finest_match(*f));
  }
  if (auto f = args.get("--finest-sources")) {
    SOLIDTEX_ASSIGN_OR_RETURN(params.finest_sources, parse_finest_sources(*f));
  }
  if (auto m = args.get("--matcher")) {
    SOLIDTEX_ASSIGN_OR_RETURN(params.matcher, parse_matcher(*m));
  }
  SOLIDTEX_ASSIGN_OR_RETURN(int seed, args.get_int("--seed", 1, 0, 1 << 30));
  params.seed = uint32_t(seed);
  SOLIDTEX_ASSIGN_OR_RETURN(params.passes, args.get_int("--passes", params.passes, 0, 8));
  SOLIDTEX_ASSIGN_OR_RETURN(params.coarse_passes, args.get_int("--coarse-passes", params.coarse_passes, 0, 8));
  SOLIDTEX_ASSIGN_OR_RETURN(params.cell_size, args.get_int("--cell", params.cell_size, 4, 64));
  SOLIDTEX_ASSIGN_OR_RETURN(params.finest_subpass_size, args.get_int("--finest-subpass-size", params.finest_subpass_size, 1, 2));
  SOLIDTEX_ASSIGN_OR_RETURN(params.init_band, args.get_int("--init-band", params.init_band, 0, 256));  // validate(): 0 or even >= 8
  SOLIDTEX_ASSIGN_OR_RETURN(auto table, load_table(args.positionals()[0]));
  params.plane_weights = table->params().suggested_plane_weights;
  if (args.has("--plane-weights")) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto w, args.get_list("--plane-weights", 3));
    params.plane_weights = {float(w[0]), float(w[1]), float(w[2])};
  }
  if (args.has("--typicality") && args.get("--typicality") != "auto") {  // absent or auto: per table
    SOLIDTEX_ASSIGN_OR_RETURN(double typicality, args.get_double("--typicality", kTypicality, 0, 4));
    params.typicality = float(typicality);
  }
  SOLIDTEX_ASSIGN_OR_RETURN(double finest_scale,
                            args.get_double("--finest-typicality-scale", params.finest_typicality_scale, 0, 1));
  params.finest_typicality_scale = float(finest_scale);
  SOLIDTEX_ASSIGN_OR_RETURN(double balance, args.get_double("--balance", params.balance, 0, 4));
  params.balance = float(balance);
  SOLIDTEX_RETURN_IF_ERROR(params.validate());
  SOLIDTEX_ASSIGN_OR_RETURN(int threads, args.get_int("--threads", 0, 0, 1024));
  set_thread_limit(threads);
  SOLIDTEX_ASSIGN_OR_RETURN(int cache_mb, args.get_int("--cache-mb", 256, 0, 1 << 20));
  SOLIDTEX_ASSIGN_OR_RETURN(auto field, parse_field_spec(args.get("--field").value_or("identity")));
  SOLIDTEX_ASSIGN_OR_RETURN(auto synth, Synthesizer::create(table, field, params, int64_t(cache_mb) << 20));
  if (args.has("--region-table") != args.has("--regions"))
    return Status(StatusCode::kInvalidArgument, "--region-table and --regions go together", "--regions");
  std::vector<std::shared_ptr<const Table>> tables{table};
  if (auto second = args.get("--region-table")) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto table2, load_table(*second));
    tables.push_back(table2);
  }
  // Only a plane cut left to auto needs the tables' preference (it reads their exemplars).
  const VoxelSampling preferred =
      cut.plane && !cut.resample ? preferred_voxel_sampling(tables, params.color) : VoxelSampling::kNearest;
  SOLIDTEX_ASSIGN_OR_RETURN(const TargetSet target, build_cut(cut, preferred));
  ProgressBar bar;
  SynthesisStats stats;
  std::vector<std::array<float, 3>> rgb;
  if (tables.size() == 2) {
    // Label 1 of --regions takes the second table's texture (same field and parameters).
    SOLIDTEX_ASSIGN_OR_RETURN(auto label, RegionLabel::parse(*args.get("--regions")));
    const auto& table2 = tables[1];
    SynthesisParams p2 = params;
    if (!args.has("--plane-weights")) p2.plane_weights = table2->params().suggested_plane_weights;
    SOLIDTEX_ASSIGN_OR_RETURN(auto synth2, Synthesizer::create(table2, field, p2, int64_t(cache_mb) << 20));
    SOLIDTEX_ASSIGN_OR_RETURN(auto volume, RegionVolume::create({synth, synth2}, label));
    std::vector<SynthesisStats> per_region;
    SOLIDTEX_ASSIGN_OR_RETURN(rgb, volume->synthesize(target, bar, &per_region));
    for (const SynthesisStats& r : per_region) {
      stats.voxels += r.voxels;
      stats.corrections += r.corrections;
      stats.seconds += r.seconds;
    }
  } else {
    SOLIDTEX_ASSIGN_OR_RETURN(rgb, synth->synthesize(target, bar, &stats));
  }
  ImageF img(target.width, target.height, 3);
  for (size_t i = 0; i < rgb.size(); ++i)
    for (int c = 0; c < 3; ++c) img.pixels[i * 3 + size_t(c)] = rgb[i][size_t(c)];
  SOLIDTEX_RETURN_IF_ERROR(save_png_srgb8(out, img));
  nlohmann::json j = stats_json(stats);
  j["scheme"] = scheme_name(params.scheme);
  j["matcher"] = matcher_name(params.matcher);
  j["field"] = field->describe();
  if (cut.plane) j["resample"] = voxel_sampling_name(target.sampling());
  if (args.has("--energy")) {
    // Neighborhood-matching energy of the cut against exemplar xy (quality.h).
    j["energy"] = neighborhood_energy(img, table->exemplars().plane(Plane::kXY), table->params().neighborhood, 2);
    std::cerr << "energy " << j["energy"] << "\n";
  }
  if (auto path = args.get("--reference")) {
    SOLIDTEX_RETURN_IF_ERROR(save_png_srgb8(*path, axis_cut_exemplar(*table, cut.axis)));
  }
  if (auto path = args.get("--stats")) {
    const std::string text = j.dump(2) + "\n";
    SOLIDTEX_RETURN_IF_ERROR(write_file_atomic(*path, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size())));
  }
  std::cerr << "wrote " << out << ": " << stats.voxels << " voxels, " << stats.corrections << " corrections in "
            << stats.seconds << " s\n";
  return Status::ok();
}

}  // namespace solidtex::cli
