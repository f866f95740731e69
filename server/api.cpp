#include "api.h"

#include <climits>
#include <cstring>
#include <map>
#include <mutex>

#include "http_errors.h"
#include "core/image_io.h"
#include "api_json.h"
#include "array_etag.h"
#include "conditional_get.h"
#include "core/json_fields.h"
#include "openapi_document.h"
#include "query_params.h"
#include "synthesis/target.h"
#include "vdb_export.h"

namespace solidtex::server {

using nlohmann::json;

HttpResponse HttpResponse::json(int status, const nlohmann::json& j) {
  HttpResponse r;
  r.status = status;
  // Never throws on bytes a client sent that are not UTF-8 (echoed ids, names): replaced.
  r.body = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return r;
}

HttpResponse HttpResponse::error(const Status& s) {
  HttpResponse r;
  r.status = http_status_for(s.code());
  r.body = error_body(s);
  if (const char* seconds = retry_after_for(s.code())) r.headers.push_back({"Retry-After", seconds});
  return r;
}

namespace {

enum class Encoding { kPng, kVdb, kRgb8, kFloat32, kJson };

// Raw answers are asked for with Accept: application/octet-stream[; dtype=float32].
Encoding negotiate(const std::string& accept, Encoding fallback) {
  if (accept.find("application/octet-stream") != std::string::npos)
    return accept.find("dtype=float32") != std::string::npos ? Encoding::kFloat32 : Encoding::kRgb8;
  if (accept.find("application/json") != std::string::npos && fallback == Encoding::kFloat32) return Encoding::kJson;
  return fallback;
}

Status require_json_body(const HttpRequest& r) {
  if (!r.content_type.empty() && r.content_type != "application/json")
    return Status(StatusCode::kUnsupported, "expected Content-Type application/json, got " + r.content_type, "Content-Type");
  return Status::ok();
}

std::string floats_to_bytes(const std::vector<std::array<float, 3>>& rgb) {
  std::string out(rgb.size() * 12, '\0');
  for (size_t i = 0; i < rgb.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const uint32_t u = std::bit_cast<uint32_t>(rgb[i][size_t(c)]);
      for (int b = 0; b < 4; ++b) out[i * 12 + size_t(c) * 4 + size_t(b)] = char((u >> (8 * b)) & 0xff);
    }
  return out;
}

// Encodes colors laid out as `shape` (outermost first, last = 3) in the negotiated form.
Result<HttpResponse> encode_colors(const std::vector<std::array<float, 3>>& rgb, int width, int height,
                                    const std::string& shape, Encoding enc) {
  HttpResponse out;
  switch (enc) {
    case Encoding::kPng: {
      SOLIDTEX_ASSIGN_OR_RETURN(auto png, encode_png_srgb8(rgb_image(rgb, width, height)));
      out.content_type = "image/png";
      out.body.assign(png.begin(), png.end());
      return out;
    }
    case Encoding::kRgb8: {
      const std::vector<uint8_t> px = to_srgb8(rgb_image(rgb, width, height));
      out.content_type = "application/octet-stream";
      out.body.assign(px.begin(), px.end());
      out.headers.push_back({"X-Dtype", "uint8"});
      out.headers.push_back({"X-Shape", shape});
      return out;
    }
    case Encoding::kFloat32:
      out.content_type = "application/octet-stream";
      out.body = floats_to_bytes(rgb);
      out.headers.push_back({"X-Dtype", "float32"});
      out.headers.push_back({"X-Shape", shape});
      return out;
    case Encoding::kJson: {
      json a = json::array();
      for (const auto& c : rgb) a.push_back({c[0], c[1], c[2]});
      out.body = json{{"rgb", a}}.dump();
      return out;
    }
    case Encoding::kVdb: break;
  }
  return Status(StatusCode::kInternal, "unexpected encoding");
}

template <typename F>
HttpResponse respond(int ok_status, F&& f) {
  auto r = f();
  if (!r) return HttpResponse::error(r.status());
  return HttpResponse::json(ok_status, *r);
}

HttpResponse respond_status(const Status& s) {
  if (!s.is_ok()) return HttpResponse::error(s);
  HttpResponse r;
  r.status = 204;
  r.content_type.clear();
  return r;
}

HttpResponse respond_bytes(Result<std::vector<uint8_t>> bytes) {
  if (!bytes) return HttpResponse::error(bytes.status());
  HttpResponse r;
  r.content_type = "application/octet-stream";
  r.body.assign(bytes->begin(), bytes->end());
  return r;
}

Status no_query(const HttpRequest& r) { return QueryParams::parse(r.query, {}).status(); }

// The contract's ranges (proto/openapi.py): coordinates within +-2^28 voxels; a slice or
// region side at most 2^24 (the ceiling of --max-voxels, so larger sides could never be
// answered) with an origin that keeps origin + size within 2^28; a cut side at most 2^20.
constexpr int64_t kMaxCoordinate = int64_t(1) << 28;
constexpr int64_t kMaxSide = kMaxTargetSamples;
constexpr int64_t kMaxOrigin = kMaxCoordinate - kMaxSide;
constexpr int64_t kMaxCutSide = int64_t(1) << 20;

// The product of positive sides, saturated instead of wrapping (2^24 cubed overflows int64).
int64_t sample_count(const std::vector<int>& sides) {
  int64_t n = 1;
  for (int s : sides) n = n > INT64_MAX / s ? INT64_MAX : n * s;
  return n;
}

Status check_each(const std::vector<int>& values, int64_t lo, int64_t hi, const std::string& field) {
  for (int v : values)
    if (v < lo || v > hi)
      return Status(StatusCode::kInvalidArgument, "each must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", field);
  return Status::ok();
}

// Plane weights: each in [0, 1], at least one of them at least 1e-6 (not all zero).
Status check_plane_weights(const std::vector<double>& w, const std::string& field) {
  bool any = false;
  for (double x : w) {
    if (!(x >= 0 && x <= 1)) return Status(StatusCode::kInvalidArgument, "each must be in [0, 1]", field);
    any = any || x >= 1e-6;
  }
  if (!any) return Status(StatusCode::kInvalidArgument, "must not all be zero (one at least 1e-6)", field);
  return Status::ok();
}

}  // namespace

Api::Api(const ServerConfig& config, ExemplarService& exemplars, FieldService& fields, VolumeService& volumes,
         MeshService& meshes, Metrics& metrics, const WorkerPool& pool, const std::atomic<bool>& stopping,
         const std::atomic<bool>& shutting_down)
    : config_(config), exemplars_(exemplars), fields_(fields), volumes_(volumes), meshes_(meshes), metrics_(metrics), pool_(pool),
      chunks_(config.chunk_cache_bytes), web_(config.web_root), stopping_(stopping), shutting_down_(shutting_down) {}

Result<std::unique_ptr<RequestInterrupter>> Api::interrupter_for(const HttpRequest& r, const std::optional<std::string>& timeout) const {
  double seconds = config_.deadline_s;
  if (timeout) {  // present, even empty (`?timeout=` is not a number: 400)
    QueryParams q;
    SOLIDTEX_ASSIGN_OR_RETURN(q, QueryParams::parse({{"timeout", *timeout}}, {"timeout"}));
    SOLIDTEX_ASSIGN_OR_RETURN(seconds, q.get_double("timeout", config_.deadline_s, 0, config_.max_deadline_s));
    if (!(seconds > 0))
      return Status(StatusCode::kInvalidArgument, "must be in (0, " + std::to_string(config_.max_deadline_s) + "] (--max-deadline)",
                    "timeout");
  }
  const auto deadline = r.arrival + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  return std::make_unique<RequestInterrupter>(deadline, r.disconnected, &shutting_down_);
}

template <typename F>
auto Api::interruptible(const HttpRequest& r, const std::optional<std::string>& timeout, const std::string& what, F&& work)
    -> decltype(work(std::declval<Interrupter&>())) {
  auto made = interrupter_for(r, timeout);
  if (!made) return made.status();
  RequestInterrupter& interrupter = **made;
  if (interrupter.was_interrupted()) return interrupter.interruption_status(what);
  auto result = work(interrupter);
  if (!result && result.status().code() == StatusCode::kCancelled) return interrupter.interruption_status(what);
  return result;
}

Result<QueryResult> Api::query_volume(const HttpRequest& r, const std::string& kind, const TargetSet& target,
                                      const std::optional<std::string>& timeout, int level) {
  return interruptible(r, timeout, "the " + kind,
                       [&](Interrupter& i) { return volumes_.query(r.param("id"), kind, target, i, level); });
}

HttpResponse Api::static_file(const HttpRequest& r, const std::string& name) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_RETURN_IF_ERROR(no_query(r));
    SOLIDTEX_ASSIGN_OR_RETURN(StaticFile f, web_.read(name));
    HttpResponse out;
    out.content_type = f.content_type;
    out.body = std::move(f.body);
    out.headers.push_back({"ETag", f.etag});
    // Revalidated at every load (a 304 when unchanged), so an edited app is never stale.
    out.headers.push_back({"Cache-Control", "no-cache"});
    return conditional_get(r, std::move(out));
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::web_index(const HttpRequest& r) { return static_file(r, "index.html"); }

HttpResponse Api::web_file(const HttpRequest& r) { return static_file(r, r.param("file")); }

HttpResponse Api::healthz(const HttpRequest& r) {
  if (Status s = no_query(r); !s.is_ok()) return HttpResponse::error(s);
  // 503 while stopping, so balancers and Kubernetes take the replica out before it goes.
  const bool stopping = stopping_.load();
  return HttpResponse::json(stopping ? 503 : 200, {{"status", stopping ? "stopping" : "ok"},
                                  {"queue_depth", pool_.queued()},
                                  {"workers_busy", pool_.running()}});
}

HttpResponse Api::metrics(const HttpRequest&) {
  MetricGauges g;
  g.queue_depth = pool_.queued();
  g.workers_busy = pool_.running();
  g.queue_capacity = pool_.capacity();
  g.cache_bytes = volumes_.cache_bytes();
  g.cache_budget_bytes = config_.cache_bytes;
  g.voxels_synthesized = volumes_.voxels_synthesized();
  const VolumeStateTotals state = volumes_.state_totals();
  g.volume_state_bytes = state.bytes;
  g.volume_state_budget_bytes = state.budget_bytes;
  g.volumes_loaded = state.loaded;
  g.volume_state_loads = state.loads;
  g.volume_evictions_budget = state.evicted_budget;
  g.volume_evictions_idle = state.evicted_idle;
  g.analysis_jobs = exemplars_.jobs_pending();
  HttpResponse out;
  out.content_type = "text/plain; version=0.0.4";
  out.body = metrics_.render(g);
  return out;
}

namespace {

// The contract as this server serves it: proto/openapi.json, whose `timeout` parameters say
// the default --max-deadline (300 s), with this server's --max-deadline instead when it differs
// (so that a client or fuzzer reading the document never asks for a deadline it would refuse).
std::string served_openapi(double max_deadline_s) {
  constexpr double kDocumentedMaxDeadline = 300;
  if (max_deadline_s == kDocumentedMaxDeadline) return openapi_document();
  static std::mutex mutex;
  static std::map<double, std::string> served;
  std::lock_guard<std::mutex> g(mutex);
  auto it = served.find(max_deadline_s);
  if (it != served.end()) return it->second;
  json doc = json::parse(openapi_document());
  for (auto& [path, ops] : doc["paths"].items())
    for (auto& [method, op] : ops.items())
      if (op.is_object() && op.contains("parameters"))
        for (auto& p : op["parameters"])
          if (p.value("name", "") == "timeout" && p.value("in", "") == "query") p["schema"]["maximum"] = max_deadline_s;
  return served.emplace(max_deadline_s, doc.dump(1)).first->second;
}

}  // namespace

HttpResponse Api::openapi(const HttpRequest&) {
  HttpResponse out;
  out.body = served_openapi(config_.max_deadline_s);
  return out;
}

HttpResponse Api::list_exemplars(const HttpRequest& r) {
  if (Status s = no_query(r); !s.is_ok()) return HttpResponse::error(s);
  return HttpResponse::json(200, exemplars_.list());
}

HttpResponse Api::upload_exemplar(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"name", "levels", "neighborhood", "candidates",
                                                                          "pca_dims", "seed", "plane_weights", "grain",
                                                                          "mask_weight"}));
    ExemplarUpload up;
    up.name = q.get("name").value_or("");
    if (utf8_length(up.name) > 200) return Status(StatusCode::kInvalidArgument, "is longer than 200 characters", "name");
    // auto (the default) is kAutoLevels, resolved from the exemplar's size before analysis.
    if (const auto v = q.get("levels"); v && *v != "auto") {
      Result<int64_t> n = q.get_int("levels", up.params.levels, 1, 8);
      if (!n) return Status(StatusCode::kInvalidArgument, "must be auto or an integer in [1, 8]", "levels");
      up.params.levels = int(*n);
    }
    SOLIDTEX_ASSIGN_OR_RETURN(up.params.neighborhood, q.get_int("neighborhood", up.params.neighborhood, 3, 15));
    SOLIDTEX_ASSIGN_OR_RETURN(up.params.candidates, q.get_int("candidates", up.params.candidates, 1, 32));
    SOLIDTEX_ASSIGN_OR_RETURN(up.params.pca_dims, q.get_int("pca_dims", up.params.pca_dims, 1, 64));
    SOLIDTEX_ASSIGN_OR_RETURN(auto seed, q.get_int("seed", 1, 0, 1 << 30));
    up.params.seed = uint32_t(seed);
    if (q.has("plane_weights")) {
      SOLIDTEX_ASSIGN_OR_RETURN(auto w, q.get_list("plane_weights", 3));
      SOLIDTEX_RETURN_IF_ERROR(check_plane_weights(w, "plane_weights"));
      up.params.suggested_plane_weights = {float(w[0]), float(w[1]), float(w[2])};
    }
    up.grain = q.get("grain").value_or("auto");
    SOLIDTEX_ASSIGN_OR_RETURN(double mw, q.get_double("mask_weight", 1.0, 0.0, 10.0));
    up.mask_weight = float(mw);
    if (r.multipart) {
      for (const auto& [name, bytes] : r.parts) {
        for (const auto& [seen, unused] : up.parts)
          if (seen == name || (seen == "xy" && name == "image") || (seen == "image" && name == "xy"))
            return Status(StatusCode::kInvalidArgument, "part given more than once", name);
        up.parts.emplace_back(name, std::vector<uint8_t>(bytes.begin(), bytes.end()));
      }
    } else {
      if (r.content_type == "application/json" || r.content_type == "application/x-www-form-urlencoded")
        return Status(StatusCode::kUnsupported,
                      "send the image bytes (e.g. application/octet-stream or image/png) or multipart/form-data",
                      "Content-Type");
      up.parts.emplace_back("xy", std::vector<uint8_t>(r.body.begin(), r.body.end()));
    }
    SOLIDTEX_ASSIGN_OR_RETURN(json created, exemplars_.upload(std::move(up)));
    HttpResponse out = HttpResponse::json(202, created);
    out.headers.push_back({"Location", "/v1/jobs/" + created["job"]["id"].get<std::string>()});
    return out;
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::get_exemplar(const HttpRequest& r) { return respond(200, [&] { return exemplars_.get(r.param("id")); }); }

