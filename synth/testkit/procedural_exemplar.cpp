#include "testkit/procedural_exemplar.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace solidtex {
namespace {

constexpr float kPi = 3.14159265358979f;

uint32_t hash3(uint32_t a, uint32_t b, uint32_t c) {
  uint32_t h = a * 0x8da6b343u ^ b * 0xd8163841u ^ c * 0xcb1ab31fu;
  h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
  return h;
}
float unit(uint32_t h) { return float(h >> 8) / float(1u << 24); }

// Value noise on a lattice of `px` x `py` cells that wraps exactly at u, v in [0, 1).
float periodic_noise(float u, float v, int px, int py, uint32_t seed) {
  float x = u * px, y = v * py;
  int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  float fx = x - x0, fy = y - y0;
  fx = fx * fx * (3 - 2 * fx);
  fy = fy * fy * (3 - 2 * fy);
  auto at = [&](int ix, int iy) {
    return unit(hash3(uint32_t(((ix % px) + px) % px), uint32_t(((iy % py) + py) % py), seed));
  };
  float a = at(x0, y0), b = at(x0 + 1, y0), c = at(x0, y0 + 1), d = at(x0 + 1, y0 + 1);
  return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy;
}

float fbm(float u, float v, int px, int py, uint32_t seed, int octaves = 4) {
  float sum = 0, amp = 0.5f, norm = 0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * periodic_noise(u, v, px << o, py << o, seed + 977u * o);
    norm += amp;
    amp *= 0.5f;
  }
  return sum / norm;
}

void lerp_rgb(const float a[3], const float b[3], float t, float* out) {
  t = std::clamp(t, 0.f, 1.f);
  for (int c = 0; c < 3; ++c) out[c] = a[c] * (1 - t) + b[c] * t;
}

void wood(float u, float v, uint32_t seed, float* rgb) {
  // Grain runs along x: rings vary with y, gently warped; fine streaks stretched along x.
  const float rings = 6.f;
  float warp = fbm(u, v, 2, 4, seed) - 0.5f;
  float t = v * rings + 1.2f * warp;
  float ring = 0.5f + 0.5f * std::cos(2 * kPi * t);
  ring = std::pow(ring, 3.f);
  float streak = periodic_noise(u, v, 3, 48, seed + 11) * 0.25f;
  const float light[3] = {0.62f, 0.38f, 0.18f}, dark[3] = {0.26f, 0.12f, 0.05f};
  lerp_rgb(light, dark, ring * 0.85f + streak, rgb);
}

void stripes(float u, float v, uint32_t seed, float* rgb) {
  float warp = fbm(u, v, 3, 3, seed) - 0.5f;
  float s = std::sin(2 * kPi * (v * 5.f + 0.8f * warp));
  float t = std::clamp(0.5f + 2.5f * s, 0.f, 1.f);
  const float black[3] = {0.02f, 0.02f, 0.02f}, white[3] = {0.85f, 0.83f, 0.78f};
  lerp_rgb(black, white, t, rgb);
}

void bricks(float u, float v, uint32_t seed, float* rgb) {
  const int rows = 4, cols = 2;
  float y = v * rows;
  int row = int(std::floor(y));
  float x = u * cols + (row % 2 ? 0.5f : 0.f);
  int col = int(std::floor(x));
  float fx = x - col, fy = y - row;
  float mortar_x = 0.04f * rows / cols * 1.0f, mortar_y = 0.08f;
  bool mortar = fx < mortar_x || fx > 1 - mortar_x || fy < mortar_y || fy > 1 - mortar_y;
  float grit = fbm(u, v, 16, 16, seed + 5) - 0.5f;
  if (mortar) {
    float g = 0.55f + 0.2f * grit;
    rgb[0] = g; rgb[1] = g * 0.97f; rgb[2] = g * 0.9f;
    return;
  }
  uint32_t h = hash3(uint32_t(((col % cols) + cols) % cols), uint32_t(row), seed + 3);
  float shade = 0.75f + 0.5f * unit(h);
  rgb[0] = std::clamp((0.45f + 0.25f * grit) * shade, 0.f, 1.f);
  rgb[1] = std::clamp((0.12f + 0.08f * grit) * shade, 0.f, 1.f);
  rgb[2] = std::clamp((0.07f + 0.05f * grit) * shade, 0.f, 1.f);
}

void noise(float u, float v, uint32_t seed, float* rgb) {
  float a = fbm(u, v, 8, 8, seed), b = fbm(u, v, 8, 8, seed + 101);
  rgb[0] = a; rgb[1] = 0.5f * (a + b); rgb[2] = b;
}

