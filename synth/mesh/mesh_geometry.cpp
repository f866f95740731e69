#include "mesh/mesh_geometry.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <unordered_map>

#include "field/tensor_field.h"

namespace solidtex {
namespace {

using V3 = Eigen::Vector3d;
V3 vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }
WorldPoint wp(const V3& v) { return {v.x(), v.y(), v.z()}; }

uint64_t edge_key(int32_t a, int32_t b) {
  return (uint64_t(uint32_t(std::min(a, b))) << 32) | uint32_t(std::max(a, b));
}

std::vector<V3> face_normals(const Mesh& m) {
  std::vector<V3> n(m.triangles.size());
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    const V3 a = vec(m.vertices[size_t(t[0])]), b = vec(m.vertices[size_t(t[1])]), c = vec(m.vertices[size_t(t[2])]);
    n[f] = (b - a).cross(c - a);  // length = 2 x area
  }
  return n;
}

// Edge -> the faces on it (in face order).
std::unordered_map<uint64_t, std::vector<int32_t>> edge_faces(const Mesh& m) {
  std::unordered_map<uint64_t, std::vector<int32_t>> e;
  e.reserve(m.triangles.size() * 3);
  for (size_t f = 0; f < m.triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) e[edge_key(m.triangles[f][size_t(c)], m.triangles[f][size_t((c + 1) % 3)])].push_back(int32_t(f));
  return e;
}

std::vector<std::vector<int32_t>> vertex_neighbours(const Mesh& m) {
  std::vector<std::vector<int32_t>> nb(m.vertices.size());
  for (const auto& t : m.triangles)
    for (int c = 0; c < 3; ++c) {
      nb[size_t(t[size_t(c)])].push_back(t[size_t((c + 1) % 3)]);
      nb[size_t(t[size_t(c)])].push_back(t[size_t((c + 2) % 3)]);
    }
  for (auto& v : nb) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  return nb;
}

// Signed dihedral angle of a manifold edge (positive where the surface is convex).
double dihedral(const Mesh& m, const std::vector<V3>& fn, int32_t a, int32_t b, const std::vector<int32_t>& faces) {
  const V3 n0 = fn[size_t(faces[0])].normalized(), n1 = fn[size_t(faces[1])].normalized();
  const double angle = std::acos(std::clamp(n0.dot(n1), -1.0, 1.0));
  // Convex when the second face's far vertex lies below the first face's plane.
  const auto& t1 = m.triangles[size_t(faces[1])];
  int32_t far = t1[0];
  for (int32_t v : t1)
    if (v != a && v != b) far = v;
  const double side = n0.dot(vec(m.vertices[size_t(far)]) - vec(m.vertices[size_t(a)]));
  return side <= 0 ? angle : -angle;
}

}  // namespace

std::vector<std::array<double, 3>> vertex_normals(const Mesh& m) {
  const auto fn = face_normals(m);
  std::vector<V3> acc(m.vertices.size(), V3::Zero());
  for (size_t f = 0; f < m.triangles.size(); ++f)
    for (int32_t v : m.triangles[f]) acc[size_t(v)] += fn[f];
  std::vector<std::array<double, 3>> out(m.vertices.size(), {0, 0, 0});
  for (size_t i = 0; i < acc.size(); ++i) {
    const double l = acc[i].norm();
    if (l > 0) out[i] = {acc[i].x() / l, acc[i].y() / l, acc[i].z() / l};
  }
  return out;
}

