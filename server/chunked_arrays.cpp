#include "chunked_arrays.h"

#include <zstd.h>

#include <cstdio>

namespace solidtex::server {
namespace {

using json = nlohmann::json;

json shape_of(const ArrayWindow& w, int scale) {
  const int64_t s = w.side(scale);
  return json::array({3, s, s, s});
}

json chunk_shape() { return json::array({3, kArrayChunk, kArrayChunk, kArrayChunk}); }

// Scale and translation of dataset `scale` in finest voxels: voxel i covers [i 2^s, (i+1) 2^s),
// so its centre sits at i 2^s + (2^s - 1) / 2.
json transformations(int scale) {
  const double f = double(int64_t(1) << scale);
  return json::array({{{"type", "scale"}, {"scale", {1.0, f, f, f}}},
                      {{"type", "translation"}, {"translation", {0.0, (f - 1) / 2, (f - 1) / 2, (f - 1) / 2}}}});
}

json multiscales(const ArrayWindow& w, const std::string& name, const char* version) {
  json datasets = json::array();
  for (int s = 0; s < w.scales; ++s)
    datasets.push_back({{"path", std::to_string(s)}, {"coordinateTransformations", transformations(s)}});
  json axes = json::array({{{"name", "c"}, {"type", "channel"}},
                           {{"name", "z"}, {"type", "space"}},
                           {{"name", "y"}, {"type", "space"}},
                           {{"name", "x"}, {"type", "space"}}});
  json m = {{"name", name},
            {"axes", axes},
            {"datasets", datasets},
            {"metadata",
             {{"description",
               "solidtex synthesis levels: dataset s is synthesis level L-1-s (its triples' output colors), not a box "
               "filter of the finest; the arrays are a window of extent^3 finest voxels on an unbounded volume"},
              {"extent", w.extent}}}};
  if (version) m["version"] = version;
  return json::array({m});
}

}  // namespace

json zarr3_array(const ArrayWindow& w, int scale) {
  return {{"zarr_format", 3},
          {"node_type", "array"},
          {"shape", shape_of(w, scale)},
          {"data_type", "uint8"},
          {"chunk_grid", {{"name", "regular"}, {"configuration", {{"chunk_shape", chunk_shape()}}}}},
          {"chunk_key_encoding", {{"name", "default"}, {"configuration", {{"separator", "/"}}}}},
          {"fill_value", 0},
          {"codecs", json::array({{{"name", "bytes"}},
                                  {{"name", "zstd"}, {"configuration", {{"level", 3}, {"checksum", false}}}}})},
          {"dimension_names", {"c", "z", "y", "x"}},
          {"attributes", json::object()}};
}

json ome_zarr_group(const ArrayWindow& w, const std::string& name) {
  json arrays = json::object();
  for (int s = 0; s < w.scales; ++s) arrays[std::to_string(s)] = zarr3_array(w, s);
  return {{"zarr_format", 3},
          {"node_type", "group"},
          {"attributes", {{"ome", {{"version", "0.5"}, {"multiscales", multiscales(w, name, nullptr)}}}}},
          {"consolidated_metadata", {{"kind", "inline"}, {"must_understand", false}, {"metadata", arrays}}}};
}

json zarr2_group() { return {{"zarr_format", 2}}; }

json ome_zarr04_attributes(const ArrayWindow& w, const std::string& name) {
  return {{"multiscales", multiscales(w, name, "0.4")}};
}

json zarr2_array(const ArrayWindow& w, int scale) {
  return {{"zarr_format", 2},
          {"shape", shape_of(w, scale)},
          {"chunks", chunk_shape()},
          {"dtype", "|u1"},
          {"compressor", {{"id", "zstd"}, {"level", 3}}},
          {"fill_value", 0},
          {"order", "C"},
          {"filters", nullptr},
          {"dimension_separator", "/"}};
}

Result<ChunkBox> chunk_box(const ArrayWindow& w, int scale, const std::array<int64_t, 3>& czyx) {
  if (scale < 0 || scale >= w.scales)
    return Status(StatusCode::kNotFound, "no dataset " + std::to_string(scale) + " (0.." + std::to_string(w.scales - 1) + ")",
                  "scale");
  const int64_t n = w.chunks(scale);
  for (int64_t c : czyx)
    if (c < 0 || c >= n)
      return Status(StatusCode::kNotFound,
                    "chunk index " + std::to_string(c) + " is outside the array (0.." + std::to_string(n - 1) + ")", "chunk");
  return ChunkBox{{int(czyx[2] * kArrayChunk), int(czyx[1] * kArrayChunk), int(czyx[0] * kArrayChunk)}};
}

json precomputed_info(const ArrayWindow& w, const std::string& encoding) {
  json scales = json::array();
  for (int s = 0; s < w.scales; ++s) {
    const int64_t side = w.side(s), f = int64_t(1) << s;
    scales.push_back({{"key", std::to_string(s)},
                      {"size", {side, side, side}},
                      {"resolution", {f, f, f}},
                      {"voxel_offset", {0, 0, 0}},
                      {"chunk_sizes", {{32, 32, 32}, {64, 64, 8}, {64, 8, 64}, {8, 64, 64}}},
                      {"encoding", encoding}});
  }
  return {{"@type", "neuroglancer_multiscale_volume"}, {"type", "image"}, {"data_type", "uint8"}, {"num_channels", 3},
          {"scales", scales}};
}

Result<ChunkBox> precomputed_box(const ArrayWindow& w, int scale, const std::string& name) {
  if (scale < 0 || scale >= w.scales)
    return Status(StatusCode::kNotFound, "no scale " + std::to_string(scale) + " (0.." + std::to_string(w.scales - 1) + ")",
                  "scale");
  int64_t v[6];
  char a[6];
  int used = 0;
  const bool parsed = std::sscanf(name.c_str(), "%ld%c%ld%c%ld%c%ld%c%ld%c%ld%n", &v[0], &a[0], &v[1], &a[1], &v[2], &a[2],
                                  &v[3], &a[3], &v[4], &a[4], &v[5], &used) == 11 &&
                      used == int(name.size()) && a[0] == '-' && a[1] == '_' && a[2] == '-' && a[3] == '_' && a[4] == '-';
  if (!parsed) return Status(StatusCode::kNotFound, "'" + name + "' is not a chunk name x0-x1_y0-y1_z0-z1", "chunk");
  ChunkBox box;
  int64_t voxels = 1;
  for (int k = 0; k < 3; ++k) {
    const int64_t lo = v[2 * k], hi = v[2 * k + 1];
    if (lo < 0 || hi <= lo || hi > w.side(scale) || hi - lo > 64)
      return Status(StatusCode::kNotFound, "'" + name + "' is outside the array or wider than 64 voxels", "chunk");
    box.size[size_t(k)] = int(hi - lo);
    voxels *= hi - lo;
  }
  if (voxels > int64_t(kArrayChunk) * kArrayChunk * kArrayChunk)
    return Status(StatusCode::kNotFound, "'" + name + "' has more than 32768 voxels", "chunk");
  box.min = {int(v[0]), int(v[2]), int(v[4])};
  return box;
}

std::string chunk_bytes(const std::vector<uint8_t>& srgb_zyxc, int64_t voxels) {
  const size_t n = size_t(voxels);
  std::string out(3 * n, '\0');
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) out[c * n + i] = char(srgb_zyxc[i * 3 + c]);
  return out;
}

Result<std::string> zstd_compress(const std::string& bytes) {
  std::string out(ZSTD_compressBound(bytes.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), bytes.data(), bytes.size(), 3);
  if (ZSTD_isError(n)) return Status(StatusCode::kInternal, std::string("zstd: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

}  // namespace solidtex::server
