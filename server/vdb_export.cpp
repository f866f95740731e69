#include "vdb_export.h"

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <mutex>
#include <sstream>

namespace solidtex::server {

Result<std::string> encode_vdb_box(const Voxel& min, std::array<int, 3> size,
                                   const std::vector<std::array<float, 3>>& rgb, const std::string& volume_id) {
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  const size_t n = size_t(size[0]) * size_t(size[1]) * size_t(size[2]);
  if (rgb.size() != n) return Status(StatusCode::kInternal, "color count does not match the box");
  try {
    auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0, 0, 0));
    grid->setName("color");
    grid->setGridClass(openvdb::GRID_UNKNOWN);
    grid->setVectorType(openvdb::VEC_INVARIANT);
    grid->insertMeta("solidtex_volume", openvdb::StringMetadata(volume_id));
    grid->insertMeta("color_space", openvdb::StringMetadata("linear sRGB"));
    auto acc = grid->getAccessor();
    size_t i = 0;
    for (int z = 0; z < size[2]; ++z)
      for (int y = 0; y < size[1]; ++y)
        for (int x = 0; x < size[0]; ++x, ++i)
          acc.setValueOn(openvdb::Coord(min.x + x, min.y + y, min.z + z), openvdb::Vec3s(rgb[i][0], rgb[i][1], rgb[i][2]));
    std::ostringstream out(std::ios::binary);
    openvdb::GridPtrVec grids{grid};
    openvdb::io::Stream(out).write(grids);
    return out.str();
  } catch (const std::exception& e) {
    return Status(StatusCode::kInternal, std::string("OpenVDB encoding failed: ") + e.what());
  }
}

}  // namespace solidtex::server