Result<std::vector<SketchFrame>> curvature_frames(const Mesh& m, const Placement& placement, int max_frames, double cell) {
  if (max_frames < 1) return Status(StatusCode::kInvalidArgument, "must be >= 1", "max_constraints");
  const auto fn = face_normals(m);
  const auto normals = vertex_normals(m);
  const auto ef = edge_faces(m);
  const size_t nv = m.vertices.size();
  std::vector<Eigen::Matrix3d> tensor(nv, Eigen::Matrix3d::Zero());
  for (const auto& [key, faces] : ef) {
    if (faces.size() != 2) continue;  // boundary and non-manifold edges carry no dihedral angle
    const int32_t a = int32_t(key >> 32), b = int32_t(key & 0xffffffffu);
    const V3 e = vec(m.vertices[size_t(b)]) - vec(m.vertices[size_t(a)]);
    const double len = e.norm();
    if (!(len > 0)) continue;
    const V3 u = e / len;
    const Eigen::Matrix3d contribution = dihedral(m, fn, a, b, faces) * len * (u * u.transpose());
    tensor[size_t(a)] += contribution;
    tensor[size_t(b)] += contribution;
  }
  std::vector<V3> dir(nv, V3::Zero());
  std::vector<double> anisotropy(nv, 0);
  for (size_t v = 0; v < nv; ++v) {
    const V3 n = vec(normals[v]);
    if (n.squaredNorm() == 0) continue;
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - n * n.transpose();
    const Eigen::Matrix3d t = p * tensor[v] * p;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(t);
    // Of the two eigenvectors in the tangent plane, the one with the largest |eigenvalue|.
    int best = -1, other = -1;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(es.eigenvectors().col(k).dot(n)) > 0.7) continue;
      if (best < 0 || std::abs(es.eigenvalues()(k)) > std::abs(es.eigenvalues()(best))) {
        other = best;
        best = k;
      } else {
        other = k;
      }
    }
    if (best < 0) continue;
    V3 d = es.eigenvectors().col(best);
    d = (d - n * n.dot(d)).normalized();
    dir[v] = d;
    const double l1 = std::abs(es.eigenvalues()(best)), l2 = other >= 0 ? std::abs(es.eigenvalues()(other)) : 0;
    anisotropy[v] = l1 + l2 > 0 ? (l1 - l2) / (l1 + l2) : 0;
  }
  const auto nb = vertex_neighbours(m);
  // Smooth the line field: average with neighbours, each flipped to agree first.
  for (int sweep = 0; sweep < 3; ++sweep) {
    std::vector<V3> next(nv, V3::Zero());
    for (size_t v = 0; v < nv; ++v) {
      if (dir[v].squaredNorm() == 0) continue;
      V3 acc = dir[v] * (1 + anisotropy[v]);
      for (int32_t u : nb[v]) {
        if (dir[size_t(u)].squaredNorm() == 0) continue;
        const V3 d = dir[size_t(u)].dot(dir[v]) < 0 ? V3(-dir[size_t(u)]) : dir[size_t(u)];
        acc += d * (1 + anisotropy[size_t(u)]);
      }
      const V3 n = vec(normals[v]);
      acc -= n * n.dot(acc);
      next[v] = acc.norm() > 0 ? V3(acc.normalized()) : dir[v];
    }
    dir = std::move(next);
  }
  // Breadth-first walk from the lowest-index vertex of each component: consistent directions
  // and quaternion signs.
  std::vector<int32_t> order;
  std::vector<char> seen(nv, 0);
  std::vector<Quat> quat(nv);
  for (size_t start = 0; start < nv; ++start) {
    if (seen[start] || dir[start].squaredNorm() == 0) continue;
    std::deque<int32_t> queue{int32_t(start)};
    seen[start] = 1;
    const V3 n0 = vec(normals[start]);
    quat[start] = frame_from_tangent_normal(wp(dir[start]), wp(n0), 0);
    if (quat[start].w < 0) quat[start] = {-quat[start].w, -quat[start].x, -quat[start].y, -quat[start].z};
    while (!queue.empty()) {
      const int32_t v = queue.front();
      queue.pop_front();
      order.push_back(v);
      for (int32_t u : nb[size_t(v)]) {
        if (seen[size_t(u)] || dir[size_t(u)].squaredNorm() == 0) continue;
        seen[size_t(u)] = 1;
        if (dir[size_t(u)].dot(dir[size_t(v)]) < 0) dir[size_t(u)] = -dir[size_t(u)];
        Quat q = frame_from_tangent_normal(wp(dir[size_t(u)]), wp(vec(normals[size_t(u)])), 0);
        if (q.dot(quat[size_t(v)]) < 0) q = {-q.w, -q.x, -q.y, -q.z};
        quat[size_t(u)] = q;
        queue.push_back(u);
      }
    }
  }
  // Subsample: the first vertex (in walk order) of each occupied cell; grow cells to the budget.
  for (double c = std::max(cell, 1e-6);; c *= 1.25) {
    std::map<std::array<int64_t, 3>, int32_t> cells;
    for (int32_t v : order) {
      const WorldPoint p = placement.apply(m.vertices[size_t(v)]);
      cells.emplace(std::array<int64_t, 3>{int64_t(std::floor(p.x / c)), int64_t(std::floor(p.y / c)), int64_t(std::floor(p.z / c))}, v);
    }
    if (int64_t(cells.size()) > max_frames) continue;
    std::vector<std::pair<size_t, int32_t>> chosen;  // (walk position, vertex) to keep walk order
    std::unordered_map<int32_t, size_t> position;
    for (size_t i = 0; i < order.size(); ++i) position[order[i]] = i;
    for (const auto& [key, v] : cells) chosen.emplace_back(position[v], v);
    std::sort(chosen.begin(), chosen.end());
    std::vector<SketchFrame> out;
    for (const auto& [pos, v] : chosen)
      out.push_back({placement.apply(m.vertices[size_t(v)]), quat[size_t(v)], 100.0 * std::max(0.05, anisotropy[size_t(v)])});
    if (out.empty()) return Status(StatusCode::kUnprocessable, "no vertex has a usable curvature frame", "mesh");
    return out;
  }
}

