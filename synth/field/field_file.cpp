#include "field/field_file.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/byte_io.h"
#include "core/image_io.h"

namespace solidtex {
namespace {
constexpr char kMagic[8] = {'S', 'T', 'X', 'F', 'I', 'E', 'L', 'D'};
constexpr uint32_t kHeader = 32;
Status corrupt(const std::string& m) { return Status(StatusCode::kCorrupt, m, "field"); }
// A stored value the writer cannot have produced (the checksum only proves the bytes are the
// ones written): kCorrupt naming the value, e.g. field "field.spacing".
Status bad_value(const std::string& item, const std::string& m) {
  return Status(StatusCode::kCorrupt, m, "field." + item);
}
std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
// The solver stores normalised quaternions (|q|^2 within a few ulp of 1).
constexpr double kUnitTolerance = 1e-6;
}  // namespace

bool looks_like_field_file(std::span<const uint8_t> b) { return b.size() >= 8 && std::memcmp(b.data(), kMagic, 8) == 0; }

std::vector<uint8_t> encode_field(const StoredField& f) {
  ByteWriter w;
  w.f64(f.origin.x);
  w.f64(f.origin.y);
  w.f64(f.origin.z);
  w.f64(f.spacing);
  for (int d : f.dims) w.i32(d);
  w.i32(f.singular_nodes);
  for (const Quat& q : f.nodes) {
    w.f64(q.w);
    w.f64(q.x);
    w.f64(q.y);
    w.f64(q.z);
  }
  w.u8(f.log_scales.empty() ? 0 : 1);
  for (const auto& ls : f.log_scales)
    for (double v : ls) w.f64(v);
  w.u64(f.sketch_json.size());
  w.bytes(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(f.sketch_json.data()), f.sketch_json.size()));
  std::vector<uint8_t> payload = std::move(w.buffer());
  ByteWriter h;
  h.bytes(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(kMagic), 8));
  h.u32(kFieldFormatVersion);
  h.u32(kHeader);
  h.u64(payload.size());
  h.u64(checksum64(payload));
  std::vector<uint8_t> out = std::move(h.buffer());
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

Result<StoredField> decode_field(std::span<const uint8_t> bytes) {
  if (bytes.size() < kHeader) return corrupt("file is shorter than the header");
  if (!looks_like_field_file(bytes)) return corrupt("not a solidtex field (bad magic)");
  ByteReader hr(bytes.subspan(8, kHeader - 8));
  uint32_t version = 0, header = 0;
  uint64_t size = 0, sum = 0;
  SOLIDTEX_RETURN_IF_ERROR(hr.u32(version));
  SOLIDTEX_RETURN_IF_ERROR(hr.u32(header));
  SOLIDTEX_RETURN_IF_ERROR(hr.u64(size));
  SOLIDTEX_RETURN_IF_ERROR(hr.u64(sum));
  if (version != kFieldFormatVersion)
    return Status(StatusCode::kVersionMismatch, "field format version " + std::to_string(version) + " is not supported",
                  "field");
  if (header != kHeader || size != bytes.size() - kHeader) return corrupt("size fields disagree with the file (truncated?)");
  auto payload = bytes.subspan(kHeader);
  if (checksum64(payload) != sum) return corrupt("checksum mismatch: the file is damaged");
  ByteReader r(payload);
  StoredField f;
  SOLIDTEX_RETURN_IF_ERROR(r.f64(f.origin.x));
  SOLIDTEX_RETURN_IF_ERROR(r.f64(f.origin.y));
  SOLIDTEX_RETURN_IF_ERROR(r.f64(f.origin.z));
  SOLIDTEX_RETURN_IF_ERROR(r.f64(f.spacing));
  for (int& d : f.dims) SOLIDTEX_RETURN_IF_ERROR(r.i32(d));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(f.singular_nodes));
  // Everything a decoded field holds is what QuatGridField::create accepts, so a field file
  // that decodes also loads.
  if (!std::isfinite(f.origin.x) || !std::isfinite(f.origin.y) || !std::isfinite(f.origin.z))
    return bad_value("origin", "stored origin (" + number(f.origin.x) + ", " + number(f.origin.y) + ", " +
                                   number(f.origin.z) + ") is not finite");
  if (!(f.spacing > 0) || !std::isfinite(f.spacing))
    return bad_value("spacing", "stored spacing " + number(f.spacing) + " is not a finite number > 0");
  int64_t n = 1;
  for (int d : f.dims) {
    if (d < 2 || d > kMaxGridSide)
      return bad_value("dims", "stored grid size " + std::to_string(f.dims[0]) + "x" + std::to_string(f.dims[1]) + "x" +
                                   std::to_string(f.dims[2]) + " is impossible (each side in [2, " +
                                   std::to_string(kMaxGridSide) + "])");
    n *= d;
  }
  if (f.singular_nodes < 0 || f.singular_nodes > n)
    return bad_value("singular_nodes", "stored singular node count " + std::to_string(f.singular_nodes) +
                                           " is outside [0, " + std::to_string(n) + "]");
  if (uint64_t(n) * 32 > r.remaining()) return corrupt("node data ends early");
  f.nodes.resize(size_t(n));
  for (size_t i = 0; i < f.nodes.size(); ++i) {
    Quat& q = f.nodes[i];
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.w));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.x));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.y));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.z));
    // Also refuses non-finite, zero and huge quaternions (|q|^2 overflows to infinity).
    if (!(std::fabs(q.dot(q) - 1) <= kUnitTolerance))
      return bad_value("nodes", "stored node " + std::to_string(i) + " (" + number(q.w) + ", " + number(q.x) + ", " +
                                    number(q.y) + ", " + number(q.z) + ") is not a unit quaternion");
  }
  uint8_t has_scales = 0;
  SOLIDTEX_RETURN_IF_ERROR(r.u8(has_scales));
  if (has_scales > 1) return corrupt("flag byte out of range");
  if (has_scales) {
    if (uint64_t(n) * 24 > r.remaining()) return corrupt("scale data ends early");
    f.log_scales.resize(size_t(n));
    for (size_t i = 0; i < f.log_scales.size(); ++i)
      for (double& v : f.log_scales[i]) {
        SOLIDTEX_RETURN_IF_ERROR(r.f64(v));
        // The same bounds as QuatGridField::create (the solver clamps to [log 0.25, log 4]).
        if (!std::isfinite(v) || std::exp(v) < kMinScale * 0.999 || std::exp(v) > kMaxScale * 1.001)
          return bad_value("log_scales", "stored log scale " + number(v) + " of node " + std::to_string(i) +
                                             " is outside [log 0.25, log 4]");
      }
  }
  uint64_t len = 0;
  SOLIDTEX_RETURN_IF_ERROR(r.u64(len));
  std::vector<uint8_t> text;
  SOLIDTEX_RETURN_IF_ERROR(r.bytes(text, size_t(len)));
  f.sketch_json.assign(text.begin(), text.end());
  if (r.remaining() != 0) return corrupt("unexpected bytes at the end");
  return f;
}

Status save_field(const std::string& path, const StoredField& f) { return write_file_atomic(path, encode_field(f)); }

Result<std::shared_ptr<const QuatGridField>> load_field(const std::string& path) {
  SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, read_file_bytes(path, int64_t(1) << 30));
  auto f = decode_field(bytes);
  if (!f) return f.status().with_context("'" + path + "'");
  return QuatGridField::create(f->origin, f->spacing, f->dims, f->nodes, f->log_scales);
}

}  // namespace solidtex
