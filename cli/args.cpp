#include "args.h"

#include "core/number_list.h"

#include <cctype>
#include <charconv>
#include <cstdlib>
#include <cmath>
#include <sstream>

namespace solidtex::cli {

Status Args::parse(const std::vector<std::string>& argv) {
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.size() > 1 && a[0] == '-' && !(a.size() > 1 && (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.'))) {
      std::string name = a, value;
      bool inline_value = false;
      if (auto eq = a.find('='); eq != std::string::npos && a.rfind("--", 0) == 0) {
        name = a.substr(0, eq);
        value = a.substr(eq + 1);
        inline_value = true;
      }
      if (valued_.count(name)) {
        if (!inline_value) {
          if (i + 1 >= argv.size()) return Status(StatusCode::kInvalidArgument, "needs a value", name);
          value = argv[++i];
        }
        if (values_.count(name)) return Status(StatusCode::kInvalidArgument, "given more than once", name);
        values_[name] = value;
      } else if (switches_.count(name) && !inline_value) {
        set_switches_.insert(name);
      } else {
        return Status(StatusCode::kInvalidArgument, "unknown option '" + name + "'", name);
      }
    } else {
      positionals_.push_back(a);
    }
  }
  return Status::ok();
}

std::optional<std::string> Args::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

Result<std::string> Args::required(const std::string& name) const {
  auto v = get(name);
  if (!v) return Status(StatusCode::kInvalidArgument, "is required", name);
  return *v;
}

Result<int> Args::get_int(const std::string& name, int fallback, int lo, int hi) const {
  auto v = get(name);
  if (!v) return fallback;
  int out = 0;
  auto [ptr, ec] = std::from_chars(v->data(), v->data() + v->size(), out);
  if (ec != std::errc() || ptr != v->data() + v->size())
    return Status(StatusCode::kInvalidArgument, "'" + *v + "' is not an integer", name);
  if (out < lo || out > hi)
    return Status(StatusCode::kInvalidArgument,
                  "is " + *v + "; must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", name);
  return out;
}

Result<double> Args::get_double(const std::string& name, double fallback, double lo, double hi) const {
  auto v = get(name);
  if (!v) return fallback;
  char* end = nullptr;
  double out = std::strtod(v->c_str(), &end);
  if (v->empty() || end != v->c_str() + v->size() || !std::isfinite(out))
    return Status(StatusCode::kInvalidArgument, "'" + *v + "' is not a number", name);
  if (out < lo || out > hi) return Status(StatusCode::kInvalidArgument, "is " + *v + "; out of range", name);
  return out;
}

Result<std::vector<double>> Args::get_list(const std::string& name, size_t count) const {
  SOLIDTEX_ASSIGN_OR_RETURN(std::string v, required(name));
  return parse_number_list(v, count, name);
}

}  // namespace solidtex::cli
