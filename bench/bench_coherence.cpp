// Benchmark (diagnostic, issue #12): how coherent a cut's coordinate triples are, level by
// level, and how far the three exemplar pixels of a finest triple agree. Prints one JSON object.
//   bench_coherence TABLE.stx [--size N] [--typicality auto|T] [--passes P] [--finest-subpass-size S]
//                   [--finest-match auto|triple|plane] [--finest-sources cross|square]
// A z cut N x N (default 128) at z = 0, identity field, default parameters otherwise (the
// table's suggested plane weights), synthesized twice: as configured, and with no correction
// at the finer levels (upsampling only: the coarsest level's result carried down). Per level:
//  - `coherent[plane]`: of the pairs of in-cut neighbours along an axis of that plane, the
//    fraction whose plane coordinates differ by exactly that step (wrapping): 2D k-coherence
//    synthesis makes this high (copied patches); incoherent triples make mosaics;
//  - `table_coherent_fraction`: the table's stored triples coherent with a neighbour's (analysis).
// Finest level only: `color_spread`, the mean squared RGB difference between the triple's three
// pixels (over pairs) relative to twice the exemplar's colour variance (0: they agree; 1: as
// unrelated as random pixels), and `medoid_picks` per plane of the output color rule.
#include <nlohmann/json.hpp>

#include <cstring>
#include <iostream>
#include <optional>
#include <string>

#include "analysis/table_file.h"
#include "field/tensor_field.h"
#include "synthesis/correction.h"
#include "synthesis/synthesizer.h"

using namespace solidtex;

