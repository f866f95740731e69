#include "synthesis/correction.h"

#include <algorithm>
#include <limits>

#include "core/hash.h"

namespace solidtex {
namespace {
// std::lround (half away from zero) for the small finite values of stencil offsets, inline:
// the truncation and the remainder x - trunc(x) are exact in float.
int round_offset(float x) {
  int i = int(x);
  const float rest = x - float(i);
  if (rest >= 0.5f) ++i;
  else if (rest <= -0.5f) --i;
  return i;
}

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
          out.taps.push_back({int8_t(round_offset(w[0])), int8_t(round_offset(w[1])), int8_t(round_offset(w[2])), 1.f});
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
      out.candidate[size_t(plane)][size_t(ab)] = {int8_t(round_offset(w[0])), int8_t(round_offset(w[1])),
                                                  int8_t(round_offset(w[2]))};
    }
}

// Sorted (lexicographically by dx, dy, dz) and unique. Varying fields ask for this once per
// voxel per step, so the common small reach dedups through a bitmap over the stencil's box,
// whose scan in index order is already lexicographic; wide reaches sort packed keys.
void stencil_offsets(const ReadStencil& s, std::vector<std::array<int8_t, 3>>& out) {
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  auto grow = [&](int8_t x, int8_t y, int8_t z) {
    const int o[3] = {x, y, z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], o[a]);
      hi[a] = std::max(hi[a], o[a]);
    }
  };
  for (const Tap& t : s.taps) grow(t.dx, t.dy, t.dz);
  for (const auto& plane : s.candidate)
    for (const auto& o : plane) grow(o[0], o[1], o[2]);
  const int ey = hi[1] - lo[1] + 1, ez = hi[2] - lo[2] + 1;
  const int cells = (hi[0] - lo[0] + 1) * ey * ez;
  out.clear();
  if (cells <= (1 << 16)) {
    thread_local std::vector<uint64_t> bits;
    bits.assign(size_t(cells + 63) / 64, 0);
    auto mark = [&](int x, int y, int z) {
      const int i = ((x - lo[0]) * ey + (y - lo[1])) * ez + (z - lo[2]);
      bits[size_t(i) >> 6] |= uint64_t(1) << (i & 63);
    };
    mark(0, 0, 0);
    for (const Tap& t : s.taps) mark(t.dx, t.dy, t.dz);
    for (const auto& plane : s.candidate)
      for (const auto& o : plane) mark(o[0], o[1], o[2]);
    for (size_t w = 0; w < bits.size(); ++w)
      for (uint64_t b = bits[w]; b; b &= b - 1) {
        const int i = int(w * 64) + __builtin_ctzll(b);
        const int z = i % ez, y = (i / ez) % ey, x = i / (ez * ey);
        out.push_back({int8_t(x + lo[0]), int8_t(y + lo[1]), int8_t(z + lo[2])});
      }
    return;
  }
  // Offsets are within +-127: biased bytes packed high to low sort like (dx, dy, dz).
  auto key = [](int x, int y, int z) { return uint32_t(x + 128) << 16 | uint32_t(y + 128) << 8 | uint32_t(z + 128); };
  std::vector<uint32_t> keys;
  keys.reserve(s.taps.size() + 28);
  keys.push_back(key(0, 0, 0));
  for (const Tap& t : s.taps) keys.push_back(key(t.dx, t.dy, t.dz));
  for (const auto& plane : s.candidate)
    for (const auto& o : plane) keys.push_back(key(o[0], o[1], o[2]));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  for (uint32_t k : keys) out.push_back({int8_t(int(k >> 16) - 128), int8_t(int((k >> 8) & 255) - 128), int8_t(int(k & 255) - 128)});
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

