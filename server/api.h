// The handlers of the HTTP API (proto/openapi.json): each decodes an HttpRequest, calls a
// service, and encodes the HttpResponse. No HTTP library here, no business logic either.
// Heavy handlers (synthesis, analysis uploads, field solves) are run on the worker pool by the
// adapter (routes.h says which); they derive an interrupter from the request's deadline
// (query `timeout`, default --deadline) and disconnection, and answer 504 past the deadline.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "chunk_cache.h"
#include "chunked_arrays.h"
#include "exemplar_service.h"
#include "field_service.h"
#include "http_types.h"
#include "mesh_service.h"
#include "metrics.h"
#include "query_params.h"
#include "server_config.h"
#include "static_files.h"
#include "volume_service.h"
#include "worker_pool.h"

namespace solidtex::server {

class Api {
 public:
  Api(const ServerConfig& config, ExemplarService& exemplars, FieldService& fields, VolumeService& volumes,
      MeshService& meshes, Metrics& metrics, const WorkerPool& pool, const std::atomic<bool>& stopping,
      const std::atomic<bool>& shutting_down);

  // The browser app: GET / (index.html) and GET /web/{file} (static_files.h).
  HttpResponse web_index(const HttpRequest& r);
  HttpResponse web_file(const HttpRequest& r);
  HttpResponse healthz(const HttpRequest& r);
  HttpResponse metrics(const HttpRequest& r);
  HttpResponse openapi(const HttpRequest& r);
  HttpResponse list_exemplars(const HttpRequest& r);
  HttpResponse upload_exemplar(const HttpRequest& r);
  HttpResponse get_exemplar(const HttpRequest& r);
  HttpResponse delete_exemplar(const HttpRequest& r);
  HttpResponse get_exemplar_table(const HttpRequest& r);
  HttpResponse get_job(const HttpRequest& r);
  HttpResponse list_fields(const HttpRequest& r);
  HttpResponse create_field(const HttpRequest& r);
  HttpResponse get_field(const HttpRequest& r);
  HttpResponse delete_field(const HttpRequest& r);
  HttpResponse get_field_file(const HttpRequest& r);
  HttpResponse add_curve(const HttpRequest& r);
  HttpResponse remove_last_curve(const HttpRequest& r);
  HttpResponse sample_frames(const HttpRequest& r);
  HttpResponse list_volumes(const HttpRequest& r);
  HttpResponse create_volume(const HttpRequest& r);
  HttpResponse get_volume(const HttpRequest& r);
  HttpResponse delete_volume(const HttpRequest& r);
  HttpResponse slice(const HttpRequest& r);
  HttpResponse cut(const HttpRequest& r);
  HttpResponse region(const HttpRequest& r);
  HttpResponse points(const HttpRequest& r);
  HttpResponse volume_stats(const HttpRequest& r);
  HttpResponse list_meshes(const HttpRequest& r);
  HttpResponse upload_mesh(const HttpRequest& r);
  HttpResponse get_mesh(const HttpRequest& r);
  HttpResponse delete_mesh(const HttpRequest& r);
  HttpResponse get_mesh_file(const HttpRequest& r);
  HttpResponse surface(const HttpRequest& r);
  HttpResponse field_from_mesh(const HttpRequest& r);
  // Chunked-array views (api_arrays.cpp, chunked_arrays.h).
  HttpResponse zarr_group(const HttpRequest& r);
  HttpResponse zarr_array(const HttpRequest& r);
  HttpResponse zarr_chunk(const HttpRequest& r);
  HttpResponse zarr2_group(const HttpRequest& r);
  HttpResponse zarr2_attributes(const HttpRequest& r);
  HttpResponse zarr2_array(const HttpRequest& r);
  HttpResponse zarr2_chunk(const HttpRequest& r);
  HttpResponse precomputed_info(const HttpRequest& r);
  HttpResponse precomputed_chunk(const HttpRequest& r);
  HttpResponse precomputed_jpeg_info(const HttpRequest& r);
  HttpResponse precomputed_jpeg_chunk(const HttpRequest& r);

 private:
  Result<std::unique_ptr<RequestInterrupter>> interrupter_for(const HttpRequest& r, const std::optional<std::string>& timeout) const;
  // Runs `work(interrupter)` under the request's deadline and disconnect flag; a cancelled
  // result becomes 504 (deadline) or "cancelled" (client gone, shutdown), naming `what`.
  template <typename F>
  auto interruptible(const HttpRequest& r, const std::optional<std::string>& timeout, const std::string& what, F&& work)
      -> decltype(work(std::declval<Interrupter&>()));
  // A volume query (kind: slice, cut, region, points, surface, chunk) under the request's
  // deadline; `level` as in VolumeService::query.
  Result<QueryResult> query_volume(const HttpRequest& r, const std::string& kind, const TargetSet& target,
                                   const std::optional<std::string>& timeout, int level = -1);
  struct ArrayView {
    ArrayWindow window;
    std::string tag;  // VolumeService::ArrayInfo::tag
  };
  Result<ArrayView> array_view(const HttpRequest& r);
  Result<int> dataset_of(const HttpRequest& r, const ArrayView& view);
  enum class ChunkEncoding { kZstd, kRaw, kJpeg };
  HttpResponse array_chunk(const HttpRequest& r, const std::string& format);  // the same bytes in every format
  HttpResponse precomputed_chunk_as(const HttpRequest& r, const std::string& format, ChunkEncoding encoding);
  Result<HttpResponse> serve_box(const HttpRequest& r, const ArrayView& view, int scale, const ChunkBox& box,
                                 const std::string& format, const std::string& key, ChunkEncoding encoding);
  HttpResponse static_file(const HttpRequest& r, const std::string& name);
  // The `scale` query parameter of slice and cut (dataset s of the pyramid, as /zarr's): the
  // synthesis level to pass to query_volume (-1 for scale 0, the finest); 404 past the coarsest.
  Result<int> level_of_scale(const HttpRequest& r, const QueryParams& q);
  // What `resample` auto (nullopt) stands for in volume r.param("id"): its preferred sampling;
  // a given sampling is returned as is, without loading the volume.
  Result<VoxelSampling> auto_sampling(const HttpRequest& r, const std::optional<VoxelSampling>& requested);
  HttpResponse array_metadata(const HttpRequest& r, const std::function<Result<nlohmann::json>(const ArrayView&)>& make);
  // Adds a content ETag and `Cache-Control: immutable` to a synthesized answer (200 only).
  static void mark_immutable(HttpResponse& out);
  Result<HttpResponse> synthesize_image(const HttpRequest& r, const std::string& kind, const TargetSet& target,
                                        const std::optional<std::string>& timeout, int level = -1);

  const ServerConfig& config_;
  ExemplarService& exemplars_;
  FieldService& fields_;
  VolumeService& volumes_;
  MeshService& meshes_;
  Metrics& metrics_;
  const WorkerPool& pool_;
  ChunkCache chunks_;  // encoded array chunks by ETag (--chunk-cache-mb)
  StaticFiles web_;    // --web-root
  const std::atomic<bool>& stopping_;       // shutdown has begun: new work is refused, /healthz says 503
  const std::atomic<bool>& shutting_down_;  // the grace period is over: running requests are interrupted
};

}  // namespace solidtex::server
