#include "synthesis/region_volume.h"

#include "core/number_list.h"


namespace solidtex {

int RegionLabel::label_of(const WorldPoint& p) const {
  if (kind == Kind::kHalfSpace) return normal.x * p.x + normal.y * p.y + normal.z * p.z >= offset ? 1 : 0;
  if (kind == Kind::kSurfaceShell) return surface && surface->at(p) <= distance ? 1 : 0;
  return p.x >= min.x && p.y >= min.y && p.z >= min.z && p.x <= max.x && p.y <= max.y && p.z <= max.z ? 1 : 0;
}

Result<RegionLabel> RegionLabel::parse(const std::string& spec) {
  RegionLabel l;
  if (spec.rfind("halfspace:", 0) == 0) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto v, parse_number_list(spec.substr(10), 4, "regions"));
    if (v[0] == 0 && v[1] == 0 && v[2] == 0)
      return Status(StatusCode::kInvalidArgument, "half-space normal must be non-zero", "regions");
    l.kind = Kind::kHalfSpace;
    l.normal = {v[0], v[1], v[2]};
    l.offset = v[3];
    return l;
  }
  if (spec.rfind("box:", 0) == 0) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto v, parse_number_list(spec.substr(4), 6, "regions"));
    if (!(v[3] >= v[0] && v[4] >= v[1] && v[5] >= v[2]))
      return Status(StatusCode::kInvalidArgument, "box max must not be below its min", "regions");
    l.kind = Kind::kBox;
    l.min = {v[0], v[1], v[2]};
    l.max = {v[3], v[4], v[5]};
    return l;
  }
  if (spec.rfind("surface:", 0) == 0) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto v, parse_number_list(spec.substr(8), 1, "regions"));
    if (!(v[0] >= 0.5 && v[0] <= 64)) return Status(StatusCode::kInvalidArgument, "surface distance must be in [0.5, 64] voxels", "regions");
    l.kind = Kind::kSurfaceShell;
    l.distance = v[0];
    return l;
  }
  return Status(StatusCode::kInvalidArgument, "'" + spec + "' is not halfspace:NX,NY,NZ,D, box:X0,Y0,Z0,X1,Y1,Z1 or surface:D",
                "regions");
}

Result<std::shared_ptr<RegionVolume>> RegionVolume::create(std::vector<std::shared_ptr<Synthesizer>> regions,
                                                           RegionLabel label) {
  if (regions.size() != 2) return Status(StatusCode::kInvalidArgument, "needs exactly two region textures", "regions");
  for (const auto& r : regions)
    if (!r) return Status(StatusCode::kInvalidArgument, "a region has no texture", "regions");
  if (label.kind == RegionLabel::Kind::kSurfaceShell && !label.surface)
    return Status(StatusCode::kInvalidArgument, "a surface label needs a mesh", "regions.mesh");
  auto v = std::shared_ptr<RegionVolume>(new RegionVolume());
  v->regions_ = std::move(regions);
  v->label_ = label;
  return v;
}

Result<std::vector<std::array<float, 3>>> RegionVolume::synthesize(const TargetSet& target, Interrupter& interrupter,
                                                                   std::vector<SynthesisStats>* stats,
                                                                   const SynthesisOptions& options) {
  // Split the target's distinct voxels by label, synthesize each part, then map samples back.
  std::vector<std::vector<Voxel>> parts(regions_.size());
  std::vector<std::pair<int, uint32_t>> where(target.voxels.size());
  for (size_t i = 0; i < target.voxels.size(); ++i) {
    const Voxel& v = target.voxels[i];
    const int k = label_.label_of({double(v.x), double(v.y), double(v.z)});
    where[i] = {k, uint32_t(parts[size_t(k)].size())};
    parts[size_t(k)].push_back(v);
  }
  std::vector<std::vector<std::array<float, 3>>> colors(regions_.size());
  if (stats) stats->assign(regions_.size(), SynthesisStats{});
  for (size_t k = 0; k < regions_.size(); ++k) {
    if (parts[k].empty()) continue;
    const TargetSet sub = TargetSet::from_voxels(parts[k], int(parts[k].size()), 1);
    SOLIDTEX_ASSIGN_OR_RETURN(colors[k], regions_[k]->synthesize(sub, interrupter, stats ? &(*stats)[k] : nullptr, options));
  }
  if (options.dependencies_only) return std::vector<std::array<float, 3>>{};
  std::vector<std::array<float, 3>> voxel_rgb(target.voxels.size());
  for (size_t i = 0; i < target.voxels.size(); ++i) voxel_rgb[i] = colors[size_t(where[i].first)][where[i].second];
  return target.resolve(voxel_rgb);
}

}  // namespace solidtex