void output_color(const Table& table, const CoordinateTriple& t, const PlaneWeights& w, ColorRule rule, float rgb[3]) {
  const ExemplarSet& e = table.exemplars();
  const std::array<const float*, 3> px{e.plane(Plane::kXY).wrapped(t.at[0].x, t.at[0].y),
                                       e.plane(Plane::kYZ).wrapped(t.at[1].x, t.at[1].y),
                                       e.plane(Plane::kZX).wrapped(t.at[2].x, t.at[2].y)};
  if (rule == ColorRule::kMean) {
    for (int k = 0; k < 3; ++k) rgb[k] = w[0] * px[0][k] + w[1] * px[1][k] + w[2] * px[2][k];
    return;
  }
  // Plane i's spread is its weighted squared distance to the others, divided by its own weight:
  // with equal weights the plain medoid; a down-weighted plane (the end grain of a grain
  // layout) is output only where it agrees with the others much better, one of weight 0 never.
  auto spread = [&](int i) {
    float s = 0.f;
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) {
        const float d = px[size_t(i)][k] - px[size_t(j)][k];
        s += w[size_t(j)] * d * d;
      }
    return s / w[size_t(i)];
  };
  int best = -1;
  float best_spread = 0.f;
  for (int i = 0; i < 3; ++i) {
    if (w[size_t(i)] <= 0.f) continue;
    const float s = spread(i);
    if (best < 0 || s < best_spread) {
      best = i;
      best_spread = s;
    }
  }
  for (int k = 0; k < 3; ++k) rgb[k] = px[size_t(best)][k];
}

ColorRule resolved_color_rule(ColorRule rule) {
  return rule == ColorRule::kAuto ? ColorRule::kVote : rule;
}

FinestMatch resolved_finest_match(const Table& table, FinestMatch m) {
  if (m != FinestMatch::kAuto) return m;
  // Planes where two or more levels lie above the finest, which then only adds pixel-scale
  // detail; triples on two-level tables (small exemplars: leopard), whose finest level still
  // shapes the structure and needs the three planes to agree there (docs/quality.md, "The
  // finest level matches plane by plane").
  return table.levels() >= 3 ? FinestMatch::kPlane : FinestMatch::kTriple;
}

float resolved_typicality(const Table& table, std::optional<float> typicality) {
  if (typicality) return *typicality;
  const ExemplarSet& e = table.exemplars();
  return e.shared() || e.crossed() ? kTypicality : kThreePlaneTypicality;
}

float level_typicality(const Table& table, PyramidLevel l, const SynthesisParams& params) {
  const float t = resolved_typicality(table, params.typicality);
  return table.spacing(l) == 1 ? t * params.finest_typicality_scale : t;
}

CorrectionContext CorrectionContext::make(const Table& table, PyramidLevel l, const SynthesisParams& params) {
  CorrectionContext ctx;
  ctx.candidates_per_source = params.matcher == Matcher::kCoherent ? 4 : 64;
  ctx.cost_weights = params.plane_weights;
  ctx.color_weights = normalised_weights(params.plane_weights);
  ctx.color_rule = resolved_color_rule(params.color);
  ctx.typicality = level_typicality(table, l, params);
  ctx.level = &table.level(l);
  for (int k = 0; k < 3; ++k) {
    const PlaneAppearance& app = *ctx.level->planes[size_t(k)];
    const bool usage = params.balance > 0.f && !app.usage.empty();
    if (!(ctx.typicality > 0.f) && !usage) continue;
    if (k > 0 && ctx.level->planes[size_t(k - 1)].get() == &app) {
      ctx.penalty[size_t(k)] = ctx.penalty[size_t(k - 1)];
      continue;
    }
    auto pen = std::make_shared<std::vector<float>>(app.typicality.size());
    for (size_t i = 0; i < pen->size(); ++i) {
      float v = ctx.typicality * app.typicality[i];
      if (usage) v += params.balance * app.usage[i];
      (*pen)[i] = v;
    }
    ctx.penalty[size_t(k)] = std::move(pen);
  }
  ctx.n = table.params().neighborhood;
  ctx.spacing = table.spacing(l);
  ctx.plane_wise = ctx.spacing == 1 && resolved_finest_match(table, params.finest_match) == FinestMatch::kPlane;
  ctx.cross_sources = ctx.plane_wise && params.finest_sources == FinestSources::kCross;
  ctx.channels = table.exemplars().channels();
  ctx.dims = ctx.level->planes[0]->pca.output_dims;
  for (int k = 0; k < 3; ++k) ctx.projection[size_t(k)] = PcaProjection::of(ctx.level->planes[size_t(k)]->pca);
  return ctx;
}

