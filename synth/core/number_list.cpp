#include "core/number_list.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace solidtex {

Result<std::vector<double>> parse_number_list(const std::string& text, size_t count, const std::string& field) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double d = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(d))
      return Status(StatusCode::kInvalidArgument, "'" + item + "' in '" + text + "' is not a number", field);
    out.push_back(d);
  }
  if (out.size() != count)
    return Status(StatusCode::kInvalidArgument,
                  "expects " + std::to_string(count) + " comma-separated numbers, got '" + text + "'", field);
  return out;
}

}  // namespace solidtex
