#include "core/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

namespace solidtex {
namespace {

namespace OIIO = OIIO_NAMESPACE;

// Name with the right extension so OIIO picks the plugin; the bytes come from memory.
const char* sniff_format(std::span<const uint8_t> b) {
  auto starts = [&](std::initializer_list<uint8_t> sig) {
    return b.size() >= sig.size() && std::equal(sig.begin(), sig.end(), b.begin());
  };
  if (starts({0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A})) return "memory.png";
  if (starts({0xFF, 0xD8, 0xFF})) return "memory.jpg";
  if (starts({'I', 'I', 0x2A, 0x00}) || starts({'M', 'M', 0x00, 0x2A})) return "memory.tif";
  if (starts({0x76, 0x2F, 0x31, 0x01})) return "memory.exr";
  return nullptr;
}

}  // namespace

Result<std::vector<uint8_t>> read_file_bytes(const std::string& path, int64_t max_bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return Status(StatusCode::kNotFound, "cannot open '" + path + "'");
  const std::streamoff size = in.tellg();
  if (size < 0) return Status(StatusCode::kIo, "cannot read '" + path + "'");
  if (size > max_bytes)
    return Status(StatusCode::kTooLarge, "'" + path + "' is " + std::to_string(size) +
                                             " bytes; the limit is " + std::to_string(max_bytes));
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size))
    return Status(StatusCode::kIo, "short read from '" + path + "'");
  return bytes;
}

Result<ImageF> decode_image(std::span<const uint8_t> bytes, const ImageLimits& limits,
                            const std::string& what) {
  if (bytes.empty()) return Status(StatusCode::kInvalidArgument, "is empty (0 bytes)", what);
  if (int64_t(bytes.size()) > limits.max_bytes)
    return Status(StatusCode::kTooLarge,
                  "is " + std::to_string(bytes.size()) + " bytes; the limit is " +
                      std::to_string(limits.max_bytes),
                  what);
  const char* name = sniff_format(bytes);
  if (!name)
    return Status(StatusCode::kUnsupported,
                  "is not a PNG, JPEG, TIFF or OpenEXR image (unrecognised signature)", what);

  OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
  auto in = OIIO::ImageInput::open(name, nullptr, &reader);
  if (!in) {
    std::string err = OIIO::geterror();
    return Status(StatusCode::kCorrupt, "cannot decode header: " + (err.empty() ? "unknown error" : err), what);
  }
  const OIIO::ImageSpec spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1)
    return Status(StatusCode::kCorrupt, "header has an invalid size " + std::to_string(spec.width) +
                                            "x" + std::to_string(spec.height), what);
  if (spec.width > limits.max_side || spec.height > limits.max_side ||
      int64_t(spec.width) * spec.height > limits.max_pixels)
    return Status(StatusCode::kTooLarge,
                  "is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                      " pixels; limits are " + std::to_string(limits.max_side) + " per side and " +
                      std::to_string(limits.max_pixels) + " in all",
                  what);
  const int nc = spec.nchannels;
  if (nc < 1 || nc > 4)
    return Status(StatusCode::kUnsupported, "has " + std::to_string(nc) + " channels; 1-4 are supported", what);

  std::vector<float> raw(size_t(spec.width) * spec.height * nc);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, raw.data())) {
    std::string err = in->geterror();
    return Status(StatusCode::kCorrupt, "pixel data cannot be decoded: " + (err.empty() ? "unknown error" : err), what);
  }
  // libjpeg reports a truncated stream only as a warning; OIIO then still succeeds.
  if (in->has_error()) {
    return Status(StatusCode::kCorrupt, "pixel data is damaged: " + in->geterror(), what);
  }
  in->close();

  const bool is_float = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                        spec.format.basetype == OIIO::TypeDesc::HALF ||
                        spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  const std::string cs = spec.get_string_attribute("oiio:ColorSpace");
  const bool linear = is_float || cs == "Linear" || cs == "linear";

  ImageF out(spec.width, spec.height, 3);
  const size_t n = size_t(spec.width) * spec.height;
  for (size_t i = 0; i < n; ++i) {
    const float* src = &raw[i * nc];
    float rgb[3];
    if (nc <= 2) {
      rgb[0] = rgb[1] = rgb[2] = src[0];
    } else {
      rgb[0] = src[0]; rgb[1] = src[1]; rgb[2] = src[2];
    }
    for (int c = 0; c < 3; ++c) {
      float v = rgb[c];
      if (!std::isfinite(v))
        return Status(StatusCode::kCorrupt, "contains a non-finite pixel value", what);
      out.pixels[i * 3 + c] = linear ? v : srgb_to_linear(std::clamp(v, 0.f, 1.f));
    }
  }
  return out;
}

