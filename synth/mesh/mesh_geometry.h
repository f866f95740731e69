// Frame-field constraints from mesh geometry (Zhang §3 fed by Gorla et al.'s principal
// curvature directions and Xu et al.'s feature curves), in world units via a Placement.
//
// Curvature: per-vertex curvature tensor by the normal-cycle estimate (Cohen-Steiner & Morvan):
// T = sum over incident edges of beta(e) |e| e e^T (beta the signed dihedral angle), projected
// on the tangent plane; the eigenvector of T's largest |eigenvalue| is the direction of
// *least* curvature (along a cylinder's axis). Directions are smoothed (3 sweeps) and oriented
// consistently by a breadth-first walk over the mesh (d and -d give different frames once
// interpolated); frames are x = that direction, y = the vertex normal, z = x cross y, with
// quaternion signs following the same walk. A vertex's weight is 100 x its anisotropy
// (|k1| - |k2|) / (|k1| + |k2|), at least 5, so umbilic regions steer little.
// Features: crest lines are chains of edges whose faces' normals differ by more than the
// feature angle; each chain becomes a sketch curve (x along the curve, normals from vertices).
// Deterministic: same mesh and parameters, same constraints.
#pragma once

#include <vector>

#include "mesh/mesh.h"
#include "field/sketch.h"

namespace solidtex {

// Area-weighted unit normals per vertex (zero for unreferenced vertices).
std::vector<std::array<double, 3>> vertex_normals(const Mesh& mesh);

// At most `max_frames` frames, one per occupied cell of a grid of side `cell` world units
// (the cell grows until the budget holds), at vertices in walk order.
Result<std::vector<SketchFrame>> curvature_frames(const Mesh& mesh, const Placement& placement, int max_frames,
                                                  double cell);

// Chains of feature edges (dihedral angle above `angle_degrees`) as curves in world units.
Result<std::vector<SketchCurve>> crest_curves(const Mesh& mesh, const Placement& placement, double angle_degrees);

// User polylines in mesh coordinates -> sketch curves (world units), normals from the nearest
// vertices, x along the curve. Errors name "curves[i]".
Result<std::vector<SketchCurve>> surface_curves(const Mesh& mesh, const Placement& placement,
                                                const std::vector<std::vector<std::array<double, 3>>>& polylines);

}  // namespace solidtex
