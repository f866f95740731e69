// solidtex serve [--host 127.0.0.1] [--port 8080] [--data DIR] [--threads N] [--io-threads N]
//   [--queue N] [--deadline S] [--max-deadline S] [--cache-mb M] [--max-upload-mb M]
//   [--max-image-side PX] [--max-image-pixels N] [--max-voxels N] [--max-field-nodes N]
//   [--max-jobs N] [--analysis-threads N] [--max-mesh-vertices N] [--max-mesh-faces N] [--max-request-mb M]
//   [--volume-state-mb M] [--idle-evict-s S] [--array-extent VOXELS] [--chunk-cache-mb M] [--web-root DIR]
//   [--job-lease-seconds S] [--storage s3://bucket/prefix --s3-endpoint URL]
// --storage keeps the data in an S3-compatible object store instead of --data DIR; credentials
// come from AWS_ACCESS_KEY_ID, AWS_SECRET_ACCESS_KEY, AWS_REGION (default us-east-1) and
// AWS_SESSION_TOKEN (README, "Storage backends").
#include "args.h"
#include "commands.h"
#include "http_server.h"
#include "static_files.h"

namespace solidtex::cli {

Status run_serve(const std::vector<std::string>& argv) {
  Args args({"--host", "--port", "--data", "--threads", "--io-threads", "--queue", "--deadline", "--max-deadline",
             "--cache-mb", "--max-upload-mb", "--max-image-side", "--max-image-pixels", "--max-voxels",
             "--max-field-nodes", "--max-jobs", "--analysis-threads", "--max-mesh-vertices", "--max-mesh-faces",
             "--max-request-mb", "--volume-state-mb", "--idle-evict-s", "--array-extent", "--chunk-cache-mb",
             "--web-root", "--job-lease-seconds", "--storage", "--s3-endpoint"},
            {});
  SOLIDTEX_RETURN_IF_ERROR(args.parse(argv));
  if (!args.positionals().empty())
    return Status(StatusCode::kInvalidArgument, "takes no positional arguments", args.positionals()[0]);
  server::ServerConfig c;
  c.host = args.get("--host").value_or(c.host);
  SOLIDTEX_ASSIGN_OR_RETURN(c.port, args.get_int("--port", c.port, 1, 65535));
  c.data_dir = args.get("--data").value_or(c.data_dir);
  c.storage = args.get("--storage").value_or(c.storage);
  c.s3_endpoint = args.get("--s3-endpoint").value_or(c.s3_endpoint);
  if (args.get("--storage") && args.get("--data"))
    return Status(StatusCode::kInvalidArgument, "--data and --storage name two different stores: give one", "--storage");
  SOLIDTEX_ASSIGN_OR_RETURN(c.threads, args.get_int("--threads", c.threads, 1, 256));
  SOLIDTEX_ASSIGN_OR_RETURN(c.io_threads, args.get_int("--io-threads", c.io_threads, 1, 64));
  SOLIDTEX_ASSIGN_OR_RETURN(c.queue, args.get_int("--queue", c.queue, 0, 10000));
  SOLIDTEX_ASSIGN_OR_RETURN(c.max_deadline_s, args.get_double("--max-deadline", c.max_deadline_s, 0.001, 3600));
  SOLIDTEX_ASSIGN_OR_RETURN(c.deadline_s, args.get_double("--deadline", c.deadline_s, 0.001, c.max_deadline_s));
  SOLIDTEX_ASSIGN_OR_RETURN(int cache_mb, args.get_int("--cache-mb", int(c.cache_bytes >> 20), 0, 1 << 20));
  c.cache_bytes = int64_t(cache_mb) << 20;
  SOLIDTEX_ASSIGN_OR_RETURN(int upload_mb, args.get_int("--max-upload-mb", int(c.max_upload_bytes >> 20), 1, 4096));
  c.max_upload_bytes = int64_t(upload_mb) << 20;
  c.image_limits.max_bytes = c.max_upload_bytes;
  SOLIDTEX_ASSIGN_OR_RETURN(c.image_limits.max_side, args.get_int("--max-image-side", c.image_limits.max_side, 8, 65536));
  SOLIDTEX_ASSIGN_OR_RETURN(double pixels, args.get_double("--max-image-pixels", double(c.image_limits.max_pixels), 64, 4294967296.0));
  c.image_limits.max_pixels = int64_t(pixels);
  SOLIDTEX_ASSIGN_OR_RETURN(double voxels, args.get_double("--max-voxels", double(c.max_voxels), 1, double(int64_t(1) << 24)));
  c.max_voxels = int64_t(voxels);
  SOLIDTEX_ASSIGN_OR_RETURN(c.array_extent, args.get_int("--array-extent", int(c.array_extent), 32, 1 << 20));
  SOLIDTEX_ASSIGN_OR_RETURN(int chunk_mb, args.get_int("--chunk-cache-mb", int(c.chunk_cache_bytes >> 20), 0, 65536));
  c.chunk_cache_bytes = int64_t(chunk_mb) << 20;
  // The browser app: the source tree's web/ unless named (validate() checks it holds index.html).
  c.web_root = args.get("--web-root").value_or(server::default_web_root());
  if (args.get("--web-root") && c.web_root.empty())
    return Status(StatusCode::kInvalidArgument, "must name a directory", "--web-root");
  SOLIDTEX_ASSIGN_OR_RETURN(int request_mb, args.get_int("--max-request-mb", int(c.max_request_bytes >> 20), 16, 1 << 20));
  c.max_request_bytes = int64_t(request_mb) << 20;
  SOLIDTEX_ASSIGN_OR_RETURN(int state_mb, args.get_int("--volume-state-mb", int(c.volume_state_bytes >> 20), 0, 1 << 20));
  c.volume_state_bytes = int64_t(state_mb) << 20;
  SOLIDTEX_ASSIGN_OR_RETURN(c.idle_evict_s, args.get_double("--idle-evict-s", c.idle_evict_s, 0, 1e6));
  SOLIDTEX_ASSIGN_OR_RETURN(double nodes, args.get_double("--max-field-nodes", double(c.max_field_nodes), 8, double(int64_t(1) << 24)));
  c.max_field_nodes = int64_t(nodes);
  SOLIDTEX_ASSIGN_OR_RETURN(double mesh_vertices, args.get_double("--max-mesh-vertices", double(c.mesh_limits.max_vertices), 3, 1e8));
  c.mesh_limits.max_vertices = int64_t(mesh_vertices);
  SOLIDTEX_ASSIGN_OR_RETURN(double mesh_faces, args.get_double("--max-mesh-faces", double(c.mesh_limits.max_faces), 1, 2e8));
  c.mesh_limits.max_faces = int64_t(mesh_faces);
  SOLIDTEX_ASSIGN_OR_RETURN(c.max_jobs, args.get_int("--max-jobs", c.max_jobs, 1, 1000));
  SOLIDTEX_ASSIGN_OR_RETURN(c.analysis_threads, args.get_int("--analysis-threads", c.analysis_threads, 1, 16));
  SOLIDTEX_ASSIGN_OR_RETURN(c.job_lease_s, args.get_double("--job-lease-seconds", c.job_lease_s, 0.5, 3600));
  return server::run_server(c);
}

}  // namespace solidtex::cli