namespace detail {

namespace {

// Squared distance with four fixed accumulator lanes, lane j summing dims j, j+4, ... in
// ascending order, then (lane0 + lane1) + (lane2 + lane3): the same bits at every vector
// width. Inlined into the candidate loop, where it is called hundreds of times per voxel.
inline float plane_distance(const float* q, const float* a, int d) {
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

// Plane k's weighted cost term of one exemplar pixel (by flat index) for the current query.
struct PlaneTerm {
  const float* query;
  const PlaneAppearance* app;
  float weight;
  const float* penalty;  // CorrectionContext::penalty, or null
  int dims;
  float operator()(size_t pixel) const {
    float dk = plane_distance(query, &app->projected[pixel * size_t(dims)], dims);
    if (penalty) dk += penalty[pixel];
    return weight * dk;
  }
  void prefetch(size_t pixel) const {
    const char* row = reinterpret_cast<const char*>(&app->projected[pixel * size_t(dims)]);
    __builtin_prefetch(row);
    __builtin_prefetch(row + size_t(dims) * sizeof(float) - 1);
  }
};

size_t pixel_index(const PlaneAppearance& app, ExemplarPixel p) { return size_t(p.y) * app.stack.width + size_t(p.x); }

}  // namespace

void project_planes(const CorrectionContext& ctx, CorrectionScratch& s) {
  const int in_dims = ctx.n * ctx.n * ctx.channels;
  const int d = ctx.dims;
  s.projected.resize(size_t(3) * d);
  for (int k = 0; k < 3; ++k)
    ctx.projection[size_t(k)].project(s.gathered.data() + size_t(k) * in_dims, s.projected.data() + size_t(k) * d);
}

// The winner is the minimum of (cost, triple) over the candidate set, so the order in which
// candidates are visited cannot change it; only the cost of each survivor must be exact.
// A candidate's cost is ((t0 + t1) + t2) in floats, t_k = w_k * (distance_k + penalty_k) >= 0
// (CorrectionContext::penalty), and float addition of non-negative terms is monotone, so any partial sum
// is a lower bound of the cost: a candidate (or a whole source list) whose lower bound
// exceeds the best cost so far is skipped without changing the result. Every candidate of
// plane k's source list at pixel p has T[k] = p, so t_k is computed once per source, and
// sources are visited cheapest first so the bound tightens early.
CoordinateTriple best_candidate(const CorrectionContext& ctx, const CoordinateTriple& current,
                                const std::array<std::array<ExemplarPixel, 9>, 3>& sources, CorrectionScratch& s) {
  const TableLevel& level = *ctx.level;
  std::array<PlaneTerm, 3> term;
  for (int k = 0; k < 3; ++k)
    term[size_t(k)] = {s.projected.data() + size_t(k) * ctx.dims, level.planes[size_t(k)].get(), ctx.cost_weights[size_t(k)],
                       ctx.penalty[size_t(k)] ? ctx.penalty[size_t(k)]->data() : nullptr, ctx.dims};
  float best = std::numeric_limits<float>::infinity();
  CoordinateTriple best_t{};
  auto offer = [&](float cost, const CoordinateTriple& t) {
    if (cost < best || (cost == best && t < best_t)) {
      best = cost;
      best_t = t;
    }
  };

  CoordinateTriple cur = current;
  std::array<float, 3> cur_terms;
  for (int k = 0; k < 3; ++k) {
    const PlaneAppearance& app = *level.planes[size_t(k)];
    cur.at[size_t(k)] = {ImageF::wrap(cur.at[size_t(k)].x, app.stack.width), ImageF::wrap(cur.at[size_t(k)].y, app.stack.height)};
    cur_terms[size_t(k)] = term[size_t(k)](pixel_index(app, cur.at[size_t(k)]));
  }
  if (ctx.plane_wise) {
    // Each plane's pixel by its own term: the minimum of (term, y, x) over the plane's current
    // pixel and sources, independent of the order they are visited in.
    for (int k = 0; k < 3; ++k) {
      const PlaneAppearance& app = *level.planes[size_t(k)];
      float best_k = cur_terms[size_t(k)];
      ExemplarPixel& pick = cur.at[size_t(k)];
      for (int ab = 0; ab < 9; ++ab) {
        if (ctx.cross_sources && ab % 2 == 0 && ab != 4) continue;  // a diagonal neighbour's
        const ExemplarPixel& raw = sources[size_t(k)][size_t(ab)];
        const ExemplarPixel src{ImageF::wrap(raw.x, app.stack.width), ImageF::wrap(raw.y, app.stack.height)};
        const float t = term[size_t(k)](pixel_index(app, src));
        if (t < best_k || (t == best_k && (src.y < pick.y || (src.y == pick.y && src.x < pick.x)))) {
          best_k = t;
          pick = src;
        }
      }
    }
    return cur;
  }
  offer((cur_terms[0] + cur_terms[1]) + cur_terms[2], cur);

  struct Source {
    float own;  // t_k of the source pixel
    int plane;
    ExemplarPixel pixel;
  };
  std::array<Source, 27> list;
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    const PlaneCandidates& pc = level.candidates->planes[size_t(k)];
    const int first = count;
    for (const ExemplarPixel& raw : sources[size_t(k)]) {
      const ExemplarPixel src{ImageF::wrap(raw.x, pc.width), ImageF::wrap(raw.y, pc.height)};
      bool seen = false;
      for (int u = first; u < count && !seen; ++u) seen = list[size_t(u)].pixel == src;
      if (seen) continue;
      list[size_t(count++)] = {0.f, k, src};
      // The lists and rows lie far apart in tables of megabytes: ask for them all up front.
      const auto cands = pc.at(src).packed();
      const char* bytes = reinterpret_cast<const char*>(cands.data());
      for (size_t off = 0; off < cands.size_bytes(); off += 64) __builtin_prefetch(bytes + off);
      term[size_t(k)].prefetch(pixel_index(*level.planes[size_t(k)], src));
    }
  }
  for (int i = 0; i < count; ++i) {
    Source& src = list[size_t(i)];
    src.own = term[size_t(src.plane)](pixel_index(*level.planes[size_t(src.plane)], src.pixel));
  }
  std::sort(list.begin(), list.begin() + count, [](const Source& a, const Source& b) { return a.own < b.own; });