HttpResponse Api::delete_exemplar(const HttpRequest& r) {
  return respond_status(exemplars_.remove(r.param("id"), [&](const std::string& id) { return volumes_.uses_exemplar(id); }));
}

HttpResponse Api::get_exemplar_table(const HttpRequest& r) { return respond_bytes(exemplars_.table_bytes(r.param("id"))); }

HttpResponse Api::get_job(const HttpRequest& r) { return respond(200, [&] { return exemplars_.job(r.param("id")); }); }

HttpResponse Api::list_fields(const HttpRequest& r) {
  if (Status s = no_query(r); !s.is_ok()) return HttpResponse::error(s);
  return HttpResponse::json(200, fields_.list());
}

HttpResponse Api::create_field(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"timeout"}));
    SOLIDTEX_RETURN_IF_ERROR(require_json_body(r));
    auto created = interruptible(r, q.get("timeout"), "the field solve",
                                 [&](Interrupter& i) { return fields_.create(normalized_body(r.body), i); });
    if (!created) return created.status();
    HttpResponse out = HttpResponse::json(201, *created);
    out.headers.push_back({"Location", "/v1/fields/" + (*created)["id"].get<std::string>()});
    return out;
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::get_field(const HttpRequest& r) { return respond(200, [&] { return fields_.get(r.param("id")); }); }

