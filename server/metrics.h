// Prometheus text-format metrics: request counts by route, method and status; latency
// histograms by route; plus gauges the caller samples at scrape time (queue depth, cache
// bytes, voxels synthesized, analysis jobs, loaded volumes' state and evictions). Thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

namespace solidtex::server {

struct MetricGauges {
  int queue_depth = 0;       // synthesis requests waiting for a worker
  int workers_busy = 0;
  int queue_capacity = 0;
  int64_t cache_bytes = 0;
  int64_t cache_budget_bytes = 0;  // --cache-mb
  int64_t voxels_synthesized = 0;  // counter: over all volumes since start
  int analysis_jobs = 0;           // queued or running
  // Loaded volumes' state outside the voxel cache (VolumeStateTotals).
  int64_t volume_state_bytes = 0;
  int64_t volume_state_budget_bytes = 0;
  int64_t volumes_loaded = 0;
  int64_t volume_state_loads = 0;       // counter
  int64_t volume_evictions_budget = 0;  // counter
  int64_t volume_evictions_idle = 0;    // counter
};

class Metrics {
 public:
  // `route` is the route template ("/v1/volumes/{id}/slice"), not the concrete path.
  void observe(const std::string& route, const std::string& method, int status, double seconds);
  std::string render(const MetricGauges& gauges) const;

 private:
  static const std::vector<double>& buckets();
  struct Histogram {
    std::vector<int64_t> counts;  // per bucket (not cumulative)
    int64_t count = 0;
    double sum = 0;
  };
  mutable std::mutex mutex_;
  std::map<std::tuple<std::string, std::string, int>, int64_t> requests_;
  std::map<std::string, Histogram> latency_;
};

}  // namespace solidtex::server
