// solidtex exemplar KIND -o FILE.png [--size W,H] [--seed S]
#include <iostream>

#include "args.h"
#include "commands.h"
#include "core/image_io.h"
#include "testkit/procedural_exemplar.h"

namespace solidtex::cli {

Status run_exemplar(const std::vector<std::string>& argv) {
  Args args({"-o", "--size", "--seed"}, {});
  SOLIDTEX_RETURN_IF_ERROR(args.parse(argv));
  if (args.positionals().size() != 1)
    return Status(StatusCode::kInvalidArgument, "expects exactly one KIND (wood, stripes, bricks, noise)", "kind");
  ProceduralParams p;
  SOLIDTEX_ASSIGN_OR_RETURN(p.kind, parse_procedural_kind(args.positionals()[0]));
  if (args.has("--size")) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto size, args.get_list("--size", 2));
    p.width = int(size[0]);
    p.height = int(size[1]);
  }
  SOLIDTEX_ASSIGN_OR_RETURN(int seed, args.get_int("--seed", 1, 0, 1 << 30));
  p.seed = uint32_t(seed);
  SOLIDTEX_ASSIGN_OR_RETURN(std::string out, args.required("-o"));
  SOLIDTEX_ASSIGN_OR_RETURN(ImageF img, make_procedural_exemplar(p));
  SOLIDTEX_RETURN_IF_ERROR(save_png_srgb8(out, img));
  std::cerr << "wrote " << out << " (" << p.width << "x" << p.height << ")\n";
  return Status::ok();
}

}  // namespace solidtex::cli