namespace {
// No `timeout` in the query: the server's --deadline (a named empty optional: GCC 12 warns
// falsely, -Wmaybe-uninitialized, about a temporary one).
const std::optional<std::string> kServerDeadline;
}  // namespace

HttpResponse Api::delete_field(const HttpRequest& r) {
  // A curve being added or removed finishes first; waiting for it is bounded by --deadline (504).
  auto removed = interruptible(r, kServerDeadline, "the delete (waiting for the field's running change)",
                               [&](Interrupter& i) -> Result<bool> {
                                 SOLIDTEX_RETURN_IF_ERROR(fields_.remove(r.param("id"), i));
                                 return true;
                               });
  return respond_status(removed ? Status::ok() : removed.status());
}

namespace {

// `revision=N` of the curve routes: the revision the client has seen (409 when the field has
// moved on); absent: whatever is current.
Result<std::optional<int>> expected_revision(const QueryParams& q) {
  if (!q.has("revision")) return std::optional<int>();
  SOLIDTEX_ASSIGN_OR_RETURN(const int64_t revision, q.get_int("revision", 0, 1, INT_MAX));
  return std::optional<int>(int(revision));
}

}  // namespace

HttpResponse Api::get_field_file(const HttpRequest& r) { return respond_bytes(fields_.file_bytes(r.param("id"))); }

