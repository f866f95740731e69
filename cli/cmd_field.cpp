// solidtex field SKETCH.json -o FIELD.stf [--json]
#include <nlohmann/json.hpp>

#include <fstream>
#include <iostream>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "field/field_file.h"
#include "field/sketch.h"
#include "field/tensor_field.h"

namespace solidtex::cli {

Status run_field(const std::vector<std::string>& argv) {
  Args args({"-o"}, {"--json"});
  SOLIDTEX_RETURN_IF_ERROR(args.parse(argv));
  if (args.positionals().size() != 1) return Status(StatusCode::kInvalidArgument, "expects one SKETCH.json", "sketch");
  SOLIDTEX_ASSIGN_OR_RETURN(std::string out, args.required("-o"));
  std::ifstream in(args.positionals()[0]);
  if (!in) return Status(StatusCode::kNotFound, "cannot open '" + args.positionals()[0] + "'", "sketch");
  std::stringstream text;
  text << in.rdbuf();
  SOLIDTEX_ASSIGN_OR_RETURN(Sketch sketch, parse_sketch_json(text.str()));
  FieldSolveStats stats;
  SOLIDTEX_ASSIGN_OR_RETURN(auto solver, FieldSolver::solve(sketch, &stats));
  StoredField f;
  f.origin = solver->origin();
  f.spacing = solver->spacing();
  f.dims = solver->dims();
  f.singular_nodes = stats.singular_nodes;
  f.nodes = solver->nodes();
  f.log_scales = solver->log_scales();
  f.sketch_json = text.str();
  SOLIDTEX_RETURN_IF_ERROR(save_field(out, f));
  if (args.has("--json")) {
    nlohmann::json j = {{"field", out},
                        {"seconds", stats.seconds},
                        {"residual", stats.residual},
                        {"singular_cells", stats.singular_nodes},
                        {"constrained_nodes", stats.constrained_nodes},
                        {"nodes", stats.nodes},
                        {"dims", {f.dims[0], f.dims[1], f.dims[2]}},
                        {"spacing", f.spacing},
                        {"curves", sketch.curves.size()},
                        {"scale_points", sketch.scales.size()}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "wrote " << out << ": " << f.dims[0] << "x" << f.dims[1] << "x" << f.dims[2] << " nodes, solved in "
              << stats.seconds << " s, residual " << stats.residual << ", " << stats.singular_nodes << " singular\n";
  }
  return Status::ok();
}

}  // namespace solidtex::cli
