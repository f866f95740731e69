// Shared helpers of the libFuzzer harnesses (fuzz/*_fuzzer.cpp).
//
// Each harness feeds one parser the fuzzer's bytes and checks what the parser promises: errors
// are Status values (never exceptions, exits or crashes), and what it accepts satisfies the
// documented invariants (e.g. an encode/decode round trip gives the same value back). A
// broken invariant aborts via FUZZ_CHECK, which libFuzzer records as a crash with its input.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "core/byte_io.h"

#define FUZZ_CHECK(cond)                                                                  \
  do {                                                                                    \
    if (!(cond)) {                                                                        \
      std::fprintf(stderr, "%s:%d: FUZZ_CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                       \
    }                                                                                     \
  } while (0)

namespace solidtex::fuzz {

inline std::span<const uint8_t> bytes(const uint8_t* data, size_t size) { return {data, size}; }
inline std::string text(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

// The .stx and .stf files share a 32-byte header: magic[8] | u32 version | u32 header bytes |
// u64 payload bytes | u64 checksum64(payload). A copy of `file` whose payload size and
// checksum fields match its payload (magic, version and header size are kept as given), so
// mutations of the payload get past the checksum and reach the payload decoder. Empty when
// `file` is shorter than the header.
inline std::vector<uint8_t> with_valid_checksum(std::span<const uint8_t> file) {
  constexpr size_t kHeader = 32;
  if (file.size() < kHeader) return {};
  std::vector<uint8_t> out(file.begin(), file.end());
  const std::span<const uint8_t> payload(out.data() + kHeader, out.size() - kHeader);
  const uint64_t fields[2] = {uint64_t(payload.size()), checksum64(payload)};
  for (int f = 0; f < 2; ++f)
    for (int i = 0; i < 8; ++i) out[16 + size_t(f) * 8 + size_t(i)] = uint8_t(fields[f] >> (8 * i));
  return out;
}

// Runs `check` on the input as given, then on its checksum-fixed copy when that differs.
template <class Check>
void as_given_and_with_valid_checksum(const uint8_t* data, size_t size, Check&& check) {
  check(bytes(data, size));
  const std::vector<uint8_t> fixed = with_valid_checksum(bytes(data, size));
  if (!fixed.empty() && !std::equal(fixed.begin(), fixed.end(), data)) check(std::span<const uint8_t>(fixed));
}

}  // namespace solidtex::fuzz
