#include "synthesis/usage_balance.h"

#include <algorithm>
#include <cmath>

#include "synthesis/synthesizer.h"
#include "synthesis/target.h"

namespace solidtex {
namespace {

constexpr uint32_t kCalibrationSeed = 0x5eedba1u;
constexpr int64_t kCalibrationCacheBytes = int64_t(256) << 20;

// Maps a sub-task's percent into its share of the whole calibration.
class ShareInterrupter : public Interrupter {
 public:
  ShareInterrupter(Interrupter& outer, int done, int total) : outer_(outer), done_(done), total_(total) {}
  bool was_interrupted(int percent) override {
    const int sub = std::clamp(percent, 0, 100);
    return outer_.was_interrupted((100 * done_ + sub) / std::max(total_, 1));
  }

 private:
  Interrupter& outer_;
  int done_, total_;
};

// Separable Gaussian blur with wrap-around, in double with a fixed summation order.
std::vector<double> blur_wrap(const std::vector<double>& in, int w, int h, float sigma) {
  const int r = std::max(1, int(std::ceil(3.f * sigma)));
  std::vector<double> k(size_t(2 * r + 1));
  double sum = 0;
  for (int i = -r; i <= r; ++i) sum += k[size_t(i + r)] = std::exp(-0.5 * i * i / (double(sigma) * sigma));
  for (double& v : k) v /= sum;
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  std::vector<double> rows(in.size()), out(in.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double a = 0;
      for (int i = -r; i <= r; ++i) a += k[size_t(i + r)] * in[size_t(y) * w + size_t(wrap(x + i, w))];
      rows[size_t(y) * w + x] = a;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double a = 0;
      for (int i = -r; i <= r; ++i) a += k[size_t(i + r)] * rows[size_t(wrap(y + i, h)) * w + x];
      out[size_t(y) * w + x] = a;
    }
  return out;
}

// Blurred usage counts per distinct image at `level`: every triple counts once on each plane.
std::vector<std::vector<double>> blurred_counts(const Table& table, PyramidLevel level,
                                                const std::vector<CoordinateTriple>& triples, float sigma) {
  const TableLevel& lev = table.level(level);
  const int distinct = table.distinct_images();
  std::vector<std::vector<double>> counts(static_cast<size_t>(distinct));
  for (int k = 0; k < distinct; ++k) counts[size_t(k)].assign(size_t(lev.planes[size_t(k)]->stack.pixel_count()), 0.0);
  for (const CoordinateTriple& t : triples)
    for (int plane = 0; plane < 3; ++plane) {
      const ImageF& img = lev.planes[size_t(plane)]->stack;
      const int x = ImageF::wrap(t.at[size_t(plane)].x, img.width), y = ImageF::wrap(t.at[size_t(plane)].y, img.height);
      counts[size_t(distinct == 1 ? 0 : plane)][size_t(y) * img.width + size_t(x)] += 1.0;
    }
  for (int k = 0; k < distinct; ++k) {
    const ImageF& img = lev.planes[size_t(k)]->stack;
    counts[size_t(k)] = blur_wrap(counts[size_t(k)], img.width, img.height, sigma);
  }
  return counts;
}

// Total variance of an image's appearance vectors: the scale of its match costs.
double appearance_spread(const PlaneAppearance& app) {
  const size_t d = size_t(app.pca.output_dims);
  const size_t n = app.projected.size() / std::max<size_t>(d, 1);
  double total = 0;
  for (size_t r = 0; r < d; ++r) {
    double mean = 0, var = 0;
    for (size_t p = 0; p < n; ++p) mean += app.projected[p * d + r];
    mean /= double(n);
    for (size_t p = 0; p < n; ++p) {
      const double x = app.projected[p * d + r] - mean;
      var += x * x;
    }
    total += var / double(n);
  }
  return total;
}

// Synthesizes the finest `box`^3 block at `min` and returns, per level, the final triples the
// request left in its cache: the block itself at the finest level, and at every coarser level
// the (larger, in voxels of that level relatively) region the block depends on.
Result<std::vector<std::vector<CoordinateTriple>>> final_triples_by_level(const std::shared_ptr<const Table>& table,
                                                                          const SynthesisParams& params, Voxel min,
                                                                          int box, Interrupter& interrupter) {
  auto field = std::make_shared<ConstantField>(Quat{});
  SOLIDTEX_ASSIGN_OR_RETURN(auto synth, Synthesizer::create(table, field, params, kCalibrationCacheBytes));
  SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::box(min, box, box, box));
  SOLIDTEX_RETURN_IF_ERROR(synth->synthesize(target, interrupter).status());
  const int levels = table->levels();
  std::vector<std::vector<CoordinateTriple>> out(static_cast<size_t>(levels));
  for (int l = 0; l < levels; ++l) {
    const int shift = levels - 1 - l;  // a level-l voxel is the parent of finest voxels v >> shift
    constexpr int kMargin = 24;        // beyond any dependency halo at a level
    const Voxel lo{(min.x >> shift) - kMargin, (min.y >> shift) - kMargin, (min.z >> shift) - kMargin};
    const int side = ((box - 1) >> shift) + 2 + 2 * kMargin;
    // A plain list, not a TargetSet: its sort and sample index cost more than the lookup, and
    // counts do not depend on the order.
    std::vector<Voxel> region;
    region.reserve(size_t(side) * side * side);
    for (int x = 0; x < side; ++x)
      for (int y = 0; y < side; ++y)
        for (int z = 0; z < side; ++z) region.push_back({lo.x + x, lo.y + y, lo.z + z});
    std::vector<CoordinateTriple> triples;
    std::vector<uint8_t> found;
    synth->cache().lookup(PyramidLevel{l}, region, triples, found);
    for (size_t i = 0; i < triples.size(); ++i)
      if (found[i]) out[size_t(l)].push_back(triples[i]);
  }
  return out;
}

}  // namespace