HttpResponse Api::add_curve(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"revision", "timeout"}));
    SOLIDTEX_ASSIGN_OR_RETURN(const std::optional<int> revision, expected_revision(q));
    SOLIDTEX_RETURN_IF_ERROR(require_json_body(r));
    auto updated = interruptible(r, q.get("timeout"), "the field solve", [&](Interrupter& i) {
      return fields_.add_curve(r.param("id"), normalized_body(r.body), i, revision);
    });
    if (!updated) return updated.status();
    return HttpResponse::json(200, *updated);
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::remove_last_curve(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"revision", "timeout"}));
    SOLIDTEX_ASSIGN_OR_RETURN(const std::optional<int> revision, expected_revision(q));
    auto updated = interruptible(r, q.get("timeout"), "the field solve",
                                 [&](Interrupter& i) { return fields_.remove_last_curve(r.param("id"), i, revision); });
    if (!updated) return updated.status();
    return HttpResponse::json(200, *updated);
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::sample_frames(const HttpRequest& r) {
  return respond(200, [&]() -> Result<json> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"min", "size", "step"}));
    SOLIDTEX_ASSIGN_OR_RETURN(auto min, q.get_list("min", 3));
    SOLIDTEX_ASSIGN_OR_RETURN(auto size, q.get_int_list("size", 3));
    SOLIDTEX_ASSIGN_OR_RETURN(double step, q.get_double("step", 1.0, 0, 1e6));
    return fields_.sample_frames(r.param("id"), {min[0], min[1], min[2]}, {size[0], size[1], size[2]}, step);
  });
}

HttpResponse Api::list_volumes(const HttpRequest& r) {
  if (Status s = no_query(r); !s.is_ok()) return HttpResponse::error(s);
  return HttpResponse::json(200, volumes_.list());
}

