// decode_field (field/field_file.h), the .stf reader, then what loading a stored field does
// with it (QuatGridField::create, as load_field and the volume service do; the stored sketch
// is re-parsed when a curve is added). Each input is decoded as given and with its size and
// checksum fields recomputed (fuzz_support.h), so mutated payloads reach the payload decoder.
// Checked: encode_field(decode_field(x)) == x; what decode_field accepts loads
// (QuatGridField::create accepts it); the grid field answers finite unit quaternions and
// scales within [0.25, 4] everywhere, inside and outside the grid, and node 0's frame at the
// grid's origin.
#include <algorithm>
#include <cmath>

#include "field/field_file.h"
#include "field/sketch.h"
#include "fuzz_support.h"

using namespace solidtex;

namespace {

void check_at(const QuatGridField& g, const WorldPoint& p) {
  const Quat q = g.at(p);
  FUZZ_CHECK(std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z));
  FUZZ_CHECK(std::fabs(q.dot(q) - 1) < 1e-6);
  for (double s : g.scale_at(p)) FUZZ_CHECK(s >= kMinScale * 0.999 && s <= kMaxScale * 1.001);
}

void check_grid(const QuatGridField& g, const StoredField& f) {
  // Points of the world (synthesis asks for any voxel) and points relative to the grid.
  for (const WorldPoint& p : {WorldPoint{0, 0, 0}, WorldPoint{1e6, -1e6, 3.5}, WorldPoint{-7, 12.25, 1e9}}) check_at(g, p);
  const double ext[3] = {f.spacing * (f.dims[0] - 1), f.spacing * (f.dims[1] - 1), f.spacing * (f.dims[2] - 1)};
  for (double u : {-0.5, 0.0, 0.37, 1.0, 1.5})
    for (double v : {0.0, 0.61})
      for (double w : {0.0, 0.83}) {
        const WorldPoint p{f.origin.x + u * ext[0], f.origin.y + v * ext[1], f.origin.z + w * ext[2]};
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) check_at(g, p);
      }
  // At the first node the field is that node's rotation (normalised without overflow here).
  const WorldPoint o = f.origin;
  if (std::isfinite(o.x) && std::isfinite(o.y) && std::isfinite(o.z)) {
    const Quat& n = f.nodes[0];
    const double m = std::max({std::fabs(n.w), std::fabs(n.x), std::fabs(n.y), std::fabs(n.z)});
    const Quat want = Quat{n.w / m, n.x / m, n.y / m, n.z / m}.normalized();
    FUZZ_CHECK(std::fabs(std::fabs(g.at(o).dot(want)) - 1) < 1e-6);
  }
  FUZZ_CHECK(g.max_scale() >= 1 && g.max_scale() <= kMaxScale * 1.001);
  FUZZ_CHECK(!g.describe().empty());
}

void decode_and_check(std::span<const uint8_t> file) {
  Result<StoredField> f = decode_field(file);
  if (!f) {
    FUZZ_CHECK(!f.status().message().empty());
    return;
  }
  FUZZ_CHECK(looks_like_field_file(file));
  const std::vector<uint8_t> again = encode_field(*f);
  FUZZ_CHECK(again.size() == file.size() && std::equal(again.begin(), again.end(), file.begin()));
  auto grid = QuatGridField::create(f->origin, f->spacing, f->dims, f->nodes, f->log_scales);
  FUZZ_CHECK(grid.is_ok());
  check_grid(**grid, *f);
  (void)parse_sketch_json(f->sketch_json);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::as_given_and_with_valid_checksum(data, size, decode_and_check);
  return 0;
}
