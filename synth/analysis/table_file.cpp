#include "analysis/table_file.h"

#include <cmath>
#include <cstring>

#include "core/byte_io.h"
#include "core/image_io.h"

namespace solidtex {
namespace {

constexpr char kMagic[8] = {'S', 'T', 'X', 'T', 'A', 'B', 'L', 'E'};
constexpr uint32_t kHeaderBytes = 32;
constexpr int64_t kMaxTableBytes = int64_t(4) << 30;

Status corrupt(const std::string& what) { return Status(StatusCode::kCorrupt, what, "table"); }

void write_image(ByteWriter& w, const ImageF& img) {
  w.i32(img.width);
  w.i32(img.height);
  w.i32(img.channels);
  w.f32s(img.pixels);
}

Result<std::shared_ptr<const ImageF>> read_image(ByteReader& r) {
  int32_t w = 0, h = 0, c = 0;
  SOLIDTEX_RETURN_IF_ERROR(r.i32(w));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(h));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(c));
  if (w < kMinExemplarSide || h < kMinExemplarSide || w > 65535 || h > 65535 || (c != 3 && c != 4) ||
      int64_t(w) * h * c * 4 > int64_t(r.remaining()))
    return corrupt("stored exemplar has an impossible size");
  auto img = std::make_shared<ImageF>(w, h, c);
  SOLIDTEX_RETURN_IF_ERROR(r.f32s(img->pixels, size_t(w) * h * c));
  return std::shared_ptr<const ImageF>(std::move(img));
}

void write_pca(ByteWriter& w, const PcaBasis& p) {
  w.i32(p.input_dims);
  w.i32(p.output_dims);
  w.f32s(p.mean);
  w.f32s(p.basis);
}

Status read_pca(ByteReader& r, PcaBasis& p) {
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.input_dims));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.output_dims));
  if (p.input_dims < 1 || p.input_dims > 4096 || p.output_dims < 1 || p.output_dims > p.input_dims)
    return corrupt("stored PCA basis has impossible dimensions");
  SOLIDTEX_RETURN_IF_ERROR(r.f32s(p.mean, size_t(p.input_dims)));
  SOLIDTEX_RETURN_IF_ERROR(r.f32s(p.basis, size_t(p.input_dims) * p.output_dims));
  return Status::ok();
}

}  // namespace

std::vector<uint8_t> encode_table(const Table& table) {
  ByteWriter w;
  const AnalysisParams& p = table.params();
  w.i32(p.levels);
  w.i32(p.neighborhood);
  w.i32(p.candidates);
  w.i32(p.pca_dims);
  w.i32(p.search_k);
  w.i32(p.knn_checks);
  w.u32(p.seed);
  for (float pw : p.suggested_plane_weights) w.f32(pw);
  const bool shared = table.exemplars().shared();
  w.u8(shared ? 1 : 0);
  w.u8(table.exemplars().has_mask() ? 1 : 0);
  const int distinct = shared ? 1 : 3;
  for (int k = 0; k < distinct; ++k) write_image(w, table.exemplars().plane(plane_from_index(k)));
  for (int l = 0; l < table.levels(); ++l) {
    const TableLevel& level = table.level(PyramidLevel{l});
    w.f64(level.candidates->mean_crossbar_error);
    w.f64(level.candidates->random_crossbar_error);
    w.f64(level.candidates->coherent_fraction);
    for (int k = 0; k < distinct; ++k) write_pca(w, level.planes[k]->pca);
    for (int k = 0; k < distinct; ++k) {
      const PlaneCandidates& pc = level.candidates->planes[k];
      w.i32(pc.per_pixel);
      w.bytes(*pc.counts);
      for (size_t i = 0; i < pc.counts->size(); ++i)
        for (int j = 0; j < (*pc.counts)[i]; ++j) {
          const CoordinateTriple t = pc.at({int(i % size_t(pc.width)), int(i / size_t(pc.width))})[size_t(j)];
          for (int o = 1; o <= 2; ++o) {
            w.u16(uint16_t(t.at[(k + o) % 3].x));
            w.u16(uint16_t(t.at[(k + o) % 3].y));
          }
        }
    }
  }
  if (table.has_usage())
    for (int l = 0; l < table.levels(); ++l)
      for (int k = 0; k < distinct; ++k)
        for (float v : table.level(PyramidLevel{l}).planes[k]->usage) w.f32(v);
  std::vector<uint8_t> payload = std::move(w.buffer());
  ByteWriter h;
  h.bytes(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(kMagic), 8));
  h.u32(table.has_usage() ? kTableFormatVersion : 2);
  h.u32(kHeaderBytes);
  h.u64(payload.size());
  h.u64(checksum64(payload));
  std::vector<uint8_t> out = std::move(h.buffer());
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