namespace {

struct Options {
  std::string table;
  int size = 128;
  std::optional<float> typicality = SynthesisParams{}.typicality;  // absent: auto, per table
  int passes = SynthesisParams{}.passes;
  int finest_subpass_size = SynthesisParams{}.finest_subpass_size;
  FinestMatch finest_match = SynthesisParams{}.finest_match;
  FinestSources finest_sources = SynthesisParams{}.finest_sources;
};

// "auto" is absent (resolved per table), anything else a weight.
std::optional<float> typicality_arg(const std::string& s) {
  if (s == "auto") return std::nullopt;
  return float(std::atof(s.c_str()));
}

// Steps of each plane's coordinate when moving one voxel along world x or y (a z cut's axes):
// plane k's first/second axes (types.h) are xy: (x, y), yz: (y, z), zx: (z, x).
ExemplarPixel plane_step(int plane, int world_axis, int h) {
  const int first = kPlaneFirstAxis[size_t(plane)], second = kPlaneSecondAxis[size_t(plane)];
  return {first == world_axis ? h : 0, second == world_axis ? h : 0};
}

nlohmann::json measure(const Table& table, VoxelCache& cache, int n, const PlaneWeights& weights) {
  const ExemplarSet& ex = table.exemplars();
  const int levels = table.levels();
  nlohmann::json out = nlohmann::json::array();
  for (int l = 0; l < levels; ++l) {
    const int h = table.spacing(PyramidLevel{l});
    const int m = std::max(1, n / h);
    std::vector<Voxel> voxels;
    for (int y = 0; y < m; ++y)
      for (int x = 0; x < m; ++x) voxels.push_back({x, y, 0});
    std::vector<CoordinateTriple> triples;
    std::vector<uint8_t> found;
    cache.lookup(PyramidLevel{l}, voxels, triples, found);
    nlohmann::json coherent = nlohmann::json::object();
    for (int plane = 0; plane < 3; ++plane) {
      const ImageF& img = ex.plane(plane_from_index(plane));
      int64_t pairs = 0, same = 0;
      for (int axis = 0; axis < 2; ++axis) {  // world x, world y
        const ExemplarPixel step = plane_step(plane, axis, h);
        if (step.x == 0 && step.y == 0) continue;  // the plane does not contain this axis
        for (int y = 0; y + (axis == 1) < m; ++y)
          for (int x = 0; x + (axis == 0) < m; ++x) {
            const size_t i = size_t(y) * m + x, j = i + (axis == 0 ? 1 : size_t(m));
            if (!found[i] || !found[j]) continue;
            ++pairs;
            const ExemplarPixel a = triples[i].at[size_t(plane)], b = triples[j].at[size_t(plane)];
            same += ImageF::wrap(a.x + step.x, img.width) == ImageF::wrap(b.x, img.width) &&
                    ImageF::wrap(a.y + step.y, img.height) == ImageF::wrap(b.y, img.height);
          }
      }
      coherent[plane_name(plane_from_index(plane))] = pairs ? double(same) / double(pairs) : 0.0;
    }
    nlohmann::json level = {{"level", l},
                            {"spacing", h},
                            {"voxels", m * m},
                            {"coherent", coherent},
                            {"table_coherent_fraction", table.level(PyramidLevel{l}).candidates->coherent_fraction}};
    if (l == levels - 1) {
      const ImageF& xy = ex.plane(Plane::kXY);
      double mean[3] = {0, 0, 0}, var = 0;
      const int64_t count = xy.pixel_count();
      for (int64_t i = 0; i < count; ++i)
        for (int c = 0; c < 3; ++c) mean[c] += xy.pixels[size_t(i) * xy.channels + c] / double(count);
      for (int64_t i = 0; i < count; ++i)
        for (int c = 0; c < 3; ++c) {
          const double d = xy.pixels[size_t(i) * xy.channels + c] - mean[c];
          var += d * d / double(count);
        }
      double spread = 0;
      int64_t counted = 0;
      std::array<int64_t, 3> picks{};
      for (size_t i = 0; i < triples.size(); ++i) {
        if (!found[i]) continue;
        std::array<const float*, 3> px;
        for (int k = 0; k < 3; ++k)
          px[size_t(k)] = ex.plane(plane_from_index(k)).wrapped(triples[i].at[size_t(k)].x, triples[i].at[size_t(k)].y);
        double s = 0;
        for (int a = 0; a < 3; ++a)
          for (int b = a + 1; b < 3; ++b)
            for (int c = 0; c < 3; ++c) s += double(px[size_t(a)][c] - px[size_t(b)][c]) * (px[size_t(a)][c] - px[size_t(b)][c]);
        spread += s / 3.0;
        ++counted;
        float rgb[3];
        output_color(table, triples[i], weights, ColorRule::kMedoid, rgb);
        for (int k = 0; k < 3; ++k)
          if (rgb[0] == px[size_t(k)][0] && rgb[1] == px[size_t(k)][1] && rgb[2] == px[size_t(k)][2]) {
            ++picks[size_t(k)];
            break;
          }
      }
      level["color_spread"] = counted && var > 0 ? spread / double(counted) / (2.0 * var) : 0.0;
      level["medoid_picks"] = {{"xy", picks[0]}, {"yz", picks[1]}, {"zx", picks[2]}};
    }
    out.push_back(level);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--size" && has_value) o.size = std::atoi(argv[++i]);
    else if (a == "--typicality" && has_value) o.typicality = typicality_arg(argv[++i]);
    else if (a == "--passes" && has_value) o.passes = std::atoi(argv[++i]);
    else if (a == "--finest-subpass-size" && has_value) o.finest_subpass_size = std::atoi(argv[++i]);
    else if (a == "--finest-match" && has_value) {
      auto m = parse_finest_match(argv[++i]);
      if (!m) {
        std::cerr << m.status().to_string() << "\n";
        return 2;
      }
      o.finest_match = *m;
    } else if (a == "--finest-sources" && has_value) {
      auto m = parse_finest_sources(argv[++i]);
      if (!m) {
        std::cerr << m.status().to_string() << "\n";
        return 2;
      }
      o.finest_sources = *m;
    } else if (o.table.empty() && a.rfind("--", 0) != 0) o.table = a;
    else {
      std::cerr << "usage: bench_coherence TABLE.stx [--size N] [--typicality auto|T] [--passes P] [--finest-subpass-size S] "
                   "[--finest-match auto|triple|plane] [--finest-sources cross|square]\n";
      return 2;
    }
  }
  if (o.table.empty() || o.size < 8 || o.size > 1024) {
    std::cerr << "usage: bench_coherence TABLE.stx [--size N (8..1024)] [--typicality auto|T] [--passes P]\n";
    return 2;
  }
  auto table = load_table(o.table);
  if (!table) {
    std::cerr << table.status().to_string() << "\n";
    return 1;
  }
  nlohmann::json out = {{"benchmark", "coherence"}, {"table", o.table}, {"size", o.size}};
  for (const bool corrected : {true, false}) {
    SynthesisParams p;
    p.plane_weights = (*table)->params().suggested_plane_weights;
    p.typicality = o.typicality;
    p.passes = corrected ? o.passes : 0;
    p.finest_subpass_size = o.finest_subpass_size;
    p.finest_match = o.finest_match;
    p.finest_sources = o.finest_sources;
    if (Status s = p.validate(); !s.is_ok()) {
      std::cerr << s.to_string() << "\n";
      return 2;
    }
    auto synth = Synthesizer::create(*table, parse_field_spec("identity").value(), p, int64_t(1) << 31);
    if (!synth) {
      std::cerr << synth.status().to_string() << "\n";
      return 1;
    }
    auto target = TargetSet::axis_cut('z', 0, 0, 0, o.size, o.size);
    auto colors = (*synth)->synthesize(*target);
    if (!colors) {
      std::cerr << colors.status().to_string() << "\n";
      return 1;
    }
    out[corrected ? "corrected" : "upsampled_only"] = {
        {"passes", p.passes}, {"typicality", resolved_typicality(**table, p.typicality)}, {"finest_subpass_size", p.finest_subpass_size},
        {"finest_typicality_scale", p.finest_typicality_scale},
        {"levels", measure(**table, (*synth)->cache(), o.size, normalised_weights(p.plane_weights))}};
  }
  std::cout << out.dump() << "\n";
  return 0;
}
