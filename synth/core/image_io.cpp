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

// The OIIO plugin (by its format extension) for the signature the bytes start with.
const char* sniff_format(std::span<const uint8_t> b) {
  auto starts = [&](std::initializer_list<uint8_t> sig) {
    return b.size() >= sig.size() && std::equal(sig.begin(), sig.end(), b.begin());
  };
  if (starts({0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A})) return "png";
  if (starts({0xFF, 0xD8, 0xFF})) return "jpg";
  if (starts({'I', 'I', 0x2A, 0x00}) || starts({'M', 'M', 0x00, 0x2A})) return "tif";
  if (starts({0x76, 0x2F, 0x31, 0x01})) return "exr";
  return nullptr;
}

// OIIO 2.4.7's IOMemReader::pread tests `size + size_t(offset) > buffer size`, which wraps for
// a negative offset of at most `size` bytes: it then copies from before the buffer. OpenEXR
// Core reads chunks at offsets taken from the file (a chunk table entry of -8 read the 8 bytes
// before it). Reads here never leave the bytes; outside them they read nothing.
class BoundedMemReader final : public OIIO::Filesystem::IOMemReader {
 public:
  using IOMemReader::IOMemReader;
  size_t read(void* buf, size_t size) override {
    size = pread(buf, size, m_pos);
    m_pos += int64_t(size);
    return size;
  }
  size_t pread(void* buf, size_t size, int64_t offset) override {
    const int64_t end = int64_t(m_buf.size());  // OIIO's span has a signed size
    if (offset < 0 || offset >= end || size == 0) return 0;
    size = std::min(size, size_t(end - offset));
    std::memcpy(buf, m_buf.data() + offset, size);
    return size;
  }
};

// A PNG's chunks (length, type, data, CRC) must all lie within the bytes, up to IEND. libpng
// would otherwise read past the end, and OIIO 2.4's read callback then leaks its error message
// (png_error longjmps past the string's destructor): one leak per truncated upload.
Status check_png_chunks(std::span<const uint8_t> b, const std::string& what) {
  size_t pos = 8;
  while (true) {
    if (b.size() - pos < 12)
      return Status(StatusCode::kCorrupt, "is a truncated PNG (ends before its IEND chunk)", what);
    const uint32_t len = uint32_t(b[pos]) << 24 | uint32_t(b[pos + 1]) << 16 | uint32_t(b[pos + 2]) << 8 | b[pos + 3];
    if (len > 0x7fffffffu)
      return Status(StatusCode::kCorrupt, "is not a valid PNG (chunk length " + std::to_string(len) + ")", what);
    if (b.size() - pos - 12 < len)
      return Status(StatusCode::kCorrupt, "is a truncated PNG (a chunk ends after the data)", what);
    const bool end = std::memcmp(&b[pos + 4], "IEND", 4) == 0;
    pos += 12 + size_t(len);
    if (end) return Status::ok();
  }
}

Status too_large(int64_t w, int64_t h, const ImageLimits& limits, const std::string& what) {
  return Status(StatusCode::kTooLarge,
                "is " + std::to_string(w) + "x" + std::to_string(h) + " pixels; limits are " +
                    std::to_string(limits.max_side) + " per side and " + std::to_string(limits.max_pixels) + " in all",
                what);
}

