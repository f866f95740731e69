#include "field/field_file.h"

#include <cmath>
#include <cstring>

#include "core/byte_io.h"
#include "core/image_io.h"

namespace solidtex {
namespace {
constexpr char kMagic[8] = {'S', 'T', 'X', 'F', 'I', 'E', 'L', 'D'};
constexpr uint32_t kHeader = 32;
Status corrupt(const std::string& m) { return Status(StatusCode::kCorrupt, m, "field"); }
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
  int64_t n = 1;
  for (int d : f.dims) {
    if (d < 2 || d > 4096) return corrupt("impossible grid size");
    n *= d;
  }
  if (uint64_t(n) * 32 > r.remaining()) return corrupt("node data ends early");
  f.nodes.resize(size_t(n));
  for (Quat& q : f.nodes) {
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.w));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.x));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.y));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(q.z));
  }
  uint8_t has_scales = 0;
  SOLIDTEX_RETURN_IF_ERROR(r.u8(has_scales));
  if (has_scales > 1) return corrupt("flag byte out of range");
  if (has_scales) {
    if (uint64_t(n) * 24 > r.remaining()) return corrupt("scale data ends early");
    f.log_scales.resize(size_t(n));
    for (auto& ls : f.log_scales)
      for (double& v : ls) SOLIDTEX_RETURN_IF_ERROR(r.f64(v));
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