Status UsageBalanceParams::validate() const {
  if (rounds < 0 || rounds > 8) return Status(StatusCode::kInvalidArgument, "must be in [0, 8]", "rounds");
  if (!(strength >= 0.f && strength <= 1.f)) return Status(StatusCode::kInvalidArgument, "must be in [0, 1]", "strength");
  if (!(sigma >= 0.5f && sigma <= 32.f)) return Status(StatusCode::kInvalidArgument, "must be in [0.5, 32]", "sigma");
  if (box < 8 || box > 64) return Status(StatusCode::kInvalidArgument, "must be in [8, 64]", "box");
  if (!(fine_gain >= 0.25f && fine_gain <= 4.f)) return Status(StatusCode::kInvalidArgument, "must be in [0.25, 4]", "fine_gain");
  return Status::ok();
}

Result<std::shared_ptr<const Table>> balance_usage(std::shared_ptr<const Table> table, const UsageBalanceParams& params,
                                                   Interrupter& interrupter) {
  SOLIDTEX_RETURN_IF_ERROR(params.validate());
  if (table->has_usage()) return Status(StatusCode::kInvalidArgument, "the table already has usage penalties", "table");
  if (params.rounds == 0) return table;
  const int levels = table->levels(), distinct = table->distinct_images();
  UsagePenalties usage(static_cast<size_t>(levels));
  for (int l = 0; l < levels; ++l)
    for (int k = 0; k < distinct; ++k)
      usage[size_t(l)].emplace_back(size_t(table->level(PyramidLevel{l}).planes[size_t(k)]->stack.pixel_count()), 0.f);
  SynthesisParams calibration;  // the defaults
  calibration.seed = kCalibrationSeed;
  // Calibration counts triples, which no colour rule changes; patch votes (the default's choice
  // for one image) would also synthesize a ring around the block and count it, changing every
  // table analysed since, and cost time.
  calibration.color = ColorRule::kMedoid;
  // Calibration predates typicality auto and measured its gains at this weight on every table;
  // pinned so that tables analysed before auto and after are the same.
  calibration.typicality = kTypicality;
  for (int round = 0; round < params.rounds; ++round) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto current, table->with_usage(usage));
    ShareInterrupter share(interrupter, round, params.rounds);
    // Blocks far apart, and from the origin where users look first, for independent samples.
    const int at = 4096 * (round + 1);
    const Voxel min{at, -at / 2, at / 3};
    SOLIDTEX_ASSIGN_OR_RETURN(auto by_level, final_triples_by_level(current, calibration, min, params.box, share));
    for (int l = 0; l < levels; ++l) {
      const PyramidLevel level{l};
      // Coarser levels are smoother: their counts are blurred over more exemplar pixels.
      const float sigma = params.sigma * std::sqrt(float(table->spacing(level)));
      const auto counts = blurred_counts(*table, level, by_level[size_t(l)], sigma);
      for (int k = 0; k < distinct; ++k) {
        const std::vector<double>& c = counts[size_t(k)];
        double sum = 0;
        for (double v : c) sum += v;
        const double mean = sum / double(c.size());
        if (!(mean > 0)) continue;
        const double spread = appearance_spread(*table->level(level).planes[size_t(k)]);
        std::vector<float>& u = usage[size_t(l)][size_t(k)];
        std::vector<double> next(u.size());
        double least = 0;
        for (size_t p = 0; p < u.size(); ++p) {
          next[p] = double(u[p]) + params.strength * spread * std::log((c[p] + 0.1 * mean) / (1.1 * mean));
          least = p == 0 ? next[p] : std::min(least, next[p]);
        }
        for (size_t p = 0; p < u.size(); ++p) u[p] = float(next[p] - least);
      }
    }
  }
  if (interrupter.was_interrupted(100)) return Status(StatusCode::kCancelled, "usage balancing was cancelled");
  const ExemplarSet& e = table->exemplars();
  if (e.shared() || e.crossed())
    for (int l = 0; l < levels; ++l)
      if (table->spacing(PyramidLevel{l}) <= 2)
        for (auto& image : usage[size_t(l)])
          for (float& u : image) u *= params.fine_gain;
  return table->with_usage(std::move(usage));
}