// An OpenEXR header's attributes (name\0 type\0 i32 size, value) must lie within the bytes:
// the Core library allocates each attribute's declared size before reading it (up to 2 GB
// for a file of a few bytes). Multi-part files hold several headers, ended by an empty one.
// Each part's data window is checked against the limits here too: opening a file allocates
// its chunk table, whose size follows the window's height.
Status check_exr_headers(std::span<const uint8_t> b, const ImageLimits& limits, const std::string& what) {
  auto bad = [&](const std::string& m) { return Status(StatusCode::kCorrupt, "is not a valid OpenEXR file (" + m + ")", what); };
  if (b.size() < 8) return bad("no version field");
  const bool multipart = (b[5] & 0x10) != 0;  // version flags, bit 12
  auto le32 = [&](size_t at) {
    return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24;
  };
  size_t pos = 8;
  // The next \0-terminated string from `pos`, or false when the bytes end first.
  auto skip_string = [&]() {
    const auto end = std::find(b.begin() + long(pos), b.end(), uint8_t(0));
    if (end == b.end()) return false;
    pos = size_t(end - b.begin()) + 1;
    return true;
  };
  for (int header = 0;; ++header) {
    if (pos >= b.size()) return bad("the header ends early");
    if (b[pos] == 0) {
      if (header == 0) return bad("the header has no attributes");
      return Status::ok();  // the empty header that ends a multi-part file's headers
    }
    while (b[pos] != 0) {
      const size_t name = pos;
      if (!skip_string()) return bad("the header ends early");
      const size_t type = pos;
      if (!skip_string() || b.size() - pos < 4) return bad("the header ends early");
      const uint32_t size = le32(pos);
      pos += 4;
      if (size > b.size() - pos)
        return bad("attribute '" + std::string(reinterpret_cast<const char*>(&b[name]),
                                               strnlen(reinterpret_cast<const char*>(&b[name]), 32)) +
                   "' claims " + std::to_string(size) +
                   " bytes, " + std::to_string(b.size() - pos) + " are left");
      auto is = [&](size_t at, const char* text) { return std::strcmp(reinterpret_cast<const char*>(&b[at]), text) == 0; };
      if (is(name, "dataWindow") && is(type, "box2i") && size == 16) {
        // xmin, ymin, xmax, ymax
        const int64_t x0 = int32_t(le32(pos)), y0 = int32_t(le32(pos + 4));
        const int64_t w = int64_t(int32_t(le32(pos + 8))) - x0 + 1, h = int64_t(int32_t(le32(pos + 12))) - y0 + 1;
        if (w < 1 || h < 1) return bad("empty data window");
        if (w > limits.max_side || h > limits.max_side || w * h > limits.max_pixels) return too_large(w, h, limits, what);
      }
      pos += size;
      if (pos >= b.size()) return bad("the header ends early");
    }
    ++pos;  // the header's closing \0
    if (!multipart) return Status::ok();
  }
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
  const char* format = sniff_format(bytes);
  if (!format)
    return Status(StatusCode::kUnsupported,
                  "is not a PNG, JPEG, TIFF or OpenEXR image (unrecognised signature)", what);
  if (std::strcmp(format, "png") == 0) SOLIDTEX_RETURN_IF_ERROR(check_png_chunks(bytes, what));
  if (std::strcmp(format, "exr") == 0) SOLIDTEX_RETURN_IF_ERROR(check_exr_headers(bytes, limits, what));

  // The sniffed format's reader only. ImageInput::open("x.png") would, when the PNG reader
  // fails, offer the bytes to every other plugin OIIO has (DICOM, FITS, ...; those without
  // IOProxy support would open "x.png" in the working directory). Created from the bare
  // format name, the reader is returned unopened, without that probing.
  // OpenEXR's classic reader (3.1) accepts a zip chunk that inflates to fewer bytes than its
  // scanlines need and hands out the rest of its buffer, uninitialised heap memory, as pixels;
  // the Core library's reader refuses such chunks. (A process-wide OIIO setting, reads only.)
  static const bool exr_core = OIIO::attribute("openexr:core", 1);
  (void)exr_core;
  BoundedMemReader reader(bytes.data(), bytes.size());
  auto in = OIIO::ImageInput::create(format);
  if (!in || !in->set_ioproxy(&reader)) {
    std::string err = OIIO::geterror();
    return Status(StatusCode::kInternal, std::string("no ") + format + " reader: " + (err.empty() ? "unknown error" : err),
                  what);
  }
  OIIO::ImageSpec spec;
  if (!in->open(std::string("memory.") + format, spec)) {
    std::string err = in->geterror();
    if (err.empty()) err = OIIO::geterror();
    return Status(StatusCode::kCorrupt, "cannot decode header: " + (err.empty() ? "unknown error" : err), what);
  }
  if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1)
    return Status(StatusCode::kCorrupt, "header has an invalid size " + std::to_string(spec.width) +
                                            "x" + std::to_string(spec.height), what);
  if (spec.width > limits.max_side || spec.height > limits.max_side ||
      int64_t(spec.width) * spec.height > limits.max_pixels)
    return too_large(spec.width, spec.height, limits, what);
  const int nc = spec.nchannels;
  if (nc < 1 || nc > 4)
    return Status(StatusCode::kUnsupported, "has " + std::to_string(nc) + " channels; 1-4 are supported", what);

  const size_t n = size_t(spec.width) * spec.height;
  std::vector<float> raw(n * nc);
  // The pixels in the file's own types into a buffer of the image's size, then converted to
  // float here (by the functions OIIO converts with). Asked for floats, OIIO 2.4's
  // read_scanlines converts through a 64 MB scratch buffer on every call, whatever the size.
  const size_t pixel_bytes = spec.pixel_bytes(true);
  std::vector<unsigned char> native(n * pixel_bytes);
  bool read = in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UNKNOWN, native.data());
  if (spec.channelformats.empty()) {
    const size_t value_bytes = spec.format.size();
    for (size_t at = 0, step = size_t(1) << 24; read && at < raw.size(); at += step) {
      const size_t count = std::min(step, raw.size() - at);
      read = OIIO::convert_pixel_values(spec.format, native.data() + at * value_bytes, OIIO::TypeDesc::FLOAT,
                                        raw.data() + at, int(count));
    }
  } else {  // per-channel types (OpenEXR): one channel at a time, with strides
    size_t offset = 0;
    const OIIO::stride_t out_x = OIIO::stride_t(nc * sizeof(float));
    for (int c = 0; read && c < nc; ++c) {
      const OIIO::TypeDesc type = spec.channelformats[size_t(c)];
      read = OIIO::convert_image(1, spec.width, spec.height, 1, native.data() + offset, type, OIIO::stride_t(pixel_bytes),
                                 OIIO::stride_t(pixel_bytes) * spec.width, OIIO::AutoStride, raw.data() + c,
                                 OIIO::TypeDesc::FLOAT, out_x, out_x * spec.width, OIIO::AutoStride);
      offset += type.size();
    }
  }
  if (!read) {
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
