// Handlers of the chunked-array views (chunked_arrays.h): decode the path, ask the volume
// service, encode. Every answer carries CORS headers (browser viewers read them cross-origin);
// metadata and chunks carry strong ETags (array_etag.h); chunks are immutable.
// Successful answers go through conditional_get (If-None-Match, Range); HEAD is the adapter's.
#include <charconv>

#include "api.h"
#include "array_etag.h"
#include "chunked_arrays.h"
#include "conditional_get.h"
#include "core/image_io.h"
#include "jpeg_chunk.h"
#include "query_params.h"
#include "synthesis/target.h"

namespace solidtex::server {
namespace {

using nlohmann::json;

void add_cors(HttpResponse& r) {
  r.headers.push_back({"Access-Control-Allow-Origin", "*"});
  r.headers.push_back({"Access-Control-Expose-Headers",
                       "ETag, Content-Length, Content-Range, Accept-Ranges, X-Voxels-Synthesized"});
}

HttpResponse array_error(const Status& s) {
  HttpResponse r = HttpResponse::error(s);
  add_cors(r);
  return r;
}

// A path segment that must be a non-negative index; anything else names no array element.
Result<int64_t> index_segment(const HttpRequest& r, const std::string& name) {
  const std::string& s = r.param(name);
  int64_t v = -1;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v < 0)
    return Status(StatusCode::kNotFound, "'" + s + "' is not an index of the array", name);
  return v;
}

}  // namespace

Result<Api::ArrayView> Api::array_view(const HttpRequest& r) {
  SOLIDTEX_RETURN_IF_ERROR(QueryParams::parse(r.query, {}).status());
  SOLIDTEX_ASSIGN_OR_RETURN(const VolumeService::ArrayInfo info, volumes_.array_info(r.param("id")));
  ArrayView view;
  view.window.scales = info.levels;
  view.window.extent = config_.array_extent;
  view.tag = info.tag;
  return view;
}

HttpResponse Api::array_metadata(const HttpRequest& r, const std::function<Result<json>(const ArrayView&)>& make) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(const ArrayView view, array_view(r));
    SOLIDTEX_ASSIGN_OR_RETURN(const json j, make(view));
    HttpResponse out = HttpResponse::json(200, j);
    // The window follows --array-extent, so metadata may change across restarts: revalidate.
    out.headers.push_back({"ETag", metadata_etag(view.tag, view.window.extent, r.path)});
    out.headers.push_back({"Cache-Control", "public, max-age=60"});
    add_cors(out);
    return conditional_get(r, std::move(out));
  }();
  return result ? *result : array_error(result.status());
}

Result<int> Api::dataset_of(const HttpRequest& r, const ArrayView& view) {
  SOLIDTEX_ASSIGN_OR_RETURN(const int64_t scale, index_segment(r, "scale"));
  if (scale >= view.window.scales)
    return Status(StatusCode::kNotFound,
                  "no dataset " + std::to_string(scale) + " (0.." + std::to_string(view.window.scales - 1) + ")", "scale");
  return int(scale);
}

HttpResponse Api::zarr_group(const HttpRequest& r) {
  return array_metadata(r, [&](const ArrayView& v) -> Result<json> { return ome_zarr_group(v.window, r.param("id")); });
}

HttpResponse Api::zarr_array(const HttpRequest& r) {
  return array_metadata(r, [&](const ArrayView& v) -> Result<json> {
    SOLIDTEX_ASSIGN_OR_RETURN(const int scale, dataset_of(r, v));
    return zarr3_array(v.window, scale);
  });
}

HttpResponse Api::zarr2_group(const HttpRequest& r) {
  return array_metadata(r, [](const ArrayView&) -> Result<json> { return server::zarr2_group(); });
}

HttpResponse Api::zarr2_attributes(const HttpRequest& r) {
  return array_metadata(r, [&](const ArrayView& v) -> Result<json> { return ome_zarr04_attributes(v.window, r.param("id")); });
}

HttpResponse Api::zarr2_array(const HttpRequest& r) {
  return array_metadata(r, [&](const ArrayView& v) -> Result<json> {
    SOLIDTEX_ASSIGN_OR_RETURN(const int scale, dataset_of(r, v));
    return server::zarr2_array(v.window, scale);
  });
}

HttpResponse Api::zarr_chunk(const HttpRequest& r) { return array_chunk(r, "zarr3"); }

HttpResponse Api::zarr2_chunk(const HttpRequest& r) { return array_chunk(r, "zarr2"); }

