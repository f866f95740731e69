#include "server_config.h"

#include <filesystem>
#include <system_error>

#include "synthesis/target.h"

namespace solidtex::server {
namespace {
Status out_of_range(const char* flag, const std::string& range) {
  return Status(StatusCode::kInvalidArgument, "must be in " + range, flag);
}
}  // namespace

Status ServerConfig::validate() const {
  if (host.empty()) return Status(StatusCode::kInvalidArgument, "must not be empty", "--host");
  if (port < 1 || port > 65535) return out_of_range("--port", "[1, 65535]");
  if (data_dir.empty()) return Status(StatusCode::kInvalidArgument, "must not be empty", "--data");
  if (!storage.empty() && storage.rfind("s3://", 0) != 0)
    return Status(StatusCode::kInvalidArgument, "must be s3://bucket[/prefix] (or leave it out and use --data DIR)", "--storage");
  if (!storage.empty() && s3_endpoint.empty())
    return Status(StatusCode::kInvalidArgument, "is required with --storage s3:// (e.g. http://127.0.0.1:7070)", "--s3-endpoint");
  if (storage.empty() && !s3_endpoint.empty())
    return Status(StatusCode::kInvalidArgument, "is only used with --storage s3://bucket/prefix", "--s3-endpoint");
  if (threads < 1 || threads > 256) return out_of_range("--threads", "[1, 256]");
  if (io_threads < 1 || io_threads > 64) return out_of_range("--io-threads", "[1, 64]");
  if (queue < 0 || queue > 10000) return out_of_range("--queue", "[0, 10000]");
  if (!(max_deadline_s > 0 && max_deadline_s <= 3600)) return out_of_range("--max-deadline", "(0, 3600]");
  if (!(deadline_s > 0 && deadline_s <= max_deadline_s)) return out_of_range("--deadline", "(0, --max-deadline]");
  if (cache_bytes < 0 || cache_bytes > (int64_t(1) << 40)) return out_of_range("--cache-mb", "[0, 1048576]");
  if (max_upload_bytes < 1024 || max_upload_bytes > (int64_t(4) << 30)) return out_of_range("--max-upload-mb", "[1, 4096] MiB");
  if (image_limits.max_side < 8 || image_limits.max_side > 65536) return out_of_range("--max-image-side", "[8, 65536]");
  if (image_limits.max_pixels < 64 || image_limits.max_pixels > (int64_t(1) << 32))
    return out_of_range("--max-image-pixels", "[64, 2^32]");
  if (max_voxels < 1 || max_voxels > kMaxTargetSamples) return out_of_range("--max-voxels", "[1, 2^24]");
  if (array_extent < 32 || array_extent > (int64_t(1) << 20) || array_extent % 32)
    return out_of_range("--array-extent", "[32, 1048576], a multiple of 32");
  if (chunk_cache_bytes < 0 || chunk_cache_bytes > (int64_t(64) << 30)) return out_of_range("--chunk-cache-mb", "[0, 65536]");
  if (max_request_bytes < (int64_t(16) << 20) || max_request_bytes > (int64_t(1) << 40))
    return out_of_range("--max-request-mb", "[16, 1048576]");
  if (volume_state_bytes < 0 || volume_state_bytes > (int64_t(1) << 40)) return out_of_range("--volume-state-mb", "[0, 1048576]");
  if (!(idle_evict_s >= 0 && idle_evict_s <= 1e6)) return out_of_range("--idle-evict-s", "[0, 1e6]");
  if (max_field_nodes < 8 || max_field_nodes > (int64_t(1) << 24)) return out_of_range("--max-field-nodes", "[8, 2^24]");
  if (max_jobs < 1 || max_jobs > 1000) return out_of_range("--max-jobs", "[1, 1000]");
  if (analysis_threads < 1 || analysis_threads > 16) return out_of_range("--analysis-threads", "[1, 16]");
  if (!(job_lease_s >= 0.5 && job_lease_s <= 3600)) return out_of_range("--job-lease-seconds", "[0.5, 3600]");
  if (!web_root.empty()) {
    // symlink_status, as serving does (static_files.h: O_NOFOLLOW): an index.html that is a
    // symbolic link would never be served, so it is refused here rather than answered 404 later.
    std::error_code ec;
    const auto index = std::filesystem::symlink_status(std::filesystem::path(web_root) / "index.html", ec);
    if (ec || !std::filesystem::is_regular_file(index))
      return Status(StatusCode::kInvalidArgument,
                    "must be a directory holding index.html as a regular file (not a symbolic link): " + web_root,
                    "--web-root");
  }
  return Status::ok();
}

}  // namespace solidtex::server
