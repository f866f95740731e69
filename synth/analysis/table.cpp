#include "analysis/table.h"

#include <cmath>

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
  if (params.levels == kAutoLevels)
    return Status(StatusCode::kInvalidArgument, "must be resolved before a table is assembled (resolve_levels)", "levels");
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
      if (pc.width != img.width || pc.height != img.height || pc.per_pixel < 1 || !pc.counts || !pc.triples ||
          pc.counts->size() != size_t(img.pixel_count()) ||
          pc.triples->size() != size_t(img.pixel_count()) * pc.per_pixel)
        return Status(StatusCode::kCorrupt, "candidate table does not match its exemplar");
    }
    table->levels_[l].candidates = std::make_shared<const LevelCandidates>(std::move(candidates[l]));
  }
  return std::shared_ptr<const Table>(std::move(table));
}

bool Table::has_usage() const { return !levels_.empty() && !levels_[0].planes[0]->usage.empty(); }

UsagePenalties Table::usage() const {
  if (!has_usage()) return {};
  UsagePenalties out(levels_.size());
  for (size_t l = 0; l < levels_.size(); ++l)
    for (int k = 0; k < distinct_images(); ++k) out[l].push_back(levels_[l].planes[size_t(k)]->usage);
  return out;
}

Result<std::shared_ptr<const Table>> Table::with_usage(UsagePenalties usage) const {
  if (!usage.empty()) {
    if (usage.size() != levels_.size()) return Status(StatusCode::kCorrupt, "usage penalties: level count does not match");
    for (size_t l = 0; l < levels_.size(); ++l) {
      if (int(usage[l].size()) != distinct_images())
        return Status(StatusCode::kCorrupt, "usage penalties: image count does not match");
      for (int k = 0; k < distinct_images(); ++k) {
        const auto& u = usage[l][size_t(k)];
        if (u.size() != size_t(levels_[l].planes[size_t(k)]->stack.pixel_count()))
          return Status(StatusCode::kCorrupt, "usage penalties: pixel count does not match the exemplar");
        for (float v : u)
          if (!(std::isfinite(v) && v >= 0.f)) return Status(StatusCode::kCorrupt, "usage penalties must be finite and >= 0");
      }
    }
  }
  auto table = std::make_shared<Table>(*this);
  for (size_t l = 0; l < levels_.size(); ++l)
    for (int k = 0; k < distinct_images(); ++k) {
      auto app = std::make_shared<PlaneAppearance>(*levels_[l].planes[size_t(k)]);
      app->usage = usage.empty() ? std::vector<float>{} : std::move(usage[l][size_t(k)]);
      for (int p = k; p < (distinct_images() == 1 ? 3 : k + 1); ++p) table->levels_[l].planes[size_t(p)] = app;
    }
  return std::shared_ptr<const Table>(std::move(table));
}

}  // namespace solidtex