HttpResponse Api::create_volume(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_RETURN_IF_ERROR(no_query(r));
    SOLIDTEX_RETURN_IF_ERROR(require_json_body(r));
    SOLIDTEX_ASSIGN_OR_RETURN(json created, volumes_.create(normalized_body(r.body)));
    HttpResponse out = HttpResponse::json(201, created);
    out.headers.push_back({"Location", "/v1/volumes/" + created["id"].get<std::string>()});
    return out;
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::get_volume(const HttpRequest& r) { return respond(200, [&] { return volumes_.get(r.param("id")); }); }

HttpResponse Api::delete_volume(const HttpRequest& r) { return respond_status(volumes_.remove(r.param("id"))); }

Result<int> Api::level_of_scale(const HttpRequest& r, const QueryParams& q) {
  SOLIDTEX_ASSIGN_OR_RETURN(const int64_t scale, q.get_int("scale", 0, 0, 7));
  if (scale == 0) return -1;
  SOLIDTEX_ASSIGN_OR_RETURN(const VolumeService::ArrayInfo info, volumes_.array_info(r.param("id")));
  if (scale >= info.levels)
    return Status(StatusCode::kNotFound,
                  "no dataset " + std::to_string(scale) + " (0.." + std::to_string(info.levels - 1) + ")", "scale");
  return info.levels - 1 - int(scale);
}

Result<HttpResponse> Api::synthesize_image(const HttpRequest& r, const std::string& kind, const TargetSet& target,
                                           const std::optional<std::string>& timeout, int level) {
  SOLIDTEX_ASSIGN_OR_RETURN(auto q, query_volume(r, kind, target, timeout, level));
  const std::string shape = std::to_string(target.height) + "," + std::to_string(target.width) + ",3";
  SOLIDTEX_ASSIGN_OR_RETURN(HttpResponse out,
                            encode_colors(q.rgb, target.width, target.height, shape, negotiate(r.accept, Encoding::kPng)));
  out.headers.push_back({"X-Voxels-Synthesized", std::to_string(q.voxels_synthesized)});
  mark_immutable(out);
  return out;
}

void Api::mark_immutable(HttpResponse& out) {
  // Voxels are a pure function of the volume, whose id is never reused, and the request: the
  // same request always gets these bytes, so any HTTP cache (nginx in deploy/) may keep them.
  out.headers.push_back({"ETag", "\"img-" + fnv1a_hex(out.body) + "\""});
  out.headers.push_back({"Cache-Control", "public, max-age=31536000, immutable"});
}

HttpResponse Api::slice(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"axis", "at", "origin", "size", "scale", "timeout"}));
    SOLIDTEX_ASSIGN_OR_RETURN(std::string axis, q.required("axis"));
    if (axis != "x" && axis != "y" && axis != "z") return Status(StatusCode::kInvalidArgument, "must be x, y or z", "axis");
    if (!q.has("at")) return Status(StatusCode::kInvalidArgument, "is required", "at");
    SOLIDTEX_ASSIGN_OR_RETURN(int64_t at, q.get_int("at", 0, -kMaxCoordinate, kMaxCoordinate));
    std::vector<int> origin{0, 0};
    if (q.has("origin")) {
      SOLIDTEX_ASSIGN_OR_RETURN(origin, q.get_int_list("origin", 2));
      SOLIDTEX_RETURN_IF_ERROR(check_each(origin, -kMaxCoordinate, kMaxOrigin, "origin"));
    }
    SOLIDTEX_ASSIGN_OR_RETURN(auto size, q.get_int_list("size", 2));
    SOLIDTEX_RETURN_IF_ERROR(check_each(size, 1, kMaxSide, "size"));
    SOLIDTEX_RETURN_IF_ERROR(volumes_.check_target_size(sample_count(size), "size"));
    SOLIDTEX_ASSIGN_OR_RETURN(const int level, level_of_scale(r, q));
    SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::axis_cut(axis[0], int(at), origin[0], origin[1], size[0], size[1]));
    SOLIDTEX_ASSIGN_OR_RETURN(HttpResponse out, synthesize_image(r, "slice", target, q.get("timeout"), level));
    return conditional_get(r, std::move(out));
  }();
  return result ? *result : HttpResponse::error(result.status());
}

Result<VoxelSampling> Api::auto_sampling(const HttpRequest& r, const std::optional<VoxelSampling>& requested) {
  if (requested) return *requested;  // auto only needs the volume's tables
  return volumes_.preferred_voxel_sampling(r.param("id"));
}

