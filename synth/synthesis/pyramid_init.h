// Version 0 of every level: initialisation at the coarsest level (§4.1) and upsampling from
// the parent (§4.2, Eq. 3-4). Pure functions of (table, rotation, voxel, params).
//
// Initialisation: the volume is tiled with candidate slabs. A slab is exemplar xy thickened
// by N voxels along z: voxel w of layer L = floor(w.z / N) takes the first candidate triple of
// pixel (h*w.x + ox, h*w.y + oy), moved by the 3D step (0, 0, h*(w.z - L*N - N/2)) (Eq. 4);
// (ox, oy) is hash(layer, subpart, seed) so layers and subparts differ. The coarsest level is
// cut into subparts of K voxels a side (B along the slabs' across-grain axes:
// slab_subpart_sides); a voxel v in the subpart with centre c reads the tiled volume at
// w = lround(R^T (v - c)) + c, so the slab pattern turns with the local frame about c and
// rotation-induced distortion stays bounded by the subpart's size (Fig. 4).
// Scatter initialisation (SynthesisParams::init; auto's choice for one shared exemplar): voxel w takes the first
// candidate triple of the exemplar pixel hash(w, seed); neither the field nor K matter, since
// a pattern of independent draws looks the same turned. The coarse passes then grow
// coherent patches from it, in every direction alike.
//
// Upsampling: child v of parent P = floor(v/2) gets T(P) + R_P^T * (h_l * (v mod 2)), each
// plane's 2D offset rounded to the nearest pixel (std::lround).
#pragma once

#include <array>

#include "field/frame_field.h"
#include "synthesis/synthesis_params.h"
#include "analysis/table.h"
#include "core/types.h"

namespace solidtex {

// The initialisation `init` stands for with this table: kAuto is kScatter when one exemplar
// serves all three planes and kSlab otherwise (grain layouts, three images).
Init resolved_init(const Table& table, Init init);

// The slab subparts' sides in coarsest-level voxels along x, y, z: params.init_subpart (K),
// except params.init_band (B, when not 0) along the normal of every long-grain plane the slabs
// cross: of yz (normal x) and zx (normal y), the one the table weighs more, both when equal.
// Grain x (yz is the end grain): (K, B, K); grain y: (B, K, K).
std::array<int, 3> slab_subpart_sides(const Table& table, const SynthesisParams& params);

CoordinateTriple init_triple(const Table& table, const Voxel& v, const Rot3& r, const SynthesisParams& params);
CoordinateTriple upsample_triple(const Table& table, PyramidLevel child_level, const Voxel& v,
                                 const CoordinateTriple& parent, const Rot3& parent_rotation);

}  // namespace solidtex
