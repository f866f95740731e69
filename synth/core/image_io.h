// Decoding and encoding images with OpenImageIO. The only translation unit that includes
// OpenImageIO headers. Thread-safe (no shared state besides OIIO's own).
//
// Decoding contract:
//  - PNG, JPEG, TIFF and OpenEXR, detected from the bytes (never from a file name), each read
//    by that format's OIIO reader only (no other plugin is tried); a PNG whose chunks end
//    before IEND is refused as truncated before libpng sees it; OpenEXR is read with the
//    OpenEXR Core library (OIIO "openexr:core", set on the first decode);
//  - 8/16-bit integer and half/float pixels; 1 (gray), 2 (gray+alpha), 3 (RGB), 4 (RGBA) channels;
//  - the result is always 3-channel *linear* float RGB: integer images are taken as sRGB
//    unless they declare a linear color space, float images as linear; gray is replicated,
//    alpha is dropped;
//  - dimensions are checked against ImageLimits from the header *before* pixels are decoded
//    (OIIO 2.4 honours its own size limit only for TIFF).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/status.h"

namespace solidtex {

struct ImageLimits {
  int64_t max_bytes = 64ll << 20;    // encoded size, bytes; default 64 MiB
  int max_side = 8192;               // pixels along either side
  int64_t max_pixels = 16ll << 20;   // width*height; default 16 Mi pixels
};

// `what` names the input in error messages and as the Status field (e.g. "image", "mask").
Result<ImageF> decode_image(std::span<const uint8_t> bytes, const ImageLimits& limits = {},
                            const std::string& what = "image");
Result<ImageF> load_image(const std::string& path, const ImageLimits& limits = {},
                          const std::string& what = "image");

// Reads a whole file with a size cap (kTooLarge beyond it).
Result<std::vector<uint8_t>> read_file_bytes(const std::string& path, int64_t max_bytes);

// Linear RGB -> 8-bit sRGB bytes (clamped, sRGB curve, rounded), interleaved like the image.
std::vector<uint8_t> to_srgb8(const ImageF& rgb_linear);
// Encodes a linear-RGB image (3 channels) as an 8-bit sRGB PNG (quantised by to_srgb8).
Result<std::vector<uint8_t>> encode_png_srgb8(const ImageF& rgb_linear);
Status save_png_srgb8(const std::string& path, const ImageF& rgb_linear);

// Encodes a 1- or 3-channel image with values in [0,1] as 16-bit PNG, without a transfer
// curve (for masks and test fixtures); `srgb` applies the sRGB curve first.
Status save_png16(const std::string& path, const ImageF& image, bool srgb);

}  // namespace solidtex
