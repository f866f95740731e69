// decode_image (core/image_io.h): signature sniffing, the header checks against ImageLimits
// (before any pixel is decoded), then the pixel decode and conversion to linear RGB.
// What it accepts must honour the limits, be 3-channel and finite, and survive a PNG round
// trip (encode_png_srgb8, decode again: same size).
#include <OpenImageIO/imageio.h>

#include <cmath>

#include "core/image_io.h"
#include "fuzz_support.h"

using namespace solidtex;

// OpenImageIO 2.4's PNGInput::PngReadCallback builds an error message string and then
// png_error() longjmps past its destructor: every truncated PNG leaks it (a third-party leak,
// see the fuzzing report). Suppressed by that frame only; matching it needs the slow unwinder
// (libstdc++ and OIIO have no frame pointers), kept to a few frames for speed.
extern "C" const char* __asan_default_options() { return "fast_unwind_on_malloc=0:malloc_context_size=8"; }
extern "C" const char* __lsan_default_suppressions() { return "leak:OpenImageIO_v2_4::PNGInput::PngReadCallback\n"; }

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

  Result<std::vector<uint8_t>> png = encode_png_srgb8(*img);
  FUZZ_CHECK(png.is_ok());
  ImageLimits roomy;  // the encoder's output is at most a little larger than the pixels
  Result<ImageF> again = decode_image(*png, roomy, "image");
  FUZZ_CHECK(again.is_ok());
  FUZZ_CHECK(again->width == img->width && again->height == img->height && again->channels == 3);
  return 0;
}