Result<std::shared_ptr<const Table>> decode_table(std::span<const uint8_t> bytes) {
  if (bytes.size() < kHeaderBytes) return corrupt("file is " + std::to_string(bytes.size()) + " bytes, shorter than the header");
  if (std::memcmp(bytes.data(), kMagic, 8) != 0) return corrupt("not a solidtex table (bad magic)");
  ByteReader hr(bytes.subspan(8, kHeaderBytes - 8));
  uint32_t version = 0, header_bytes = 0;
  uint64_t payload_bytes = 0, checksum = 0;
  SOLIDTEX_RETURN_IF_ERROR(hr.u32(version));
  SOLIDTEX_RETURN_IF_ERROR(hr.u32(header_bytes));
  SOLIDTEX_RETURN_IF_ERROR(hr.u64(payload_bytes));
  SOLIDTEX_RETURN_IF_ERROR(hr.u64(checksum));
  if (version < kOldestTableFormatVersion || version > kTableFormatVersion)
    return Status(StatusCode::kVersionMismatch,
                  "table format version " + std::to_string(version) + " is not supported (this build reads versions " +
                      std::to_string(kOldestTableFormatVersion) + " to " + std::to_string(kTableFormatVersion) +
                      "); re-run analyze",
                  "table");
  if (header_bytes != kHeaderBytes) return corrupt("header size field is wrong");
  if (payload_bytes != bytes.size() - kHeaderBytes)
    return corrupt("payload is " + std::to_string(bytes.size() - kHeaderBytes) + " bytes but the header says " +
                   std::to_string(payload_bytes) + " (truncated or padded file)");
  std::span<const uint8_t> payload = bytes.subspan(kHeaderBytes);
  if (checksum64(payload) != checksum) return corrupt("checksum mismatch: the file is damaged");

  ByteReader r(payload);
  AnalysisParams p;
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.levels));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.neighborhood));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.candidates));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.pca_dims));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.search_k));
  SOLIDTEX_RETURN_IF_ERROR(r.i32(p.knn_checks));
  SOLIDTEX_RETURN_IF_ERROR(r.u32(p.seed));
  for (float& pw : p.suggested_plane_weights) SOLIDTEX_RETURN_IF_ERROR(r.f32(pw));
  if (Status st = p.validate(); !st) return corrupt("stored parameters are invalid: " + st.to_string());
  if (p.levels == kAutoLevels) return corrupt("stored level count is 0 (tables hold the count used)");
  uint8_t shared = 0, has_mask = 0;
  SOLIDTEX_RETURN_IF_ERROR(r.u8(shared));
  SOLIDTEX_RETURN_IF_ERROR(r.u8(has_mask));
  if (shared > 1 || has_mask > 1) return corrupt("flag byte out of range");
  const int distinct = shared ? 1 : 3;
  std::array<std::shared_ptr<const ImageF>, 3> images;
  for (int k = 0; k < distinct; ++k) {
    SOLIDTEX_ASSIGN_OR_RETURN(images[k], read_image(r));
  }
  if (shared) images[1] = images[2] = images[0];
  SOLIDTEX_ASSIGN_OR_RETURN(ExemplarSet exemplars, ExemplarSet::from_matching_images(images, has_mask != 0));

  std::vector<std::array<PcaBasis, 3>> pcas(static_cast<size_t>(p.levels));
  std::vector<LevelCandidates> candidates(static_cast<size_t>(p.levels));
  for (int l = 0; l < p.levels; ++l) {
    LevelCandidates& lc = candidates[l];
    SOLIDTEX_RETURN_IF_ERROR(r.f64(lc.mean_crossbar_error));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(lc.random_crossbar_error));
    SOLIDTEX_RETURN_IF_ERROR(r.f64(lc.coherent_fraction));
    for (int k = 0; k < distinct; ++k) SOLIDTEX_RETURN_IF_ERROR(read_pca(r, pcas[l][k]));
    if (shared) pcas[l][1] = pcas[l][2] = pcas[l][0];
    for (int k = 0; k < distinct; ++k) {
      const ImageF& img = *images[k];
      int per_pixel = 0;
      SOLIDTEX_RETURN_IF_ERROR(r.i32(per_pixel));
      if (per_pixel != p.candidates) return corrupt("candidates per pixel do not match the parameters");
      std::vector<uint8_t> counts;
      SOLIDTEX_RETURN_IF_ERROR(r.bytes(counts, size_t(img.pixel_count())));
      std::vector<PackedTriple> triples(size_t(img.pixel_count()) * per_pixel);
      for (size_t i = 0; i < counts.size(); ++i) {
        if (counts[i] > per_pixel) return corrupt("candidate count exceeds its limit");
        for (int j = 0; j < counts[i]; ++j) {
          PackedTriple& t = triples[i * per_pixel + j];
          t.c[size_t(2 * k)] = uint16_t(i % size_t(img.width));  // sides <= 65535 (read_image)
          t.c[size_t(2 * k + 1)] = uint16_t(i / size_t(img.width));
          for (int o = 1; o <= 2; ++o) {
            const int plane = (k + o) % 3;
            uint16_t x = 0, y = 0;
            SOLIDTEX_RETURN_IF_ERROR(r.u16(x));
            SOLIDTEX_RETURN_IF_ERROR(r.u16(y));
            if (x >= images[plane]->width || y >= images[plane]->height)
              return corrupt("candidate coordinate outside its exemplar");
            t.c[size_t(2 * plane)] = x;
            t.c[size_t(2 * plane + 1)] = y;
          }
        }
      }
      lc.planes[k] = PlaneCandidates::make(img.width, img.height, per_pixel, std::move(triples), std::move(counts));
    }
    if (shared)
      for (int k = 1; k < 3; ++k) lc.planes[k] = lc.planes[0].rotated(k);
  }
  UsagePenalties usage;
  if (version >= 3) {
    usage.resize(size_t(p.levels));
    for (int l = 0; l < p.levels; ++l)
      for (int k = 0; k < distinct; ++k) {
        std::vector<float>& u = usage[size_t(l)].emplace_back(size_t(images[k]->pixel_count()));
        for (float& v : u) {
          SOLIDTEX_RETURN_IF_ERROR(r.f32(v));
          if (!(std::isfinite(v) && v >= 0.f)) return corrupt("usage penalty is negative or not finite");
        }
      }
  }
  if (r.remaining() != 0) return corrupt("unexpected bytes after the last level");
  SOLIDTEX_ASSIGN_OR_RETURN(auto table, Table::assemble(p, std::move(exemplars), std::move(pcas), std::move(candidates)));
  if (usage.empty()) return table;
  return table->with_usage(std::move(usage));
}

Status save_table(const std::string& path, const Table& table) {
  const std::vector<uint8_t> bytes = encode_table(table);
  return write_file_atomic(path, bytes);
}

Result<std::shared_ptr<const Table>> load_table(const std::string& path) {
  auto bytes = read_file_bytes(path, kMaxTableBytes);
  if (!bytes) return Status(bytes.status().code(), bytes.status().message(), "table");
  auto table = decode_table(*bytes);
  if (!table) return table.status().with_context("'" + path + "'");
  return table;
}

}  // namespace solidtex