HttpResponse Api::cut(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"scale", "timeout"}));
    SOLIDTEX_RETURN_IF_ERROR(require_json_body(r));
    SOLIDTEX_ASSIGN_OR_RETURN(json j, parse_request_json(r.body, "body"));
    SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"origin", "u", "v", "size", "resample"}, ""));
    for (const char* k : {"origin", "u", "v", "size"})
      if (!j.contains(k)) return Status(StatusCode::kInvalidArgument, "is required", k);
    SOLIDTEX_ASSIGN_OR_RETURN(WorldPoint origin, json_point(j["origin"], "origin"));
    SOLIDTEX_ASSIGN_OR_RETURN(WorldPoint u, json_point(j["u"], "u"));
    SOLIDTEX_ASSIGN_OR_RETURN(WorldPoint v, json_point(j["v"], "v"));
    if (!j["size"].is_array() || j["size"].size() != 2)
      return Status(StatusCode::kInvalidArgument, "must be [W, H]", "size");
    SOLIDTEX_ASSIGN_OR_RETURN(int64_t w, json_int(j["size"][0], "size", 1, kMaxCutSide));
    SOLIDTEX_ASSIGN_OR_RETURN(int64_t h, json_int(j["size"][1], "size", 1, kMaxCutSide));
    SOLIDTEX_RETURN_IF_ERROR(volumes_.check_target_size(w * h, "size"));
    SOLIDTEX_ASSIGN_OR_RETURN(const int level, level_of_scale(r, q));
    std::optional<VoxelSampling> requested;  // auto
    if (j.contains("resample")) {  // a non-string is no name: parse_voxel_sampling's error
      const std::string name = j["resample"].is_string() ? j["resample"].get<std::string>() : std::string();
      SOLIDTEX_ASSIGN_OR_RETURN(requested, parse_voxel_sampling(name, "resample"));
    }
    SOLIDTEX_ASSIGN_OR_RETURN(const VoxelSampling preferred, auto_sampling(r, requested));
    SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::plane_cut(origin, u, v, int(w), int(h), requested, preferred));
    SOLIDTEX_ASSIGN_OR_RETURN(HttpResponse out, synthesize_image(r, "cut", target, q.get("timeout"), level));
    out.headers.push_back({"X-Resample", voxel_sampling_name(target.sampling())});
    return out;
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::region(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"min", "size", "timeout"}));
    SOLIDTEX_ASSIGN_OR_RETURN(auto min, q.get_int_list("min", 3));
    SOLIDTEX_RETURN_IF_ERROR(check_each(min, -kMaxCoordinate, kMaxOrigin, "min"));
    SOLIDTEX_ASSIGN_OR_RETURN(auto size, q.get_int_list("size", 3));
    SOLIDTEX_RETURN_IF_ERROR(check_each(size, 1, kMaxSide, "size"));
    // Saturated: W*H*D once wrapped int64 to a small number that passed the limit (500, bad_alloc).
    SOLIDTEX_RETURN_IF_ERROR(volumes_.check_target_size(sample_count(size), "size"));
    SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::box(Voxel{min[0], min[1], min[2]}, size[0], size[1], size[2]));
    auto qr = query_volume(r, "region", target, q.get("timeout"));
    if (!qr) return qr.status();
    const Encoding enc = negotiate(r.accept, Encoding::kVdb);
    HttpResponse out;
    if (enc == Encoding::kVdb) {
      SOLIDTEX_ASSIGN_OR_RETURN(out.body, encode_vdb_box(Voxel{min[0], min[1], min[2]}, {size[0], size[1], size[2]}, qr->rgb,
                                                         r.param("id")));
      out.content_type = "application/x-vdb";
    } else {
      const std::string shape = std::to_string(size[2]) + "," + std::to_string(size[1]) + "," + std::to_string(size[0]) + ",3";
      SOLIDTEX_ASSIGN_OR_RETURN(out, encode_colors(qr->rgb, size[0], size[1] * size[2], shape, enc));
    }
    out.headers.push_back({"X-Voxels-Synthesized", std::to_string(qr->voxels_synthesized)});
    mark_immutable(out);
    return conditional_get(r, std::move(out));
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::points(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"timeout", "resample"}));
    // Points sample their nearest voxels unless told: scattered points share no cubic taps, so
    // resampling could read 64 voxels for each (dense ones, such as a bake's texels, share them).
    std::optional<VoxelSampling> requested = VoxelSampling::kNearest;
    if (auto name = q.get("resample")) {
      SOLIDTEX_ASSIGN_OR_RETURN(requested, parse_voxel_sampling(*name, "resample"));
    }
    std::vector<WorldPoint> pts;
    if (r.content_type == "application/json") {
      SOLIDTEX_ASSIGN_OR_RETURN(json j, parse_request_json(r.body, "body"));
      SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"points"}, ""));
      if (!j.contains("points") || !j["points"].is_array())
        return Status(StatusCode::kInvalidArgument, "is required (an array of [x,y,z])", "points");
      SOLIDTEX_RETURN_IF_ERROR(volumes_.check_target_size(int64_t(j["points"].size()), "points"));
      for (size_t i = 0; i < j["points"].size(); ++i) {
        SOLIDTEX_ASSIGN_OR_RETURN(WorldPoint p, json_point(j["points"][i], "points[" + std::to_string(i) + "]"));
        pts.push_back(p);
      }
    } else if (r.content_type.empty() || r.content_type == "application/octet-stream") {
      if (r.body.size() % 12 != 0)
        return Status(StatusCode::kInvalidArgument,
                      "must be little-endian float32 x,y,z triples (" + std::to_string(r.body.size()) + " bytes is not a multiple of 12)",
                      "body");
      SOLIDTEX_RETURN_IF_ERROR(volumes_.check_target_size(int64_t(r.body.size() / 12), "points"));
      for (size_t i = 0; i < r.body.size() / 12; ++i) {
        float v[3];
        for (int c = 0; c < 3; ++c) {
          uint32_t u = 0;
          for (int b = 0; b < 4; ++b) u |= uint32_t(uint8_t(r.body[i * 12 + size_t(c) * 4 + size_t(b)])) << (8 * b);
          v[c] = std::bit_cast<float>(u);
          if (!std::isfinite(v[c]))
            return Status(StatusCode::kInvalidArgument, "point " + std::to_string(i) + " is not finite", "body");
        }
        pts.push_back({v[0], v[1], v[2]});
      }
    } else {
      return Status(StatusCode::kUnsupported, "expected application/octet-stream or application/json", "Content-Type");
    }
    if (pts.empty()) return Status(StatusCode::kInvalidArgument, "holds no points", "body");
    SOLIDTEX_ASSIGN_OR_RETURN(const VoxelSampling preferred, auto_sampling(r, requested));
    SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::points(pts, requested, preferred));
    auto qr = query_volume(r, "points", target, q.get("timeout"));
    if (!qr) return qr.status();
    const Encoding enc = r.accept.find("application/json") != std::string::npos ? Encoding::kJson : Encoding::kFloat32;
    SOLIDTEX_ASSIGN_OR_RETURN(HttpResponse out,
                              encode_colors(qr->rgb, int(pts.size()), 1, std::to_string(pts.size()) + ",3", enc));
    out.headers.push_back({"X-Voxels-Synthesized", std::to_string(qr->voxels_synthesized)});
    out.headers.push_back({"X-Resample", voxel_sampling_name(target.sampling())});
    mark_immutable(out);
    return conditional_get(r, std::move(out));
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::volume_stats(const HttpRequest& r) { return respond(200, [&] { return volumes_.stats(r.param("id")); }); }

