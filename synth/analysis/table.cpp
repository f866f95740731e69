#include "analysis/table.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "analysis/gaussian_stack.h"
#include "analysis/neighborhood.h"
#include "analysis/typicality.h"

namespace solidtex {

std::vector<float> project_all_neighborhoods(const ImageF& stack, const PcaBasis& basis, int n, int spacing) {
  const PcaProjection pca = PcaProjection::of(basis);
  std::vector<float> out(size_t(stack.pixel_count()) * pca.output_dims);
  tbb::parallel_for(tbb::blocked_range<int>(0, stack.height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<float> nb(static_cast<size_t>(neighborhood_dims(n, stack.channels)));
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < stack.width; ++x) {
        gather_neighborhood(stack, {x, y}, n, spacing, nb.data());
        pca.project(nb.data(), &out[(size_t(y) * stack.width + x) * pca.output_dims]);
      }
  });
  return out;
}

Result<std::shared_ptr<const Table>> Table::assemble(AnalysisParams params, ExemplarSet exemplars,
                                                     std::vector<std::array<PcaBasis, 3>> pca_per_level,
                                                     std::vector<LevelCandidates> candidates) {
  SOLIDTEX_RETURN_IF_ERROR(params.validate());
  const int L = params.levels;
  if (int(pca_per_level.size()) != L || int(candidates.size()) != L)
    return Status(StatusCode::kCorrupt, "level count does not match the parameters");
  auto table = std::make_shared<Table>();
  table->params_ = params;
  table->exemplars_ = exemplars;
  table->levels_.resize(size_t(L));
  const int distinct = exemplars.shared() ? 1 : 3;
  for (int k = 0; k < distinct; ++k) {
    const ImageF& img = exemplars.plane(plane_from_index(k));
    std::vector<ImageF> stack = build_gaussian_stack(img, L);
    for (int l = 0; l < L; ++l) {
      const PcaBasis& pca = pca_per_level[l][k];
      if (pca.input_dims != neighborhood_dims(params.neighborhood, img.channels))
        return Status(StatusCode::kCorrupt, "PCA basis does not fit the neighborhood size");
      const int spacing = stack_spacing(PyramidLevel{l}, L);
      auto app = std::make_shared<PlaneAppearance>();
      app->stack = std::move(stack[size_t(L - 1 - l)]);
      app->pca = pca;
      app->projected = project_all_neighborhoods(app->stack, pca, params.neighborhood, spacing);
      app->typicality = typicality_penalty(app->projected, pca.output_dims);
      for (int p = k; p < (distinct == 1 ? 3 : k + 1); ++p) table->levels_[l].planes[p] = app;
    }
  }
  for (int l = 0; l < L; ++l) {
    for (int k = 0; k < 3; ++k) {
      const PlaneCandidates& pc = candidates[l].planes[k];
      const ImageF& img = exemplars.plane(plane_from_index(k));
      if (pc.width != img.width || pc.height != img.height || pc.per_pixel < 1 ||
          pc.counts.size() != size_t(img.pixel_count()) ||
          pc.triples.size() != size_t(img.pixel_count()) * pc.per_pixel)
        return Status(StatusCode::kCorrupt, "candidate table does not match its exemplar");
    }
    table->levels_[l].candidates = std::move(candidates[l]);
  }
  return std::shared_ptr<const Table>(std::move(table));
}

}  // namespace solidtex