Result<std::vector<SketchCurve>> crest_curves(const Mesh& m, const Placement& placement, double angle_degrees) {
  if (!(angle_degrees > 0 && angle_degrees < 180)) return Status(StatusCode::kInvalidArgument, "must be in (0, 180)", "feature_angle_degrees");
  const auto fn = face_normals(m);
  const auto normals = vertex_normals(m);
  const double cos_limit = std::cos(angle_degrees * M_PI / 180);
  // Feature edges, in a deterministic order.
  std::map<uint64_t, char> feature;
  for (const auto& [key, faces] : edge_faces(m)) {
    if (faces.size() != 2) continue;
    if (fn[size_t(faces[0])].normalized().dot(fn[size_t(faces[1])].normalized()) < cos_limit) feature[key] = 1;
  }
  std::map<int32_t, std::vector<int32_t>> adj;
  for (const auto& [key, unused] : feature) {
    const int32_t a = int32_t(key >> 32), b = int32_t(key & 0xffffffffu);
    adj[a].push_back(b);
    adj[b].push_back(a);
  }
  std::map<uint64_t, char> used;
  std::vector<SketchCurve> curves;
  auto walk = [&](int32_t start, int32_t next) {
    std::vector<int32_t> chain{start};
    int32_t prev = start, cur = next;
    used[edge_key(prev, cur)] = 1;
    chain.push_back(cur);
    // Continue through vertices where exactly two feature edges meet.
    while (adj[cur].size() == 2) {
      const int32_t n = adj[cur][0] == prev ? adj[cur][1] : adj[cur][0];
      if (used.count(edge_key(cur, n))) break;
      used[edge_key(cur, n)] = 1;
      prev = cur;
      cur = n;
      chain.push_back(cur);
    }
    SketchCurve c;
    c.axis = 0;
    for (int32_t v : chain) {
      c.points.push_back(placement.apply(m.vertices[size_t(v)]));
      c.normals.push_back({normals[size_t(v)][0], normals[size_t(v)][1], normals[size_t(v)][2]});
    }
    if (c.points.size() >= 2) curves.push_back(std::move(c));
  };
  // Open chains start at ends and junctions; what remains are closed loops.
  for (const auto& [v, nbrs] : adj)
    if (nbrs.size() != 2)
      for (int32_t u : nbrs)
        if (!used.count(edge_key(v, u))) walk(v, u);
  for (const auto& [v, nbrs] : adj)
    for (int32_t u : nbrs)
      if (!used.count(edge_key(v, u))) walk(v, u);
  if (curves.empty())
    return Status(StatusCode::kUnprocessable, "no crest lines: no edge's dihedral angle exceeds " + std::to_string(angle_degrees) + " degrees",
                  "feature_angle_degrees");
  return curves;
}

Result<std::vector<SketchCurve>> surface_curves(const Mesh& m, const Placement& placement,
                                                const std::vector<std::vector<std::array<double, 3>>>& polylines) {
  const auto normals = vertex_normals(m);
  std::vector<SketchCurve> out;
  for (size_t i = 0; i < polylines.size(); ++i) {
    if (polylines[i].size() < 2)
      return Status(StatusCode::kInvalidArgument, "needs at least 2 points", "curves[" + std::to_string(i) + "]");
    SketchCurve c;
    c.axis = 0;
    for (const auto& p : polylines[i]) {
      size_t best = 0;
      double best_d = INFINITY;
      for (size_t v = 0; v < m.vertices.size(); ++v) {
        if (normals[v] == std::array<double, 3>{0, 0, 0}) continue;
        const double d = (vec(m.vertices[v]) - vec(p)).squaredNorm();
        if (d < best_d) {
          best_d = d;
          best = v;
        }
      }
      c.points.push_back(placement.apply(p));
      c.normals.push_back({normals[best][0], normals[best][1], normals[best][2]});
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace solidtex
