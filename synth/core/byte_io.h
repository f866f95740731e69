// Endian-explicit binary encoding for stored files: every multi-byte value is little-endian
// on disk whatever the host. The reader is bounds-checked and reports truncation as kCorrupt.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex {

class ByteWriter {
 public:
  void u8(uint8_t v) { out_.push_back(v); }
  void u16(uint16_t v) { put(v); }
  void u32(uint32_t v) { put(v); }
  void u64(uint64_t v) { put(v); }
  void i32(int32_t v) { put(uint32_t(v)); }
  void f32(float v) { put(std::bit_cast<uint32_t>(v)); }
  void f64(double v) { put(std::bit_cast<uint64_t>(v)); }
  void f32s(std::span<const float> v) {
    for (float f : v) f32(f);
  }
  void bytes(std::span<const uint8_t> v) { out_.insert(out_.end(), v.begin(), v.end()); }
  std::vector<uint8_t>& buffer() { return out_; }

 private:
  template <typename U>
  void put(U v) {
    for (size_t i = 0; i < sizeof(U); ++i) out_.push_back(uint8_t(v >> (8 * i)));
  }
  std::vector<uint8_t> out_;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const uint8_t> in) : in_(in) {}
  Status u8(uint8_t& v) { return get(v); }
  Status u16(uint16_t& v) { return get(v); }
  Status u32(uint32_t& v) { return get(v); }
  Status u64(uint64_t& v) { return get(v); }
  Status i32(int32_t& v) {
    uint32_t u;
    SOLIDTEX_RETURN_IF_ERROR(get(u));
    v = int32_t(u);
    return Status::ok();
  }
  Status f32(float& v) {
    uint32_t u;
    SOLIDTEX_RETURN_IF_ERROR(get(u));
    v = std::bit_cast<float>(u);
    return Status::ok();
  }
  Status f64(double& v) {
    uint64_t u;
    SOLIDTEX_RETURN_IF_ERROR(get(u));
    v = std::bit_cast<double>(u);
    return Status::ok();
  }
  Status f32s(std::vector<float>& v, size_t count) {
    if (remaining() < count * 4) return truncated();
    v.resize(count);
    for (auto& f : v) SOLIDTEX_RETURN_IF_ERROR(f32(f));
    return Status::ok();
  }
  Status bytes(std::vector<uint8_t>& v, size_t count) {
    if (remaining() < count) return truncated();
    v.assign(in_.begin() + pos_, in_.begin() + pos_ + count);
    pos_ += count;
    return Status::ok();
  }
  size_t remaining() const { return in_.size() - pos_; }
  size_t position() const { return pos_; }

 private:
  static Status truncated() { return Status(StatusCode::kCorrupt, "data ends early (truncated)"); }
  template <typename U>
  Status get(U& v) {
    if (remaining() < sizeof(U)) return truncated();
    v = 0;
    for (size_t i = 0; i < sizeof(U); ++i) v |= U(U(in_[pos_ + i]) << (8 * i));
    pos_ += sizeof(U);
    return Status::ok();
  }
  std::span<const uint8_t> in_;
  size_t pos_ = 0;
};

// 64-bit checksum of a byte string (splitmix-chained over little-endian 8-byte words).
uint64_t checksum64(std::span<const uint8_t> data);

// Writes `bytes` to `path` atomically: temporary file in the same directory, fsync, rename,
// fsync of the directory. A crash leaves either the old file or the new one, never a mix.
Status write_file_atomic(const std::string& path, std::span<const uint8_t> bytes);

// A complete, fsync'd temporary file ".<name>.tmp-<pid>-<n>" beside `target`, created with
// O_EXCL under a name no other writer uses (the pid alone is not enough: two threads of one
// process may write one target at once). Returns its path; the caller renames or links it.
Result<std::string> write_temporary_file(const std::string& target, std::span<const uint8_t> bytes);

// fsync of the directory holding `file` (makes a rename or link into it durable); best effort.
void sync_parent_directory(const std::string& file);

}  // namespace solidtex
