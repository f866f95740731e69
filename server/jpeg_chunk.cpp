#include "jpeg_chunk.h"

#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE
#include <cstdlib>

#include <jpeglib.h>

namespace solidtex::server {
namespace {

// libjpeg reports errors through error_exit, which must not return: jump back to the encoder
// instead of letting the default handler exit the process.
struct ErrorManager {
  jpeg_error_mgr pub;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void on_error(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

}  // namespace

Result<std::string> jpeg_chunk(const std::vector<uint8_t>& srgb_zyxc, int sx, int sy, int sz, int quality) {
  if (sx <= 0 || sy <= 0 || sz <= 0 || int64_t(sy) * sz > 65500 || sx > 65500 ||
      srgb_zyxc.size() != size_t(sx) * size_t(sy) * size_t(sz) * 3)
    return Status(StatusCode::kInvalidArgument, "a jpeg chunk needs x*y*z*3 bytes and sides up to 65500", "chunk");
  // Plain data only between setjmp and the end of the encoder (longjmp skips destructors).
  jpeg_compress_struct cinfo;
  ErrorManager err;
  unsigned char* out = nullptr;
  unsigned long out_size = 0;
  cinfo.err = jpeg_std_error(&err.pub);
  err.pub.error_exit = on_error;
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&cinfo);
    std::free(out);
    return Status(StatusCode::kInternal, std::string("libjpeg: ") + err.message);
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &out, &out_size);
  cinfo.image_width = JDIMENSION(sx);
  cinfo.image_height = JDIMENSION(sy * sz);
  cinfo.input_components = 3;
  cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  for (int c = 0; c < 3; ++c) cinfo.comp_info[c].h_samp_factor = cinfo.comp_info[c].v_samp_factor = 1;
  jpeg_start_compress(&cinfo, TRUE);
  const size_t row_bytes = size_t(sx) * 3;
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(srgb_zyxc.data() + size_t(cinfo.next_scanline) * row_bytes);
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  std::string bytes(reinterpret_cast<const char*>(out), out_size);
  std::free(out);
  return bytes;
}

}  // namespace solidtex::server
