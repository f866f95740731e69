#include "routes.h"

#include <string_view>

namespace solidtex::server {

const std::vector<Route>& route_table() {
  using E = Execution;
  static const std::vector<Route> routes{
      // The browser app (static_files.h): inline, so that the page loads while workers synthesize.
      {"GET", "/", E::kInline, &Api::web_index},
      {"GET", "/web/{file}", E::kInline, &Api::web_file},
      {"GET", "/healthz", E::kInline, &Api::healthz},
      {"GET", "/metrics", E::kInline, &Api::metrics},
      {"GET", "/v1/openapi.json", E::kInline, &Api::openapi},
      {"GET", "/v1/exemplars", E::kInline, &Api::list_exemplars},
      {"POST", "/v1/exemplars", E::kWorker, &Api::upload_exemplar},
      {"GET", "/v1/exemplars/{id}", E::kInline, &Api::get_exemplar},
      {"DELETE", "/v1/exemplars/{id}", E::kWorker, &Api::delete_exemplar},
      {"GET", "/v1/exemplars/{id}/table", E::kWorker, &Api::get_exemplar_table},
      {"GET", "/v1/jobs/{id}", E::kInline, &Api::get_job},
      {"GET", "/v1/fields", E::kInline, &Api::list_fields},
      {"POST", "/v1/fields", E::kWorker, &Api::create_field},
      {"GET", "/v1/fields/{id}", E::kInline, &Api::get_field},
      {"DELETE", "/v1/fields/{id}", E::kWorker, &Api::delete_field},
      {"GET", "/v1/fields/{id}/file", E::kWorker, &Api::get_field_file},
      {"POST", "/v1/fields/{id}/curves", E::kWorker, &Api::add_curve},
      {"DELETE", "/v1/fields/{id}/curves/last", E::kWorker, &Api::remove_last_curve},
      {"GET", "/v1/fields/{id}/frames", E::kWorker, &Api::sample_frames},
      {"GET", "/v1/volumes", E::kInline, &Api::list_volumes},
      {"POST", "/v1/volumes", E::kWorker, &Api::create_volume},
      {"GET", "/v1/volumes/{id}", E::kInline, &Api::get_volume},
      {"DELETE", "/v1/volumes/{id}", E::kWorker, &Api::delete_volume},
      {"GET", "/v1/volumes/{id}/slice", E::kWorker, &Api::slice},
      {"POST", "/v1/volumes/{id}/cut", E::kWorker, &Api::cut},
      {"GET", "/v1/volumes/{id}/region", E::kWorker, &Api::region},
      {"POST", "/v1/volumes/{id}/points", E::kWorker, &Api::points},
      {"GET", "/v1/volumes/{id}/stats", E::kInline, &Api::volume_stats},
      {"GET", "/v1/meshes", E::kInline, &Api::list_meshes},
      {"POST", "/v1/meshes", E::kWorker, &Api::upload_mesh},
      {"GET", "/v1/meshes/{id}", E::kInline, &Api::get_mesh},
      {"DELETE", "/v1/meshes/{id}", E::kWorker, &Api::delete_mesh},
      {"GET", "/v1/meshes/{id}/file", E::kWorker, &Api::get_mesh_file},
      {"POST", "/v1/volumes/{id}/surface", E::kWorker, &Api::surface},
      {"POST", "/v1/fields/from-mesh", E::kWorker, &Api::field_from_mesh},
      {"GET", "/v1/volumes/{id}/zarr/zarr.json", E::kWorker, &Api::zarr_group},
      {"GET", "/v1/volumes/{id}/zarr/{scale}/zarr.json", E::kWorker, &Api::zarr_array},
      {"GET", "/v1/volumes/{id}/zarr/{scale}/c/{c}/{cz}/{cy}/{cx}", E::kWorker, &Api::zarr_chunk},
      {"GET", "/v1/volumes/{id}/zarr2/.zgroup", E::kWorker, &Api::zarr2_group},
      {"GET", "/v1/volumes/{id}/zarr2/.zattrs", E::kWorker, &Api::zarr2_attributes},
      {"GET", "/v1/volumes/{id}/zarr2/{scale}/.zarray", E::kWorker, &Api::zarr2_array},
      {"GET", "/v1/volumes/{id}/zarr2/{scale}/{c}/{cz}/{cy}/{cx}", E::kWorker, &Api::zarr2_chunk},
      {"GET", "/v1/volumes/{id}/precomputed/info", E::kWorker, &Api::precomputed_info},
      {"GET", "/v1/volumes/{id}/precomputed/{scale}/{chunk}", E::kWorker, &Api::precomputed_chunk},
      {"GET", "/v1/volumes/{id}/precomputed-jpeg/info", E::kWorker, &Api::precomputed_jpeg_info},
      {"GET", "/v1/volumes/{id}/precomputed-jpeg/{scale}/{chunk}", E::kWorker, &Api::precomputed_jpeg_chunk},
  };
  return routes;
}

namespace {

std::vector<std::string> segments(const std::string& path) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '/') {
      ++i;
      continue;
    }
    size_t j = path.find('/', i);
    if (j == std::string::npos) j = path.size();
    out.push_back(path.substr(i, j - i));
    i = j;
  }
  return out;
}

bool matches(const std::vector<std::string>& tmpl, const std::vector<std::string>& path,
             std::map<std::string, std::string>& params) {
  if (tmpl.size() != path.size()) return false;
  std::map<std::string, std::string> found;
  for (size_t i = 0; i < tmpl.size(); ++i) {
    const std::string& t = tmpl[i];
    if (t.size() > 2 && t.front() == '{' && t.back() == '}') {
      if (path[i].empty()) return false;
      found[t.substr(1, t.size() - 2)] = path[i];
    } else if (t != path[i]) {
      return false;
    }
  }
  params = std::move(found);
  return true;
}

}  // namespace

// A path that a literal template matches (/v1/fields/from-mesh) belongs to it alone, not also
// to a template with a parameter in that place (/v1/fields/{id}): only the templates with the
// most literal segments among those that match count, for the handler and for Allow.
const Route* match_route(const std::string& method, const std::string& path, std::map<std::string, std::string>& params,
                         std::vector<std::string>& allowed) {
  const auto parts = segments(path);
  const Route* hit = nullptr;
  size_t best = 0;
  std::vector<std::string> methods;
  for (const Route& r : route_table()) {
    std::map<std::string, std::string> p;
    if (!matches(segments(r.path), parts, p)) continue;
    const size_t literals = parts.size() - p.size();
    if (literals < best) continue;
    if (literals > best) {
      best = literals;
      methods.clear();
      hit = nullptr;
    }
    methods.push_back(r.method);
    // Every GET route answers HEAD too (RFC 9110 9.3.2); the adapter drops the body.
    const bool head_of_get = method == "HEAD" && std::string_view(r.method) == "GET";
    if (std::string_view(r.method) == "GET") methods.push_back("HEAD");
    if (!hit && (method == r.method || head_of_get)) {
      hit = &r;
      params = std::move(p);
    }
  }
  allowed.insert(allowed.end(), methods.begin(), methods.end());
  return hit;
}

}  // namespace solidtex::server
