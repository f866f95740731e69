#include "synthesis/resident_bytes.h"

#include <set>

#include "synthesis/correction.h"
#include "synthesis/frame_stencils.h"

namespace solidtex {
namespace {

// Heap blocks carry a header and are rounded up (glibc: 16 bytes).
constexpr int64_t kBlockOverhead = 16;

template <typename T>
int64_t vector_bytes(const std::vector<T>& v) {
  return v.capacity() == 0 ? 0 : int64_t(v.capacity() * sizeof(T)) + kBlockOverhead;
}

int64_t image_bytes(const ImageF& img) { return int64_t(sizeof(ImageF)) + vector_bytes(img.pixels); }

int64_t pca_bytes(const PcaBasis& p) { return vector_bytes(p.mean) + vector_bytes(p.basis); }

int64_t projection_bytes(const PcaProjection& p) { return vector_bytes(p.mean) + vector_bytes(p.basis_t); }

}  // namespace

int64_t table_resident_bytes(const Table& table) {
  int64_t bytes = int64_t(sizeof(Table));
  std::set<const void*> seen;
  for (int k = 0; k < 3; ++k) {
    const auto& img = table.exemplars().plane_ptr(plane_from_index(k));
    if (img && seen.insert(img.get()).second) bytes += image_bytes(*img) + kBlockOverhead;
  }
  for (int l = 0; l < table.levels(); ++l) {
    const TableLevel& level = table.level(PyramidLevel{l});
    bytes += int64_t(sizeof(TableLevel));
    for (const auto& app : level.planes)
      if (app && seen.insert(app.get()).second)
        bytes += int64_t(sizeof(PlaneAppearance)) + kBlockOverhead + vector_bytes(app->stack.pixels) +
                 pca_bytes(app->pca) + vector_bytes(app->projected) +
                 vector_bytes(app->typicality) + vector_bytes(app->usage);
    for (const PlaneCandidates& pc : level.candidates->planes)
      if (pc.triples && seen.insert(pc.triples.get()).second) bytes += vector_bytes(*pc.triples) + vector_bytes(*pc.counts);
  }
  return bytes;
}

int64_t field_resident_bytes(const FrameField& field) {
  if (const auto* grid = dynamic_cast<const QuatGridField*>(&field)) {
    const auto& d = grid->dims();
    const int64_t nodes = int64_t(d[0]) * d[1] * d[2];
    return int64_t(sizeof(QuatGridField)) + kBlockOverhead + nodes * int64_t(sizeof(Quat) + sizeof(std::array<double, 3>)) +
           2 * kBlockOverhead;
  }
  return int64_t(sizeof(ConstantField)) + kBlockOverhead;
}

int64_t synthesizer_state_bytes(const Synthesizer& s) {
  const Table& table = s.table();
  const SynthesisParams& params = s.params();
  const int levels = table.levels();
  int64_t bytes = int64_t(sizeof(Synthesizer)) + int64_t(sizeof(VoxelCache)) + 4 * kBlockOverhead;
  // The synthesizer builds exactly these per level at creation (synthesizer.cpp): rebuild them
  // here to read their sizes.
  for (int l = 0; l < levels; ++l) {
    const CorrectionContext ctx = CorrectionContext::make(table, PyramidLevel{l}, params);
    bytes += int64_t(sizeof(CorrectionContext));
    for (const PcaProjection& p : ctx.projection) bytes += projection_bytes(p);
    for (int k = 0; k < 3; ++k)  // penalty arrays, shared by planes sharing an image
      if (ctx.penalty[size_t(k)] && (k == 0 || ctx.penalty[size_t(k)] != ctx.penalty[size_t(k - 1)]))
        bytes += int64_t(sizeof(std::vector<float>)) + 2 * kBlockOverhead + vector_bytes(*ctx.penalty[size_t(k)]);
    const LevelSchedule& sch = s.schedule(PyramidLevel{l});
    // Steps with their windows' barriers, and the slot table (at most 8 classes x versions).
    int64_t barriers = 0;
    for (const CorrectionStep& step : sch.steps())
      if (step.window.has_barrier()) barriers += 2 * 12 + kBlockOverhead;
    bytes += int64_t(sizeof(LevelSchedule)) + vector_bytes(sch.steps()) + barriers +
             8 * int64_t(sch.final_version() + 1) * int64_t(sizeof(int)) + kBlockOverhead;
  }
  auto stencils = FrameStencils::make(s.field(), table.params().neighborhood, levels, params.trilinear_levels);
  if (stencils && stencils->constant()) {
    ReadStencil scratch;
    FrameStencils::Offsets offsets_scratch;
    for (int l = 0; l < levels; ++l) {
      const ReadStencil& st = stencils->stencil(PyramidLevel{l}, Voxel{}, scratch);
      bytes += int64_t(sizeof(ReadStencil)) + vector_bytes(st.taps) + vector_bytes(st.begin);
      bytes += vector_bytes(stencils->offsets(PyramidLevel{l}, Voxel{}, scratch, offsets_scratch));
    }
  }
  return bytes;
}

}  // namespace solidtex
