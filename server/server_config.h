// Configuration of `solidtex serve`: a plain struct whose fields say meaning, unit, range and
// default; validate() names the offending flag.
#pragma once

#include <cstdint>
#include <string>

#include "core/image_io.h"
#include "mesh/mesh.h"
#include "core/status.h"
#include "storage.h"

namespace solidtex::server {

struct ServerConfig {
  std::string host = "127.0.0.1";
  int port = 8080;                  // [1, 65535]
  std::string data_dir = "solidtex-data";
  // --storage s3://bucket[/prefix]: keep data in an S3-compatible store instead of data_dir
  // (storage.h, s3_storage.h); --s3-endpoint: its http(s)://host[:port]. Both or neither.
  std::string storage;
  std::string s3_endpoint;
  int threads = 2;                  // synthesis workers, [1, 256]
  int io_threads = 2;               // HTTP I/O threads, [1, 64]; they never synthesize
  int queue = 16;                   // synthesis requests waiting beyond the running ones, [0, 10000]; then 503
  double deadline_s = 30;           // default per-request deadline, seconds, (0, max_deadline_s]
  double max_deadline_s = 300;      // largest deadline a request may ask for, seconds, (0, 3600]
  int64_t cache_bytes = int64_t(256) << 20;       // voxel cache over all volumes, [0, 1 TiB]
  int64_t max_upload_bytes = int64_t(64) << 20;   // request body, bytes; beyond: 413
  ImageLimits image_limits;         // side and pixel count, checked from the header: 422
  int64_t max_voxels = int64_t(1) << 22;          // target voxels (output samples) per request: 422
  // Working memory of one synthesis request (dependency sets and level stores), bytes,
  // [16 MiB, 1 TiB]; estimated before any work and checked again after dependency analysis: 422.
  int64_t max_request_bytes = int64_t(1536) << 20;
  // Loaded volumes' state outside the voxel cache (tables, fields, surface bands, synthesizers),
  // bytes, [0, 1 TiB]: beyond it least-recently-used idle volumes are evicted (0: every volume is
  // evicted when its last request ends). One volume larger than this alone is still served.
  int64_t volume_state_bytes = int64_t(512) << 20;
  // A loaded volume no request used for this long is evicted, seconds, [0, 1e6]; 0: never.
  double idle_evict_s = 300;
  int64_t max_field_nodes = int64_t(1) << 18;     // frame-field grid nodes per field: 422 beyond
  MeshLimits mesh_limits;           // vertex and face counts per mesh: 422 beyond
  int max_jobs = 4;                 // analysis jobs queued or running, [1, 1000]; beyond: 429
  int analysis_threads = 1;         // analyses run at once, [1, 16]
  // An analysis job's lease (exemplars/<id>/lease, exemplar_service.h), seconds, [0.5, 3600]:
  // renewed every third of it while this replica has the job queued or running; another
  // replica on the same data directory takes an unfinished job over once it has expired.
  double job_lease_s = 30;
  // Side of the chunked-array views (/zarr, /zarr2) in finest voxels from the origin, a
  // multiple of 32 in [32, 2^20]: the window on the unbounded volume those clients see.
  int64_t array_extent = 1024;
  // Encoded array chunks kept for repeated reads (chunk_cache.h), bytes, [0, 64 GiB]; 0: none.
  int64_t chunk_cache_bytes = int64_t(64) << 20;
  // Directory of the browser app (web/: index.html at /, its other files at /web/{file});
  // empty: no app (404). `solidtex serve` defaults to the source tree's web/ (static_files.h).
  std::string web_root;

  Status validate() const;
  StorageConfig storage_config() const { return {data_dir, storage, s3_endpoint}; }
};

}  // namespace solidtex::server