HttpResponse Api::list_meshes(const HttpRequest& r) {
  if (Status s = no_query(r); !s.is_ok()) return HttpResponse::error(s);
  return HttpResponse::json(200, meshes_.list());
}

HttpResponse Api::upload_mesh(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"name"}));
    const std::string name = q.get("name").value_or("");
    if (utf8_length(name) > 200) return Status(StatusCode::kInvalidArgument, "is longer than 200 characters", "name");
    if (r.content_type == "application/json" || r.multipart)
      return Status(StatusCode::kUnsupported, "send the mesh file's bytes (OBJ, PLY or OFF)", "Content-Type");
    SOLIDTEX_ASSIGN_OR_RETURN(json created, meshes_.upload(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(r.body.data()), r.body.size()), name));
    HttpResponse out = HttpResponse::json(201, created);
    out.headers.push_back({"Location", "/v1/meshes/" + created["id"].get<std::string>()});
    return out;
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::get_mesh(const HttpRequest& r) { return respond(200, [&] { return meshes_.get(r.param("id")); }); }

HttpResponse Api::delete_mesh(const HttpRequest& r) { return respond_status(meshes_.remove(r.param("id"))); }

HttpResponse Api::get_mesh_file(const HttpRequest& r) {
  auto mesh = meshes_.mesh(r.param("id"));
  if (!mesh) return HttpResponse::error(Status(mesh.status().code(), mesh.status().message(), "id"));
  return respond_bytes(encode_ply(**mesh));
}

HttpResponse Api::surface(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    std::shared_ptr<const Mesh> mesh;
    Placement placement;
    std::string format = "ply";
    std::vector<std::array<double, 3>> extra;
    std::optional<std::string> timeout;
    if (r.multipart) return Status(StatusCode::kUnsupported, "send the mesh bytes or a JSON request", "Content-Type");
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"timeout", "resolution", "margin", "format"}));
    timeout = q.get("timeout");
    // With a mesh body these place the mesh and choose the answer; with a JSON body they are
    // defaults for what the body leaves out.
    format = q.get("format").value_or("ply");
    SOLIDTEX_ASSIGN_OR_RETURN(int64_t resolution, q.get_int("resolution", 512, 8, 4096));
    SOLIDTEX_ASSIGN_OR_RETURN(double margin, q.get_double("margin", 0.25, 0, 1));
    if (format != "ply" && format != "json") return Status(StatusCode::kInvalidArgument, "must be ply or json", "format");
    if (r.content_type == "application/json") {
      SOLIDTEX_ASSIGN_OR_RETURN(json j, parse_request_json(r.body, "body"));
      SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"mesh", "placement", "format", "points"}, ""));
      if (!j.contains("mesh")) return Status(StatusCode::kInvalidArgument, "is required", "mesh");
      SOLIDTEX_ASSIGN_OR_RETURN(std::string mesh_id, json_text(j["mesh"], "mesh", 64));
      SOLIDTEX_ASSIGN_OR_RETURN(mesh, meshes_.mesh(mesh_id));
      json pj = j.value("placement", json::object());
      if (pj.is_object() && !pj.contains("scale")) {
        if (!pj.contains("resolution") && q.has("resolution")) pj["resolution"] = resolution;
        if (!pj.contains("margin") && q.has("margin")) pj["margin"] = margin;
      }
      SOLIDTEX_ASSIGN_OR_RETURN(placement, placement_from_json(pj, "placement", mesh->bounds(), nullptr));
      if (j.contains("format")) { SOLIDTEX_ASSIGN_OR_RETURN(format, json_text(j["format"], "format")); }
      if (j.contains("points")) {
        if (!j["points"].is_array()) return Status(StatusCode::kInvalidArgument, "must be an array of [x,y,z]", "points");
        for (size_t i = 0; i < j["points"].size(); ++i) {
          SOLIDTEX_ASSIGN_OR_RETURN(WorldPoint p, json_point(j["points"][i], "points[" + std::to_string(i) + "]"));
          extra.push_back({p.x, p.y, p.z});
        }
      }
    } else {
      SOLIDTEX_ASSIGN_OR_RETURN(Mesh decoded, meshes_.decode(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(r.body.data()), r.body.size())));
      mesh = std::make_shared<const Mesh>(std::move(decoded));
      SOLIDTEX_ASSIGN_OR_RETURN(placement, fit_placement(mesh->bounds(), int(resolution), margin));
    }
    if (format != "ply" && format != "json") return Status(StatusCode::kInvalidArgument, "must be ply or json", "format");
    if (format == "ply" && !extra.empty()) return Status(StatusCode::kInvalidArgument, "extra points need format json", "points");
    const size_t nv = mesh->vertices.size();
    SOLIDTEX_RETURN_IF_ERROR(volumes_.check_target_size(int64_t(nv + extra.size()), "mesh"));
    std::vector<WorldPoint> world;
    world.reserve(nv + extra.size());
    for (const auto& v : mesh->vertices) world.push_back(placement.apply(v));
    for (const auto& p : extra) world.push_back(placement.apply(p));
    SOLIDTEX_ASSIGN_OR_RETURN(TargetSet target, TargetSet::points(world));
    auto qr = query_volume(r, "surface", target, timeout);
    if (!qr) return qr.status();
    const int64_t bounding = bounding_voxels(mesh->bounds(), placement);
    HttpResponse out;
    if (format == "ply") {
      ImageF img(int(nv), 1, 3);
      for (size_t i = 0; i < nv; ++i)
        for (int c = 0; c < 3; ++c) img.pixels[i * 3 + size_t(c)] = qr->rgb[i][size_t(c)];
      const std::vector<uint8_t> srgb = to_srgb8(img);
      const std::vector<uint8_t> ply = encode_ply(*mesh, &srgb);
      out.content_type = "application/x-ply";
      out.body.assign(ply.begin(), ply.end());
    } else {
      json colors = json::array(), point_colors = json::array();
      for (size_t i = 0; i < qr->rgb.size(); ++i)
        (i < nv ? colors : point_colors).push_back({qr->rgb[i][0], qr->rgb[i][1], qr->rgb[i][2]});
      json stats = qr->stats;
      stats["target_voxels"] = int64_t(target.voxels.size());
      stats["bounding_voxels"] = bounding;
      stats["voxels_synthesized"] = qr->voxels_synthesized;
      stats["fraction"] = bounding > 0 ? double(qr->voxels_synthesized) / double(bounding) : 0.0;
      out = HttpResponse::json(200, {{"vertices", int64_t(nv)},
                                     {"colors", colors},
                                     {"point_colors", point_colors},
                                     {"placement", {{"scale", placement.scale}, {"translate", placement.translate}}},
                                     {"stats", stats}});
    }
    out.headers.push_back({"X-Target-Voxels", std::to_string(target.voxels.size())});
    out.headers.push_back({"X-Bounding-Voxels", std::to_string(bounding)});
    out.headers.push_back({"X-Voxels-Synthesized", std::to_string(qr->voxels_synthesized)});
    mark_immutable(out);
    return conditional_get(r, std::move(out));
  }();
  return result ? *result : HttpResponse::error(result.status());
}

