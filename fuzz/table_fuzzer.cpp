// decode_table (analysis/table_file.h), the .stx reader: header, checksum, then the payload
// (parameters, matching images, PCA bases, candidate triples) and Table::assemble.
// Each input is decoded twice: as given (header and checksum checks), and with its size and
// checksum fields recomputed (fuzz_support.h) so mutated payloads reach the payload decoder.
// Checked for an accepted table: every stored candidate coordinate lies in its exemplar and
// the pixel's own coordinate is implicit, derived data has the right sizes, and
// encode_table(decode_table(x)) == x.
#include "analysis/table_file.h"
#include "fuzz_support.h"

using namespace solidtex;

namespace {

void check_table(const Table& t) {
  FUZZ_CHECK(t.params().validate().is_ok());
  FUZZ_CHECK(t.levels() == t.params().levels);
  const ExemplarSet& ex = t.exemplars();
  for (int l = 0; l < t.levels(); ++l) {
    const TableLevel& level = t.level(PyramidLevel{l});
    for (int k = 0; k < 3; ++k) {
      const ImageF& img = ex.plane(plane_from_index(k));
      FUZZ_CHECK(img.channels == ex.channels());
      const PlaneAppearance& app = *level.planes[size_t(k)];
      FUZZ_CHECK(app.stack.width == img.width && app.stack.height == img.height);
      FUZZ_CHECK(app.pca.output_dims >= 1 && app.pca.output_dims <= app.pca.input_dims);
      FUZZ_CHECK(app.projected.size() == size_t(img.pixel_count()) * size_t(app.pca.output_dims));
      const PlaneCandidates& pc = level.candidates->planes[size_t(k)];
      FUZZ_CHECK(pc.width == img.width && pc.height == img.height);
      FUZZ_CHECK(pc.per_pixel == t.params().candidates);
      FUZZ_CHECK(pc.counts && pc.triples);
      FUZZ_CHECK(pc.counts->size() == size_t(img.pixel_count()));
      FUZZ_CHECK(pc.triples->size() == size_t(img.pixel_count()) * size_t(pc.per_pixel));
      for (size_t i = 0; i < pc.counts->size(); ++i) {
        FUZZ_CHECK((*pc.counts)[i] <= pc.per_pixel);
        const CandidateList list = pc.at({int(i % size_t(img.width)), int(i / size_t(img.width))});
        FUZZ_CHECK(list.size() == (*pc.counts)[i]);
        for (const CoordinateTriple& tr : list) {
          FUZZ_CHECK(tr.at[size_t(k)].x == int32_t(i % size_t(img.width)) && tr.at[size_t(k)].y == int32_t(i / size_t(img.width)));
          for (int p = 0; p < 3; ++p) {
            const ImageF& other = ex.plane(plane_from_index(p));
            FUZZ_CHECK(tr.at[size_t(p)].x >= 0 && tr.at[size_t(p)].x < other.width);
            FUZZ_CHECK(tr.at[size_t(p)].y >= 0 && tr.at[size_t(p)].y < other.height);
          }
        }
      }
    }
  }
}

void decode_and_check(std::span<const uint8_t> file) {
  auto table = decode_table(file);
  if (!table) {
    FUZZ_CHECK(!table.status().message().empty());
    return;
  }
  check_table(**table);
  const std::vector<uint8_t> again = encode_table(**table);
  FUZZ_CHECK(again.size() == file.size() && std::equal(again.begin(), again.end(), file.begin()));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::as_given_and_with_valid_checksum(data, size, decode_and_check);
  return 0;
}
