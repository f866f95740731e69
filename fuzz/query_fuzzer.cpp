// Query strings as the service reads them: RESTinio's parse_query (relaxed traits, as in
// http_server.cpp; its exceptions are caught there and answered 400), then QueryParams::parse
// (server/query_params.h) against one route's accepted keys, then every typed getter, which
// in turn uses parse_number_list (core/number_list.h).
// The first byte picks the route's key set; the rest is the raw query string (after '?').
// Checked: getters return values within the requested ranges and counts, or errors naming
// the key.
#include <restinio/uri_helpers.hpp>

#include <cmath>
#include <cstdlib>
#include <set>

#include "core/number_list.h"
#include "fuzz_support.h"
#include "query_params.h"

using namespace solidtex;
using namespace solidtex::server;

namespace {

// The key sets of api.cpp's handlers.
const std::set<std::string> kRoutes[] = {
    {},
    {"timeout"},
    {"name"},
    {"name", "levels", "neighborhood", "candidates", "pca_dims", "seed", "plane_weights", "grain", "mask_weight"},
    {"min", "size", "step"},
    {"axis", "at", "origin", "size", "timeout"},
    {"min", "size", "timeout"},
    {"timeout", "resolution", "margin", "format"},
};

void check_error(const Status& st, const std::string& key) {
  FUZZ_CHECK(!st.is_ok());
  FUZZ_CHECK(st.field() == key);
  FUZZ_CHECK(!st.message().empty());
}

void exercise(const QueryParams& q, const std::string& key) {
  const bool has = q.has(key);
  FUZZ_CHECK(has == q.get(key).has_value());
  auto req = q.required(key);
  FUZZ_CHECK(req.is_ok() == has);
  if (!req) check_error(req.status(), key);

  auto i = q.get_int(key, 7, -(int64_t(1) << 28), int64_t(1) << 28);
  if (i) FUZZ_CHECK(has ? (*i >= -(int64_t(1) << 28) && *i <= (int64_t(1) << 28)) : *i == 7);
  else check_error(i.status(), key);

  auto d = q.get_double(key, 0.25, 1e-6, 1e6);
  if (d) FUZZ_CHECK(has ? (std::isfinite(*d) && *d >= 1e-6 && *d <= 1e6) : *d == 0.25);
  else check_error(d.status(), key);

  for (size_t count = 1; count <= 3; ++count) {
    auto l = q.get_list(key, count);
    if (l) {
      FUZZ_CHECK(l->size() == count);
      for (double v : *l) FUZZ_CHECK(std::isfinite(v));
    } else {
      check_error(l.status(), key);
    }
    auto il = q.get_int_list(key, count);
    if (il) {
      FUZZ_CHECK(l.is_ok() && il->size() == count);
      for (size_t k = 0; k < count; ++k) FUZZ_CHECK(double((*il)[k]) == (*l)[k] && std::abs((*il)[k]) <= (1 << 28));
    } else {
      check_error(il.status(), key);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::set<std::string>& allowed = kRoutes[data[0] % (sizeof(kRoutes) / sizeof(kRoutes[0]))];
  const std::string raw = fuzz::text(data + 1, size - 1);

  std::vector<std::pair<std::string, std::string>> query;
  try {
    for (const auto& [k, v] : restinio::parse_query<restinio::parse_query_traits::relaxed>(raw))
      query.emplace_back(std::string(k), std::string(v));
  } catch (const std::exception&) {
    return 0;  // 400 "malformed query string"
  }

  for (const auto& [k, v] : query) {
    auto n = parse_number_list(v, 3, k);
    if (n) {
      FUZZ_CHECK(n->size() == 3);
      for (double x : *n) FUZZ_CHECK(std::isfinite(x));
    }
    // The contract's number syntax (JSON numbers) is a subset of what strtod reads.
    if (is_number_text(v)) {
      char* end = nullptr;
      const double d = std::strtod(v.c_str(), &end);
      FUZZ_CHECK(end == v.c_str() + v.size());
      FUZZ_CHECK(is_number_list_text(v, 1));
      FUZZ_CHECK(parse_number_list(v, 1, k).is_ok() == std::isfinite(d));
    }
    if (is_number_list_text(v, 3) && !n) FUZZ_CHECK(n.status().message().find("is not a number") != std::string::npos);
  }

  Result<QueryParams> q = QueryParams::parse(query, allowed);
  if (!q) {
    FUZZ_CHECK(!q.status().message().empty());
    return 0;
  }
  for (const std::string& key : allowed) exercise(*q, key);
  exercise(*q, "not-a-key");
  return 0;
}