HttpResponse Api::field_from_mesh(const HttpRequest& r) {
  auto result = [&]() -> Result<HttpResponse> {
    SOLIDTEX_ASSIGN_OR_RETURN(QueryParams q, QueryParams::parse(r.query, {"timeout"}));
    SOLIDTEX_RETURN_IF_ERROR(require_json_body(r));
    SOLIDTEX_ASSIGN_OR_RETURN(json j, parse_request_json(r.body, "body"));
    SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"mesh", "kind", "placement", "shortest_side_cells", "max_constraints",
                                            "feature_angle_degrees", "curves"}, ""));
    for (const char* k : {"mesh", "kind"})
      if (!j.contains(k)) return Status(StatusCode::kInvalidArgument, "is required", k);
    SOLIDTEX_ASSIGN_OR_RETURN(std::string mesh_id, json_text(j["mesh"], "mesh", 64));
    SOLIDTEX_ASSIGN_OR_RETURN(std::string kind, json_text(j["kind"], "kind"));
    MeshFieldOptions o;
    if (kind == "curvature") o.kind = MeshFieldOptions::Kind::kCurvature;
    else if (kind == "features") o.kind = MeshFieldOptions::Kind::kFeatures;
    else return Status(StatusCode::kInvalidArgument, "must be curvature or features", "kind");
    SOLIDTEX_ASSIGN_OR_RETURN(auto mesh, meshes_.mesh(mesh_id));
    SOLIDTEX_ASSIGN_OR_RETURN(o.placement, placement_from_json(j.value("placement", json::object()), "placement", mesh->bounds(), &o.margin));
    if (j.contains("shortest_side_cells")) { SOLIDTEX_ASSIGN_OR_RETURN(o.shortest_side_cells, json_int(j["shortest_side_cells"], "shortest_side_cells", 2, 256)); }
    if (j.contains("max_constraints")) { SOLIDTEX_ASSIGN_OR_RETURN(o.max_constraints, json_int(j["max_constraints"], "max_constraints", 1, 20000)); }
    if (j.contains("feature_angle_degrees")) { SOLIDTEX_ASSIGN_OR_RETURN(o.feature_angle_degrees, json_number(j["feature_angle_degrees"], "feature_angle_degrees", 1, 179)); }
    if (j.contains("curves")) {
      if (!j["curves"].is_array()) return Status(StatusCode::kInvalidArgument, "must be an array of polylines", "curves");
      for (size_t i = 0; i < j["curves"].size(); ++i) {
        const json& c = j["curves"][i];
        const std::string where = "curves[" + std::to_string(i) + "]";
        if (!c.is_array()) return Status(StatusCode::kInvalidArgument, "must be an array of [x,y,z]", where);
        std::vector<std::array<double, 3>> line;
        for (size_t k = 0; k < c.size(); ++k) {
          SOLIDTEX_ASSIGN_OR_RETURN(WorldPoint p, json_point(c[k], where + "[" + std::to_string(k) + "]"));
          line.push_back({p.x, p.y, p.z});
        }
        o.curves.push_back(std::move(line));
      }
    }
    auto created = interruptible(r, q.get("timeout"), "the field solve",
                                 [&](Interrupter& i) { return fields_.create_from_mesh(*mesh, o, i); });
    if (!created) return created.status();
    HttpResponse out = HttpResponse::json(201, *created);
    out.headers.push_back({"Location", "/v1/fields/" + (*created)["id"].get<std::string>()});
    return out;
  }();
  return result ? *result : HttpResponse::error(result.status());
}

}  // namespace solidtex::server
