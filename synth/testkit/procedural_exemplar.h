// Procedural, seamlessly tiling exemplars so that demos and unit tests need no downloads.
// Deterministic: the same (kind, size, seed) always gives the same pixels.
#pragma once

#include <string>
#include <vector>

#include "core/image.h"
#include "core/status.h"

namespace solidtex {

enum class ProceduralKind { kWood, kStripes, kBricks, kNoise, kSpots, kPebbles };

struct ProceduralParams {
  ProceduralKind kind = ProceduralKind::kWood;
  int width = 128;    // pixels, [8, 2048]
  int height = 128;   // pixels, [8, 2048]
  uint32_t seed = 1;  // changes the noise, not the kind of pattern
};

Result<ProceduralKind> parse_procedural_kind(const std::string& name);
std::vector<std::string> procedural_kind_names();

// Returns a linear-RGB image.
Result<ImageF> make_procedural_exemplar(const ProceduralParams& params);

}  // namespace solidtex
