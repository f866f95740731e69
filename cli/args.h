// Minimal command-line parsing for the solidtex subcommands: declared options only, unknown
// flags are errors that name the flag (pbrt's ReportUnused habit), values are validated by
// typed getters whose errors name the flag too.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex::cli {

class Args {
 public:
  // `valued`: options that take a value ("-o" included); `switches`: options without one.
  Args(std::set<std::string> valued, std::set<std::string> switches)
      : valued_(std::move(valued)), switches_(std::move(switches)) {}

  Status parse(const std::vector<std::string>& argv);

  bool has(const std::string& name) const { return values_.count(name) || set_switches_.count(name); }
  const std::vector<std::string>& positionals() const { return positionals_; }
  std::optional<std::string> get(const std::string& name) const;
  Result<std::string> required(const std::string& name) const;
  // Integer option with range check; `fallback` when absent.
  Result<int> get_int(const std::string& name, int fallback, int lo, int hi) const;
  Result<double> get_double(const std::string& name, double fallback, double lo, double hi) const;
  // Comma-separated numbers, exactly `count` of them.
  Result<std::vector<double>> get_list(const std::string& name, size_t count) const;

 private:
  std::set<std::string> valued_, switches_;
  std::map<std::string, std::string> values_;
  std::set<std::string> set_switches_;
  std::vector<std::string> positionals_;
};

}  // namespace solidtex::cli