HttpResponse Api::array_chunk(const HttpRequest& r, const std::string& format) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(const ArrayView view, array_view(r));
    SOLIDTEX_ASSIGN_OR_RETURN(const int scale, dataset_of(r, view));
    SOLIDTEX_ASSIGN_OR_RETURN(const int64_t c, index_segment(r, "c"));
    if (c != 0) return Status(StatusCode::kNotFound, "the channel axis has one chunk (index 0)", "c");
    std::array<int64_t, 3> czyx{};
    const char* names[3] = {"cz", "cy", "cx"};
    for (int a = 0; a < 3; ++a) {
      SOLIDTEX_ASSIGN_OR_RETURN(czyx[size_t(a)], index_segment(r, names[a]));
    }
    SOLIDTEX_ASSIGN_OR_RETURN(const ChunkBox box, chunk_box(view.window, scale, czyx));
    const std::string key = std::to_string(czyx[0]) + "." + std::to_string(czyx[1]) + "." + std::to_string(czyx[2]);
    return serve_box(r, view, scale, box, format, key, ChunkEncoding::kZstd);
  }();
  return result ? *result : array_error(result.status());
}

HttpResponse Api::precomputed_info(const HttpRequest& r) {
  return array_metadata(r, [](const ArrayView& v) -> Result<json> { return server::precomputed_info(v.window, "raw"); });
}

HttpResponse Api::precomputed_chunk(const HttpRequest& r) { return precomputed_chunk_as(r, "precomputed", ChunkEncoding::kRaw); }

HttpResponse Api::precomputed_jpeg_info(const HttpRequest& r) {
  return array_metadata(r, [](const ArrayView& v) -> Result<json> { return server::precomputed_info(v.window, "jpeg"); });
}

HttpResponse Api::precomputed_jpeg_chunk(const HttpRequest& r) {
  return precomputed_chunk_as(r, "precomputed-jpeg", ChunkEncoding::kJpeg);
}

HttpResponse Api::precomputed_chunk_as(const HttpRequest& r, const std::string& format, ChunkEncoding encoding) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(const ArrayView view, array_view(r));
    SOLIDTEX_ASSIGN_OR_RETURN(const int scale, dataset_of(r, view));
    SOLIDTEX_ASSIGN_OR_RETURN(const ChunkBox box, precomputed_box(view.window, scale, r.param("chunk")));
    return serve_box(r, view, scale, box, format, r.param("chunk"), encoding);
  }();
  return result ? *result : array_error(result.status());
}

// The voxels of `box` at dataset `scale`: C-order (c, z, y, x) sRGB8 zstd-compressed or raw, or
// a jpeg of the z slices stacked (jpeg_chunk.h); from the chunk cache when an earlier request
// encoded them.
Result<HttpResponse> Api::serve_box(const HttpRequest& r, const ArrayView& view, int scale, const ChunkBox& box,
                                    const std::string& format, const std::string& key, ChunkEncoding encoding) {
  const std::string etag = chunk_etag(view.tag, format, scale, key);
  int64_t synthesized = 0;
  std::shared_ptr<const std::string> body = chunks_.find(etag);
  if (!body) {
    SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::box(box.min, box.size[0], box.size[1], box.size[2]));
    auto qr = query_volume(r, "chunk", target, std::nullopt, view.window.scales - 1 - scale);
    if (!qr) return qr.status();
    synthesized = qr->voxels_synthesized;
    const std::vector<uint8_t> srgb = to_srgb8(rgb_image(qr->rgb, box.size[0], box.size[1] * box.size[2]));
    std::string bytes;
    if (encoding == ChunkEncoding::kJpeg) {
      SOLIDTEX_ASSIGN_OR_RETURN(bytes, jpeg_chunk(srgb, box.size[0], box.size[1], box.size[2]));
    } else {
      bytes = chunk_bytes(srgb, int64_t(qr->rgb.size()));
      if (encoding == ChunkEncoding::kZstd) {
        SOLIDTEX_ASSIGN_OR_RETURN(bytes, zstd_compress(bytes));
      }
    }
    body = std::make_shared<const std::string>(std::move(bytes));
    chunks_.insert(etag, body);
  }
  HttpResponse out;
  out.content_type = encoding == ChunkEncoding::kJpeg ? "image/jpeg" : "application/octet-stream";
  out.body = *body;
  out.headers.push_back({"ETag", etag});
  out.headers.push_back({"Cache-Control", "public, max-age=31536000, immutable"});
  out.headers.push_back({"X-Voxels-Synthesized", std::to_string(synthesized)});
  add_cors(out);
  return conditional_get(r, std::move(out));
}

}  // namespace solidtex::server