Result<ImageF> load_image(const std::string& path, const ImageLimits& limits, const std::string& what) {
  auto bytes = read_file_bytes(path, limits.max_bytes);
  if (!bytes) return Status(bytes.status().code(), bytes.status().message(), what);
  auto img = decode_image(*bytes, limits, what);
  if (!img) return img.status().with_context("'" + path + "'");
  return img;
}

namespace {

// Encodes 1- or 3-channel [0,1] pixels as PNG of the given integer type, in memory.
Result<std::vector<uint8_t>> encode_png(const ImageF& image, OIIO::TypeDesc type, bool srgb) {
  if (image.empty() || (image.channels != 1 && image.channels != 3))
    return Status(StatusCode::kInvalidArgument, "PNG encoding needs a non-empty 1- or 3-channel image");
  std::vector<float> px(image.pixels.size());
  for (size_t i = 0; i < px.size(); ++i) {
    float v = std::clamp(image.pixels[i], 0.f, 1.f);
    px[i] = srgb ? linear_to_srgb(v) : v;
  }
  std::vector<unsigned char> out;
  OIIO::Filesystem::IOVecOutput writer(out);
  OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
  spec.attribute("oiio:ColorSpace", srgb ? "sRGB" : "Linear");
  auto o = OIIO::ImageOutput::create("out.png", &writer);
  if (!o) return Status(StatusCode::kInternal, "no PNG writer: " + OIIO::geterror());
  if (!o->open("out.png", spec) || !o->write_image(OIIO::TypeDesc::FLOAT, px.data()) || !o->close())
    return Status(StatusCode::kInternal, "PNG encoding failed: " + o->geterror());
  return std::vector<uint8_t>(out.begin(), out.end());
}

Status write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) return Status(StatusCode::kIo, "cannot create '" + path + "'", "output");
  f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  if (!f.flush()) return Status(StatusCode::kIo, "cannot write '" + path + "'", "output");
  return Status::ok();
}

}  // namespace

std::vector<uint8_t> to_srgb8(const ImageF& rgb_linear) {
  std::vector<uint8_t> out(rgb_linear.pixels.size());
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = uint8_t(std::lround(linear_to_srgb(std::clamp(rgb_linear.pixels[i], 0.f, 1.f)) * 255.f));
  return out;
}

Result<std::vector<uint8_t>> encode_png_srgb8(const ImageF& rgb_linear) {
  if (rgb_linear.channels != 3 || rgb_linear.empty())
    return Status(StatusCode::kInvalidArgument, "expected a non-empty 3-channel linear RGB image");
  // Quantised by to_srgb8, so a PNG and a raw sRGB8 answer hold the same bytes.
  const std::vector<uint8_t> px = to_srgb8(rgb_linear);
  std::vector<unsigned char> out;
  OIIO::Filesystem::IOVecOutput writer(out);
  OIIO::ImageSpec spec(rgb_linear.width, rgb_linear.height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  auto o = OIIO::ImageOutput::create("out.png", &writer);
  if (!o) return Status(StatusCode::kInternal, "no PNG writer: " + OIIO::geterror());
  if (!o->open("out.png", spec) || !o->write_image(OIIO::TypeDesc::UINT8, px.data()) || !o->close())
    return Status(StatusCode::kInternal, "PNG encoding failed: " + o->geterror());
  return std::vector<uint8_t>(out.begin(), out.end());
}

Status save_png_srgb8(const std::string& path, const ImageF& rgb_linear) {
  SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, encode_png_srgb8(rgb_linear));
  return write_bytes(path, bytes);
}

Status save_png16(const std::string& path, const ImageF& image, bool srgb) {
  SOLIDTEX_ASSIGN_OR_RETURN(auto bytes, encode_png(image, OIIO::TypeDesc::UINT16, srgb));
  return write_bytes(path, bytes);
}

}  // namespace solidtex