// Dark blobs on a light, slightly noisy ground (leopard-like): one jittered disc per cell of
// a periodic 5x5 lattice, radius varying per cell.
void spots(float u, float v, uint32_t seed, float* rgb) {
  const int cells = 5;
  float best = 1e9f;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int cx = int(std::floor(u * cells)) + dx, cy = int(std::floor(v * cells)) + dy;
      const uint32_t h = hash3(uint32_t(((cx % cells) + cells) % cells), uint32_t(((cy % cells) + cells) % cells), seed);
      const float px = (cx + 0.2f + 0.6f * unit(h)) / cells, py = (cy + 0.2f + 0.6f * unit(h * 2654435761u)) / cells;
      const float r = (0.22f + 0.12f * unit(h ^ 0x5bd1e995u)) / cells;
      best = std::min(best, std::hypot(u - px, v - py) / r);
    }
  const float grit = fbm(u, v, 16, 16, seed + 9) - 0.5f;
  const float ground[3] = {0.85f + 0.1f * grit, 0.62f + 0.1f * grit, 0.35f + 0.08f * grit};
  const float dark[3] = {0.08f, 0.06f, 0.05f};
  lerp_rgb(dark, ground, std::clamp((best - 0.85f) * 6.f, 0.f, 1.f), rgb);
}

// Pebbles: one rounded stone per cell of a periodic, jittered 6x6 lattice (Voronoi cells),
// each with its own tint, lit from the upper left, set in dark gaps: many small, distinct,
// crisp shapes, which plain L2 solid synthesis smooths into flat blobs (issue 12).
void pebbles(float u, float v, uint32_t seed, float* rgb) {
  const int cells = 6;
  float d1 = 1e9f, d2 = 1e9f, ox = 0.f, oy = 0.f;
  uint32_t h1 = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int cx = int(std::floor(u * cells)) + dx, cy = int(std::floor(v * cells)) + dy;
      const uint32_t h = hash3(uint32_t(((cx % cells) + cells) % cells), uint32_t(((cy % cells) + cells) % cells), seed);
      const float px = (cx + 0.15f + 0.7f * unit(h)) / cells, py = (cy + 0.15f + 0.7f * unit(h * 2654435761u)) / cells;
      const float d = std::hypot(u - px, v - py) * cells;
      if (d < d1) {
        d2 = d1;
        d1 = d;
        h1 = h;
        ox = (u - px) * cells;
        oy = (v - py) * cells;
      } else if (d < d2) {
        d2 = d;
      }
    }
  const float grit = fbm(u, v, 16, 16, seed + 13) - 0.5f;
  const float gap[3] = {0.16f + 0.1f * grit, 0.13f + 0.08f * grit, 0.1f + 0.06f * grit};
  const float tan[3] = {0.78f, 0.58f, 0.38f}, grey[3] = {0.62f, 0.6f, 0.57f};
  float stone[3];
  lerp_rgb(tan, grey, unit(h1 ^ 0x27d4eb2fu), stone);
  const float brightness = 0.75f + 0.35f * unit(h1 ^ 0x165667b1u);
  const float light = std::clamp(1.f - 0.9f * (ox + oy), 0.45f, 1.35f);
  for (int c = 0; c < 3; ++c) stone[c] = std::clamp(stone[c] * brightness * light + 0.08f * grit, 0.f, 1.f);
  lerp_rgb(gap, stone, std::clamp((d2 - d1 - 0.1f) * 10.f, 0.f, 1.f), rgb);
}

}  // namespace

std::vector<std::string> procedural_kind_names() { return {"wood", "stripes", "bricks", "noise", "spots", "pebbles"}; }

Result<ProceduralKind> parse_procedural_kind(const std::string& name) {
  if (name == "wood") return ProceduralKind::kWood;
  if (name == "stripes") return ProceduralKind::kStripes;
  if (name == "bricks") return ProceduralKind::kBricks;
  if (name == "noise") return ProceduralKind::kNoise;
  if (name == "spots") return ProceduralKind::kSpots;
  if (name == "pebbles") return ProceduralKind::kPebbles;
  return Status(StatusCode::kInvalidArgument, "unknown kind '" + name + "' (wood, stripes, bricks, noise, spots, pebbles)",
                "kind");
}

Result<ImageF> make_procedural_exemplar(const ProceduralParams& p) {
  if (p.width < 8 || p.width > 2048) return Status(StatusCode::kInvalidArgument, "must be in [8, 2048]", "width");
  if (p.height < 8 || p.height > 2048) return Status(StatusCode::kInvalidArgument, "must be in [8, 2048]", "height");
  ImageF img(p.width, p.height, 3);
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < p.width; ++x) {
      float u = (x + 0.5f) / p.width, v = (y + 0.5f) / p.height;
      float srgb[3];
      switch (p.kind) {
        case ProceduralKind::kWood: wood(u, v, p.seed, srgb); break;
        case ProceduralKind::kStripes: stripes(u, v, p.seed, srgb); break;
        case ProceduralKind::kBricks: bricks(u, v, p.seed, srgb); break;
        case ProceduralKind::kNoise: noise(u, v, p.seed, srgb); break;
        case ProceduralKind::kSpots: spots(u, v, p.seed, srgb); break;
        case ProceduralKind::kPebbles: pebbles(u, v, p.seed, srgb); break;
      }
      float* out = img.at(x, y);
      for (int c = 0; c < 3; ++c) out[c] = srgb_to_linear(std::clamp(srgb[c], 0.f, 1.f));
    }
  }
  return img;
}

}  // namespace solidtex
