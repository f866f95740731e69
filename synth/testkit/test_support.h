// Helpers shared by unit tests: where the real test data lives, and small exemplars.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/image.h"
#include "testkit/procedural_exemplar.h"

namespace solidtex::testing {

// ../shared next to the repository (CI always has it), or $SOLIDTEX_SHARED.
inline std::string shared_dir() {
  if (const char* env = std::getenv("SOLIDTEX_SHARED"); env && std::filesystem::exists(env)) return env;
  for (const char* c : {"../shared", "../../shared", "../../../shared"})
    if (std::filesystem::exists(c)) return std::filesystem::canonical(c).string();
  return {};
}

inline std::string exemplar_path(const std::string& name) {
  const std::string dir = shared_dir();
  if (dir.empty()) return {};
  const std::string p = dir + "/data/exemplars/" + name;
  return std::filesystem::exists(p) ? p : std::string();
}

inline ImageF procedural(ProceduralKind kind, int w, int h, uint32_t seed = 1) {
  return make_procedural_exemplar({kind, w, h, seed}).value();
}

}  // namespace solidtex::testing
