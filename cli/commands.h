// Subcommands of the `solidtex` executable. Each parses its own arguments, does its work
// through synth/, prints its result, and returns a Status; main() reports errors once.
#pragma once

#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex::cli {

Status run_analyze(const std::vector<std::string>& args);
Status run_exemplar(const std::vector<std::string>& args);
Status run_slice(const std::vector<std::string>& args);
Status run_field(const std::vector<std::string>& args);
Status run_serve(const std::vector<std::string>& args);

// Applies --threads (0 = all cores) for the rest of the process.
void set_thread_limit(int threads);

}  // namespace solidtex::cli