  for (int i = 0; i < count; ++i) {
    const Source& src = list[size_t(i)];
    if (src.own > best) break;  // every later source costs at least as much
    const int k = src.plane;
    const int j1 = k == 0 ? 1 : 0, j2 = k == 2 ? 1 : 2;  // the other planes, ascending
    const PlaneAppearance& a1 = *level.planes[size_t(j1)];
    const PlaneAppearance& a2 = *level.planes[size_t(j2)];
    const CandidateList list = level.candidates->planes[size_t(k)].at(src.pixel);
    const std::span<const PackedTriple> cands = list.packed();
    const int sk = list.stored_plane(k), s1 = list.stored_plane(j1), s2 = list.stored_plane(j2);
    const size_t take = std::min(cands.size(), size_t(ctx.candidates_per_source));
    for (size_t c = 0; c < take; ++c) {
      term[size_t(j1)].prefetch(pixel_index(a1, cands[c].stored(s1)));
      term[size_t(j2)].prefetch(pixel_index(a2, cands[c].stored(s2)));
    }
    for (size_t c = 0; c < take; ++c) {
      const PackedTriple& t = cands[c];
      std::array<float, 3> tk;
      const ExemplarPixel own = t.stored(sk);
      tk[size_t(k)] = own == src.pixel ? src.own : term[size_t(k)](pixel_index(*level.planes[size_t(k)], own));
      tk[size_t(j1)] = term[size_t(j1)](pixel_index(a1, t.stored(s1)));
      if (tk[size_t(k)] + tk[size_t(j1)] > best) continue;
      tk[size_t(j2)] = term[size_t(j2)](pixel_index(a2, t.stored(s2)));
      offer((tk[0] + tk[1]) + tk[2], t.unpack(list.rotation()));
    }
  }
  return best_t;
}

}  // namespace detail
}  // namespace solidtex
