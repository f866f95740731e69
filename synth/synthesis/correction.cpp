#include "synthesis/correction.h"

#include <algorithm>
#include <limits>

#include "core/hash.h"

namespace solidtex {
namespace {
void local_offset(int plane, int i, int j, float out[3]) {
  out[0] = out[1] = out[2] = 0.f;
  out[kPlaneFirstAxis[size_t(plane)]] = float(i);
  out[kPlaneSecondAxis[size_t(plane)]] = float(j);
}
}  // namespace

void build_stencil(const Rot3& r, int n, bool trilinear, ReadStencil& out) {
  out.n = n;
  out.trilinear = trilinear;
  out.taps.clear();
  out.begin.clear();
  const int h = n / 2;
  for (int plane = 0; plane < 3; ++plane)
    for (int j = -h; j <= h; ++j)
      for (int i = -h; i <= h; ++i) {
        out.begin.push_back(uint16_t(out.taps.size()));
        float local[3], w[3];
        local_offset(plane, i, j, local);
        r.apply(local, w);
        if (!trilinear) {
          out.taps.push_back({int8_t(std::lround(w[0])), int8_t(std::lround(w[1])), int8_t(std::lround(w[2])), 1.f});
          continue;
        }
        int f[3];
        float t[3];
        for (int a = 0; a < 3; ++a) {
          f[a] = int(std::floor(w[a]));
          t[a] = w[a] - float(f[a]);
        }
        for (int corner = 0; corner < 8; ++corner) {
          float weight = 1.f;
          int o[3];
          for (int a = 0; a < 3; ++a) {
            const int bit = (corner >> a) & 1;
            weight *= bit ? t[a] : 1.f - t[a];
            o[a] = f[a] + bit;
          }
          if (weight > 0.f) out.taps.push_back({int8_t(o[0]), int8_t(o[1]), int8_t(o[2]), weight});
        }
      }
  out.begin.push_back(uint16_t(out.taps.size()));
  for (int plane = 0; plane < 3; ++plane)
    for (int ab = 0; ab < 9; ++ab) {
      float local[3], w[3];
      local_offset(plane, ab % 3 - 1, ab / 3 - 1, local);
      r.apply(local, w);
      out.candidate[size_t(plane)][size_t(ab)] = {int8_t(std::lround(w[0])), int8_t(std::lround(w[1])),
                                                  int8_t(std::lround(w[2]))};
    }
}

void stencil_offsets(const ReadStencil& s, std::vector<std::array<int8_t, 3>>& out) {
  out.clear();
  out.push_back({0, 0, 0});
  for (const Tap& t : s.taps) out.push_back({t.dx, t.dy, t.dz});
  for (const auto& plane : s.candidate)
    for (const auto& o : plane) out.push_back(o);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

PlaneWeights normalised_weights(const std::array<float, 3>& w) {
  const float total = w[0] + w[1] + w[2];
  return {w[0] / total, w[1] / total, w[2] / total};
}

void matching_color(const TableLevel& level, const CoordinateTriple& t, int channels, const PlaneWeights& w, float* out) {
  const float* a = level.planes[0]->stack.wrapped(t.at[0].x, t.at[0].y);
  const float* b = level.planes[1]->stack.wrapped(t.at[1].x, t.at[1].y);
  const float* c = level.planes[2]->stack.wrapped(t.at[2].x, t.at[2].y);
  for (int k = 0; k < channels; ++k) out[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
  for (int k = channels; k < 4; ++k) out[k] = 0.f;
}

void output_color(const Table& table, const CoordinateTriple& t, const PlaneWeights& w, float rgb[3]) {
  const ExemplarSet& e = table.exemplars();
  const float* a = e.plane(Plane::kXY).wrapped(t.at[0].x, t.at[0].y);
  const float* b = e.plane(Plane::kYZ).wrapped(t.at[1].x, t.at[1].y);
  const float* c = e.plane(Plane::kZX).wrapped(t.at[2].x, t.at[2].y);
  for (int k = 0; k < 3; ++k) rgb[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
}

CorrectionContext CorrectionContext::make(const Table& table, PyramidLevel l, const SynthesisParams& params) {
  CorrectionContext ctx;
  ctx.candidates_per_source = params.matcher == Matcher::kCoherent ? 4 : 64;
  ctx.cost_weights = params.plane_weights;
  ctx.color_weights = normalised_weights(params.plane_weights);
  ctx.typicality = params.typicality;
  ctx.level = &table.level(l);
  ctx.n = table.params().neighborhood;
  ctx.spacing = table.spacing(l);
  ctx.channels = table.exemplars().channels();
  ctx.dims = ctx.level->planes[0]->pca.output_dims;
  for (int k = 0; k < 3; ++k) ctx.projection[size_t(k)] = PcaProjection::of(ctx.level->planes[size_t(k)]->pca);
  return ctx;
}

namespace detail {

// Squared distance with four fixed accumulator lanes: vectorisable and order-stable.
__attribute__((target_clones("avx2", "default"))) float plane_distance(const float* q, const float* a, int d) {
  float acc[4] = {0.f, 0.f, 0.f, 0.f};
  int r = 0;
  for (; r + 4 <= d; r += 4)
    for (int j = 0; j < 4; ++j) {
      const float diff = q[r + j] - a[r + j];
      acc[j] += diff * diff;
    }
  for (; r < d; ++r) {
    const float diff = q[r] - a[r];
    acc[0] += diff * diff;
  }
  return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}

void project_planes(const CorrectionContext& ctx, CorrectionScratch& s) {
  const int in_dims = ctx.n * ctx.n * ctx.channels;
  const int d = ctx.dims;
  s.projected.resize(size_t(3) * d);
  for (int k = 0; k < 3; ++k)
    ctx.projection[size_t(k)].project(s.gathered.data() + size_t(k) * in_dims, s.projected.data() + size_t(k) * d);
}

CoordinateTriple best_candidate(const CorrectionContext& ctx, const CoordinateTriple& current,
                                const std::array<std::array<ExemplarPixel, 9>, 3>& sources, CorrectionScratch& s) {
  // Candidates of distinct sources of one plane differ in that plane's coordinate, and one
  // source's list holds distinct triples, so deduplicating the (at most 9) sources per plane
  // leaves only cross-plane repeats, which cost a re-evaluation but cannot change the winner.
  const TableLevel& level = *ctx.level;
  const int d = ctx.dims;
  float best = std::numeric_limits<float>::infinity();
  CoordinateTriple best_t{};
  auto consider = [&](const CoordinateTriple& t) {
    // Planes are summed in a fixed order; a candidate whose partial cost already exceeds the
    // best cannot win (costs only grow), so stopping early changes no result.
    float cost = 0.f;
    for (int k = 0; k < 3 && cost <= best; ++k) {
      const PlaneAppearance& app = *level.planes[size_t(k)];
      const size_t pixel = size_t(t.at[size_t(k)].y) * app.stack.width + size_t(t.at[size_t(k)].x);
      float dk = plane_distance(s.projected.data() + size_t(k) * d, &app.projected[pixel * d], d);
      if (ctx.typicality > 0.f) dk += ctx.typicality * app.typicality[pixel];
      cost += ctx.cost_weights[size_t(k)] * dk;
    }
    if (cost < best || (cost == best && t < best_t)) {
      best = cost;
      best_t = t;
    }
  };
  CoordinateTriple cur = current;
  for (int k = 0; k < 3; ++k) {
    const ImageF& img = level.planes[size_t(k)]->stack;
    cur.at[size_t(k)] = {ImageF::wrap(cur.at[size_t(k)].x, img.width), ImageF::wrap(cur.at[size_t(k)].y, img.height)};
  }
  consider(cur);
  for (int k = 0; k < 3; ++k) {
    const PlaneCandidates& pc = level.candidates.planes[size_t(k)];
    std::array<ExemplarPixel, 9> unique;
    int count = 0;
    for (const ExemplarPixel& raw : sources[size_t(k)]) {
      const ExemplarPixel src{ImageF::wrap(raw.x, pc.width), ImageF::wrap(raw.y, pc.height)};
      bool seen = false;
      for (int u = 0; u < count && !seen; ++u) seen = unique[size_t(u)] == src;
      if (seen) continue;
      unique[size_t(count++)] = src;
      const auto list = pc.at(src);
      const size_t take = std::min(list.size(), size_t(ctx.candidates_per_source));
      for (size_t c = 0; c < take; ++c) consider(list[c]);
    }
  }
  return best_t;
}

}  // namespace detail
}  // namespace solidtex
