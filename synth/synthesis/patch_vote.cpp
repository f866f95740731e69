#include "synthesis/patch_vote.h"

#include <algorithm>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace solidtex {

void vote_color(const Table& table, const PlaneWeights& w, int spacing, const CoordinateTriple& own,
                const VoteSources& sources, float rgb[3]) {
  const ExemplarSet& e = table.exemplars();
  float medoid[3];
  output_color(table, own, w, ColorRule::kMedoid, medoid);
  const float top = std::max({w[0], w[1], w[2]});
  struct Vote {
    uint64_t key;
    float weight;
    const float* rgb;
  };
  std::array<Vote, 27> votes;
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    if (!(w[size_t(k)] > 0.f)) continue;
    // Planes holding the same image pool their votes under the first such plane's index.
    int image = k;
    for (int j = 0; j < k; ++j)
      if (e.plane_ptr(Plane(j)) == e.plane_ptr(Plane(k))) {
        image = j;
        break;
      }
    const ImageF& img = e.plane(Plane(k));
    const float weight = w[size_t(k)] / top;
    for (int ab = 0; ab < 9; ++ab) {
      const int a = ab % 3 - 1, b = ab / 3 - 1;
      const ExemplarPixel s = sources[size_t(k)][size_t(ab)];
      const int x = ImageF::wrap(s.x - spacing * a, img.width), y = ImageF::wrap(s.y - spacing * b, img.height);
      const uint64_t key = uint64_t(image) << 48 | uint64_t(uint32_t(y)) << 24 | uint64_t(uint32_t(x));
      int i = 0;
      while (i < count && votes[size_t(i)].key != key) ++i;
      if (i < count) {
        votes[size_t(i)].weight += weight;
      } else {
        votes[size_t(count++)] = {key, weight, img.wrapped(x, y)};
      }
    }
  }
  int best = 0;
  float best_score = 0.f;
  for (int i = 0; i < count; ++i) {
    const Vote& v = votes[size_t(i)];
    float d = 0.f;
    for (int c = 0; c < 3; ++c) d += (v.rgb[c] - medoid[c]) * (v.rgb[c] - medoid[c]);
    const float score = v.weight - kVoteColorPull * d;
    if (i == 0 || score > best_score || (score == best_score && v.key < votes[size_t(best)].key)) {
      best = i;
      best_score = score;
    }
  }
  for (int c = 0; c < 3; ++c) rgb[c] = votes[size_t(best)].rgb[c];
}

std::vector<Voxel> vote_support(const std::vector<Voxel>& target, const FrameStencils& frames, PyramidLevel l) {
  std::vector<std::vector<Voxel>> parts(target.size() / 4096 + 1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, parts.size()), [&](const tbb::blocked_range<size_t>& r) {
    ReadStencil scratch;
    for (size_t part = r.begin(); part != r.end(); ++part) {
      std::vector<Voxel>& out = parts[part];
      const size_t end = std::min(target.size(), (part + 1) * 4096);
      for (size_t i = part * 4096; i < end; ++i) {
        const Voxel& p = target[i];
        const ReadStencil& st = frames.stencil(l, p, scratch);
        out.push_back(p);
        for (const auto& plane : st.candidate)
          for (const auto& o : plane) out.push_back({p.x + o[0], p.y + o[1], p.z + o[2]});
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    }
  });
  std::vector<Voxel> all;
  for (const auto& part : parts) all.insert(all.end(), part.begin(), part.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

}  // namespace solidtex
