// decode_image (core/image_io.h): signature sniffing, the PNG chunk and OpenEXR header checks,
// the header checks against ImageLimits (before any pixel is decoded), then the pixel decode and
// conversion to linear RGB. What it accepts must honour the limits, be 3-channel and finite,
// decode the same way twice, and survive a PNG round trip (encode_png_srgb8, decode again: same size).
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstring>

#include "core/image_io.h"
#include "fuzz_support.h"

using namespace solidtex;

// No leak suppressions: decode_image refuses truncated PNGs before libpng reads past the end
// (where OIIO 2.4's read callback leaked its error message).
// The same bytes must decode to the same pixels. ASan is told not to fill new heap memory (by
// default the first 4 KB of each allocation get 0xbe), so pixels a decoder takes from memory
// it never wrote can differ between the two decodes. (It need not: for the short zip chunks of
// the OpenEXR finding in fuzz/README.md both decodes here got the same garbage; valgrind saw it.)
extern "C" const char* __asan_default_options() { return "max_malloc_fill_size=0"; }

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  OIIO::attribute("threads", 1);  // decode on the calling thread: the fuzzer is single-threaded
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Small limits so that the size checks are reached and pixel buffers stay small; the
  // service's defaults only move the thresholds.
  ImageLimits limits;
  limits.max_bytes = 1 << 20;
  limits.max_side = 512;
  limits.max_pixels = 128 * 128;
  Result<ImageF> img = decode_image(fuzz::bytes(data, size), limits, "image");
  if (!img) {
    FUZZ_CHECK(!img.status().message().empty());
    return 0;
  }
  FUZZ_CHECK(img->width >= 1 && img->height >= 1);
  FUZZ_CHECK(img->width <= limits.max_side && img->height <= limits.max_side);
  FUZZ_CHECK(img->pixel_count() <= limits.max_pixels);
  FUZZ_CHECK(img->channels == 3);
  FUZZ_CHECK(img->pixels.size() == size_t(img->pixel_count()) * 3);
  for (float v : img->pixels) FUZZ_CHECK(std::isfinite(v));
  Result<ImageF> twice = decode_image(fuzz::bytes(data, size), limits, "image");
  FUZZ_CHECK(twice.is_ok() && twice->width == img->width && twice->height == img->height);
  FUZZ_CHECK(std::memcmp(twice->pixels.data(), img->pixels.data(), img->pixels.size() * sizeof(float)) == 0);

  Result<std::vector<uint8_t>> png = encode_png_srgb8(*img);
  FUZZ_CHECK(png.is_ok());
  ImageLimits roomy;  // the encoder's output is at most a little larger than the pixels
  Result<ImageF> again = decode_image(*png, roomy, "image");
  FUZZ_CHECK(again.is_ok());
  FUZZ_CHECK(again->width == img->width && again->height == img->height && again->channels == 3);
  return 0;
}
