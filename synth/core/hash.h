// Stateless integer hashing: the only source of randomness in solidtex. Everything random
// is hash(position, level, seed, ...), so results never depend on evaluation order.
#pragma once

#include <cstdint>

namespace solidtex {

inline uint64_t mix64(uint64_t z) {  // splitmix64 finaliser
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

inline uint64_t hash_u64(uint64_t a, uint64_t b = 0, uint64_t c = 0, uint64_t d = 0) {
  uint64_t h = mix64(a + 0x9e3779b97f4a7c15ull);
  h = mix64(h ^ (b + 0x632be59bd9b4e019ull));
  h = mix64(h ^ (c + 0x85157af5ull));
  h = mix64(h ^ (d + 0x2545f4914f6cdd1dull));
  return h;
}

// Uniform float in [0, 1) from a hash.
inline float hash_unit(uint64_t h) { return float(h >> 40) / float(1ull << 24); }

}  // namespace solidtex