Result<std::vector<CoordinateTriple>> level_triples(std::shared_ptr<const Table> table, const SynthesisParams& params,
                                                    PyramidLevel level, Voxel min, int box, Interrupter& interrupter) {
  auto field = std::make_shared<ConstantField>(Quat{});
  SOLIDTEX_ASSIGN_OR_RETURN(auto synth, Synthesizer::create(std::move(table), field, params, kCalibrationCacheBytes));
  SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::box(min, box, box, box));
  SynthesisOptions options;
  options.level = level.index;
  SOLIDTEX_RETURN_IF_ERROR(synth->synthesize(target, interrupter, nullptr, options).status());
  std::vector<CoordinateTriple> triples;
  std::vector<uint8_t> found;
  synth->cache().lookup(level, target.voxels, triples, found);
  if (std::count(found.begin(), found.end(), uint8_t(1)) != int64_t(target.voxels.size()))
    return Status(StatusCode::kInternal, "a synthesized block did not stay in the voxel cache");
  return triples;
}

double usage_divergence(const Table& table, PyramidLevel level, const std::vector<CoordinateTriple>& triples, float sigma) {
  const auto counts = blurred_counts(table, level, triples, sigma);
  double kl = 0;
  for (const auto& c : counts) {
    double sum = 0;
    for (double v : c) sum += v;
    if (!(sum > 0)) continue;
    for (double v : c) {
      const double p = v / sum;
      if (p > 0) kl += p * std::log(p * double(c.size()));
    }
  }
  return kl / double(counts.size());
}

}  // namespace solidtex
