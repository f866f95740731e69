// Comma-separated number lists ("1,0.5,-2") as used by CLI options and field/region specs.
#pragma once

#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex {

// Exactly `count` finite numbers; errors name `field` and the offending item.
Result<std::vector<double>> parse_number_list(const std::string& text, size_t count, const std::string& field);

}  // namespace solidtex
