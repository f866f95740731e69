// The .stx table file: versioned, checksummed, little-endian.
//
// Layout: a 32-byte header, then the payload.
//   header: magic "STXTABLE" | u32 format version | u32 header bytes (32) |
//           u64 payload bytes | u64 checksum64(payload)
//   payload: parameters; shared and mask flags; the distinct matching images (float32);
//            per level: analysis statistics, a PCA basis per distinct image, and candidate
//            triples per searched plane (per pixel: a count, then for each triple the two
//            coordinates of the *other* planes as u16 pairs; the pixel's own is implicit);
//            version 3 only: per level and distinct image, the usage penalty of every pixel.
// Stacks and projected neighborhoods are not stored; Table::assemble reproduces them.
// Decoding checks magic, version, sizes and checksum before it trusts any field, and every
// coordinate afterwards, so a damaged file is a clean kCorrupt / kVersionMismatch.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"
#include "analysis/table.h"

namespace solidtex {

// 2: suggested plane weights; 3: version 2 plus usage penalties after the last level (per
// level and distinct image, float32 per pixel). Tables without usage penalties are written as
// version 2, so files stay readable by older builds where nothing new is in them.
inline constexpr uint32_t kTableFormatVersion = 3;
inline constexpr uint32_t kOldestTableFormatVersion = 2;

std::vector<uint8_t> encode_table(const Table& table);
Result<std::shared_ptr<const Table>> decode_table(std::span<const uint8_t> bytes);

Status save_table(const std::string& path, const Table& table);  // atomic replace
Result<std::shared_ptr<const Table>> load_table(const std::string& path);

}  // namespace solidtex
