// The .stf frame-field file: versioned, checksummed, little-endian.
//   header: magic "STXFIELD" | u32 version | u32 header bytes (32) | u64 payload bytes |
//           u64 checksum64(payload)
//   payload: origin (3 f64), spacing (f64), dims (3 i32), singular node count (i32),
//            node quaternions (w, x, y, z as f64, x fastest), u8 has-scales and then per node
//            three f64 log scales, then the sketch JSON (u64 length
//            + UTF-8 bytes) so a stored field can be extended by more curves later.
// decode_field refuses (kCorrupt, Status field "field" or "field.<value>") damaged files and
// values the writer never produces: a non-finite origin, a spacing that is not finite and > 0,
// sides outside [2, kMaxGridSide], a singular count outside [0, nodes], nodes that are not
// unit quaternions, log scales outside [log 0.25, log 4]. What it accepts loads
// (QuatGridField::create accepts it).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "field/frame_field.h"
#include "core/status.h"

namespace solidtex {

inline constexpr uint32_t kFieldFormatVersion = 1;

struct StoredField {
  WorldPoint origin;
  double spacing = 1;
  std::array<int, 3> dims{};
  int singular_nodes = 0;
  std::vector<Quat> nodes;
  std::vector<std::array<double, 3>> log_scales;  // empty or one per node
  std::string sketch_json;
};

std::vector<uint8_t> encode_field(const StoredField& f);
Result<StoredField> decode_field(std::span<const uint8_t> bytes);
bool looks_like_field_file(std::span<const uint8_t> bytes);
Status save_field(const std::string& path, const StoredField& f);
Result<std::shared_ptr<const QuatGridField>> load_field(const std::string& path);

}  // namespace solidtex
