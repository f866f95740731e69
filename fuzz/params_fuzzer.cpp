// The service's JSON parameter decoders (server/api_json.h) on any request body text
// (parse_request_json: strict JSON, duplicate keys refused, integral floats as integers;
// normalized_body): analysis params (POST /v1/exemplars),
// synthesis params (volumes), and a mesh placement, followed by what the surface and
// from-mesh handlers compute from a placement (placed_box, bounding_voxels).
// Checked: accepted params validate and survive to_json -> from_json unchanged; an accepted
// placement is finite with a positive scale, and the voxel count of the placed box is >= 1.
#include <cmath>

#include "api_json.h"
#include "core/json_fields.h"
#include "fuzz_support.h"

using namespace solidtex;
using namespace solidtex::server;
using nlohmann::json;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = fuzz::text(data, size);
  // Request bodies: strict JSON with integral floats read as integers (parse_request_json);
  // bodies handed on to a service are normalised to that JSON's text first.
  Result<json> j = parse_request_json(text, "body");
  FUZZ_CHECK(j.is_ok() == parse_json_text(text, "body").is_ok());
  if (!j) {
    FUZZ_CHECK(normalized_body(text) == text);
    return 0;
  }
  FUZZ_CHECK(parse_json_text(normalized_body(text), "body").is_ok());

  if (auto a = analysis_params_from_json(*j, "params")) {
    FUZZ_CHECK(a->validate().is_ok());
    const json out = to_json(*a);
    auto b = analysis_params_from_json(out, "params");
    FUZZ_CHECK(b.is_ok());
    FUZZ_CHECK(to_json(*b) == out);
  } else {
    FUZZ_CHECK(!a.status().message().empty());
  }

  if (auto s = synthesis_params_from_json(*j, "params", SynthesisParams{})) {
    FUZZ_CHECK(s->validate().is_ok());
    const json out = to_json(*s);
    auto t = synthesis_params_from_json(out, "params", SynthesisParams{});
    FUZZ_CHECK(t.is_ok());
    FUZZ_CHECK(to_json(*t) == out);
  } else {
    FUZZ_CHECK(!s.status().message().empty());
  }

  // A small mesh's bounds, as the handlers pass mesh->bounds().
  const MeshBounds bounds{{-1.5, 0, 2}, {0.5, 1, 2.25}};
  double margin = -1;
  if (auto p = placement_from_json(*j, "placement", bounds, &margin)) {
    FUZZ_CHECK(margin >= 0 && margin <= 1);
    FUZZ_CHECK(std::isfinite(p->scale) && p->scale > 0);
    for (double t : p->translate) FUZZ_CHECK(std::isfinite(t));
    const MeshBounds box = placed_box(bounds, *p, margin);
    for (int a = 0; a < 3; ++a) FUZZ_CHECK(box.min[size_t(a)] <= box.max[size_t(a)]);
    FUZZ_CHECK(bounding_voxels(bounds, *p) >= 1);
  }
  return 0;
}
