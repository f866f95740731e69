#include "metrics.h"

#include <sstream>

namespace solidtex::server {

const std::vector<double>& Metrics::buckets() {
  static const std::vector<double> b{0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60};
  return b;
}

void Metrics::observe(const std::string& route, const std::string& method, int status, double seconds) {
  std::lock_guard<std::mutex> g(mutex_);
  ++requests_[{route, method, status}];
  Histogram& h = latency_[route];
  if (h.counts.empty()) h.counts.assign(buckets().size(), 0);
  for (size_t i = 0; i < buckets().size(); ++i)
    if (seconds <= buckets()[i]) {
      ++h.counts[i];
      break;
    }
  ++h.count;
  h.sum += seconds;
}

std::string Metrics::render(const MetricGauges& g) const {
  std::ostringstream o;
  o << "# HELP solidtex_requests_total HTTP requests by route template, method and status.\n"
       "# TYPE solidtex_requests_total counter\n";
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [key, n] : requests_) {
    const auto& [route, method, status] = key;
    o << "solidtex_requests_total{route=\"" << route << "\",method=\"" << method << "\",status=\"" << status << "\"} "
      << n << "\n";
  }
  o << "# HELP solidtex_request_seconds Request latency by route template.\n"
       "# TYPE solidtex_request_seconds histogram\n";
  for (const auto& [route, h] : latency_) {
    int64_t cumulative = 0;
    for (size_t i = 0; i < buckets().size(); ++i) {
      cumulative += h.counts[i];
      o << "solidtex_request_seconds_bucket{route=\"" << route << "\",le=\"" << buckets()[i] << "\"} " << cumulative
        << "\n";
    }
    o << "solidtex_request_seconds_bucket{route=\"" << route << "\",le=\"+Inf\"} " << h.count << "\n";
    o << "solidtex_request_seconds_sum{route=\"" << route << "\"} " << h.sum << "\n";
    o << "solidtex_request_seconds_count{route=\"" << route << "\"} " << h.count << "\n";
  }
  o << "# HELP solidtex_queue_depth Synthesis requests waiting for a worker.\n# TYPE solidtex_queue_depth gauge\n"
    << "solidtex_queue_depth " << g.queue_depth << "\n"
    << "# HELP solidtex_queue_capacity Waiting requests allowed before 503.\n# TYPE solidtex_queue_capacity gauge\n"
    << "solidtex_queue_capacity " << g.queue_capacity << "\n"
    << "# HELP solidtex_workers_busy Workers running a request.\n# TYPE solidtex_workers_busy gauge\n"
    << "solidtex_workers_busy " << g.workers_busy << "\n"
    << "# HELP solidtex_cache_bytes Voxel cache bytes over all volumes.\n# TYPE solidtex_cache_bytes gauge\n"
    << "solidtex_cache_bytes " << g.cache_bytes << "\n"
    << "# HELP solidtex_cache_budget_bytes Voxel cache budget over all volumes (--cache-mb).\n"
       "# TYPE solidtex_cache_budget_bytes gauge\n"
    << "solidtex_cache_budget_bytes " << g.cache_budget_bytes << "\n"
    << "# HELP solidtex_volume_state_bytes Loaded volumes' state outside the voxel cache (tables, fields, surface bands, "
       "synthesizers; a shared table counts once).\n# TYPE solidtex_volume_state_bytes gauge\n"
    << "solidtex_volume_state_bytes " << g.volume_state_bytes << "\n"
    << "# HELP solidtex_volume_state_budget_bytes Bound of solidtex_volume_state_bytes (--volume-state-mb).\n"
       "# TYPE solidtex_volume_state_budget_bytes gauge\n"
    << "solidtex_volume_state_budget_bytes " << g.volume_state_budget_bytes << "\n"
    << "# HELP solidtex_volumes_loaded Volumes whose state is loaded.\n# TYPE solidtex_volumes_loaded gauge\n"
    << "solidtex_volumes_loaded " << g.volumes_loaded << "\n"
    << "# HELP solidtex_volume_state_loads_total Volume states built (first queries and rebuilds after eviction).\n"
       "# TYPE solidtex_volume_state_loads_total counter\n"
    << "solidtex_volume_state_loads_total " << g.volume_state_loads << "\n"
    << "# HELP solidtex_volume_evictions_total Loaded volume states evicted, by reason (budget: --volume-state-mb, "
       "idle: --idle-evict-s).\n# TYPE solidtex_volume_evictions_total counter\n"
    << "solidtex_volume_evictions_total{reason=\"budget\"} " << g.volume_evictions_budget << "\n"
    << "solidtex_volume_evictions_total{reason=\"idle\"} " << g.volume_evictions_idle << "\n"
    << "# HELP solidtex_voxels_synthesized_total Voxels synthesized (all levels) since start.\n"
       "# TYPE solidtex_voxels_synthesized_total counter\n"
    << "solidtex_voxels_synthesized_total " << g.voxels_synthesized << "\n"
    << "# HELP solidtex_analysis_jobs Exemplar analyses queued or running.\n# TYPE solidtex_analysis_jobs gauge\n"
    << "solidtex_analysis_jobs " << g.analysis_jobs << "\n";
  return o.str();
}

}  // namespace solidtex::server
