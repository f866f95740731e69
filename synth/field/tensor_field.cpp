#include "field/tensor_field.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

namespace solidtex {
namespace {

using Vec3 = std::array<double, 3>;
Vec3 v3(const WorldPoint& p) { return {p.x, p.y, p.z}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 unit(const Vec3& a) { return scale(a, 1.0 / std::sqrt(dot(a, a))); }

// Rotation matrix (columns = local axes in world) to quaternion.
Quat from_columns(const Vec3& c0, const Vec3& c1, const Vec3& c2) {
  const double m00 = c0[0], m10 = c0[1], m20 = c0[2], m01 = c1[0], m11 = c1[1], m21 = c1[2], m02 = c2[0], m12 = c2[1],
               m22 = c2[2];
  const double tr = m00 + m11 + m22;
  Quat q;
  if (tr > 0) {
    const double s = std::sqrt(tr + 1.0) * 2;
    q = {0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s};
  } else if (m00 > m11 && m00 > m22) {
    const double s = std::sqrt(1.0 + m00 - m11 - m22) * 2;
    q = {(m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s};
  } else if (m11 > m22) {
    const double s = std::sqrt(1.0 + m11 - m00 - m22) * 2;
    q = {(m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s};
  } else {
    const double s = std::sqrt(1.0 + m22 - m00 - m11) * 2;
    q = {(m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s};
  }
  return q.normalized();
}

Vec3 rotate(const Quat& q, const Vec3& v) {
  const Rot3 r = Rot3::from_quat(q);
  const float in[3] = {float(v[0]), float(v[1]), float(v[2])};
  float out[3];
  r.apply(in, out);
  return {out[0], out[1], out[2]};
}

// Quaternion of the shortest rotation taking unit a onto unit b.
Quat shortest_arc(const Vec3& a, const Vec3& b) {
  const double d = dot(a, b);
  if (d < -1 + 1e-12) {
    Vec3 axis = cross({1, 0, 0}, a);
    if (dot(axis, axis) < 1e-12) axis = cross({0, 1, 0}, a);
    axis = unit(axis);
    return {0, axis[0], axis[1], axis[2]};
  }
  const Vec3 c = cross(a, b);
  return Quat{1 + d, c[0], c[1], c[2]}.normalized();
}

Quat negate(const Quat& q) { return {-q.w, -q.x, -q.y, -q.z}; }

Status cancelled() { return Status(StatusCode::kCancelled, "field solve cancelled"); }

// One piece of an operation: the interrupter to poll and the piece's share [lo, hi] of the
// operation's percent range (was_interrupted receives lo + (hi - lo) * fraction done).
struct Progress {
  Interrupter* interrupter = &null_interrupter();
  double lo = 0, hi = 100;
  bool interrupted(double fraction = 0) const { return interrupter->was_interrupted(int(lo + (hi - lo) * fraction)); }
  Progress part(double a, double b) const { return {interrupter, lo + (hi - lo) * a, lo + (hi - lo) * b}; }
};

// Calls start()/end() around a public operation.
class Task {
 public:
  Task(Interrupter& i, const char* name) : i_(i) { i_.start(name); }
  ~Task() { i_.end(); }
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;

 private:
  Interrupter& i_;
};

// Thrown by PolledCholesky to leave Eigen's CG loop; always caught in this file.
struct Interrupted {};

// The incomplete-Cholesky preconditioner, polling `progress` each time CG applies it (once per
// iteration). Eigen's CG loop has no other hook, so stopping it takes an exception. The
// preconditioner itself is the base class's, so solutions are bit-for-bit those of
// Eigen::IncompleteCholesky.
class PolledCholesky : public Eigen::IncompleteCholesky<double> {
 public:
  const Progress* progress = nullptr;
  template <typename Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    if (progress && progress->interrupted()) throw Interrupted{};
    return Eigen::IncompleteCholesky<double>::solve(b);
  }
};
using Cg = Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, PolledCholesky>;

// "12345", "about 1.65e+13" or "more than 1e308": a node count that may not fit an integer.
std::string node_count_text(const double count[3], double total) {
  if (total < 9e18) return std::to_string(int64_t(count[0]) * int64_t(count[1]) * int64_t(count[2]));
  if (!std::isfinite(total)) return "more than 1e308";
  char buf[32];
  std::snprintf(buf, sizeof buf, "about %.3g", total);
  return buf;
}

}  // namespace

Quat frame_from_tangent_normal(const WorldPoint& tangent, const WorldPoint& normal, int axis) {
  const Vec3 t = unit(v3(tangent));
  Vec3 n = v3(normal);
  n = unit(sub(n, scale(t, dot(n, t))));
  const Vec3 b = cross(t, n);
  std::array<Vec3, 3> cols;
  cols[size_t(axis)] = t;
  cols[size_t((axis + 1) % 3)] = n;
  cols[size_t((axis + 2) % 3)] = b;
  return from_columns(cols[0], cols[1], cols[2]);
}

double rotation_angle_degrees(const Quat& a, const Quat& b) {
  const double d = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return 2.0 * std::acos(d) * 180.0 / M_PI;
}

struct FieldSolver::Impl {
  SketchDomain domain;
  std::array<int, 3> dims{};
  WorldPoint origin;
  double spacing = 1;
  int n = 0;
  Eigen::SparseMatrix<double> ltl;
  std::vector<double> weight;               // sum of w^2 * b_c per node (0: unconstrained)
  std::vector<Eigen::Triplet<double>> constraint;  // sum over samples of w^2 * b b^T
  std::vector<std::array<double, 4>> rhs;   // sum of w^2 * qbar per node
  std::vector<Quat> solution;               // normalised
  Eigen::MatrixXd raw_solution;             // n x 4, warm start for the next solve
  int curves = 0;
  std::vector<std::array<double, 3>> log_scales;

  // The operations behind the public ones (which add start()/end() and undo on failure).
  Status add_curve(const SketchCurve& c, int index, FieldSolveStats* stats, const Progress& progress);
  Status add_frames(const std::vector<SketchFrame>& frames, FieldSolveStats* stats, const Progress& progress);
  Status set_scales(const std::vector<ScalePoint>& scales, const Progress& progress);

  // CG solve of (L + C) x = b for several right-hand sides (columns), warm-started; each column
  // is an equal part of `progress`.
  Result<Eigen::MatrixXd> cg_solve(const std::vector<Eigen::Triplet<double>>& cons, const Eigen::MatrixXd& b,
                                   const Eigen::MatrixXd& guess, const Progress& progress) const {
    if (progress.interrupted()) return cancelled();
    Eigen::SparseMatrix<double> c(n, n);
    c.setFromTriplets(cons.begin(), cons.end());
    Eigen::SparseMatrix<double> a = ltl + c;
    Cg cg;
    cg.setTolerance(1e-13);
    cg.setMaxIterations(20000);
    cg.compute(a);
    Eigen::MatrixXd x(n, b.cols());
    try {
      for (int k = 0; k < b.cols(); ++k) {
        const Progress column = progress.part(double(k) / double(b.cols()), double(k + 1) / double(b.cols()));
        cg.preconditioner().progress = &column;
        x.col(k) = cg.solveWithGuess(b.col(k), guess.col(k));
        cg.preconditioner().progress = nullptr;
      }
    } catch (const Interrupted&) {
      return cancelled();
    }
    return x;
  }

  // What an incremental operation may change before it can fail; restore() undoes it.
  struct Saved {
    size_t constraints = 0;
    std::vector<std::array<double, 4>> rhs;
    std::vector<double> weight;
    int curves = 0;
  };
  Saved save() const { return {constraint.size(), rhs, weight, curves}; }
  void restore(Saved&& s) {
    constraint.erase(constraint.begin() + std::ptrdiff_t(s.constraints), constraint.end());
    rhs = std::move(s.rhs);
    weight = std::move(s.weight);
    curves = s.curves;
  }

  int index(int x, int y, int z) const { return (z * dims[1] + y) * dims[0] + x; }
  // Trilinear corners and weights of a point (clamped into the grid).
  void corners(const Vec3& p, std::array<int, 8>& idx, std::array<double, 8>& w) const {
    const double o[3] = {origin.x, origin.y, origin.z};
    int i0[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
      const double g = std::clamp((p[size_t(a)] - o[a]) / spacing, 0.0, double(dims[size_t(a)] - 1));
      i0[a] = std::min(int(std::floor(g)), dims[size_t(a)] - 2);
      f[a] = g - i0[a];
    }
    for (int c = 0; c < 8; ++c) {
      const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
      idx[size_t(c)] = index(i0[0] + dx, i0[1] + dy, i0[2] + dz);
      w[size_t(c)] = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
    }
  }
  // The current (normalised, trilinearly interpolated) field at p.
  Quat field_at(const Vec3& p) const {
    std::array<int, 8> idx;
    std::array<double, 8> w;
    corners(p, idx, w);
    const Quat ref = solution[size_t(idx[0])];
    Quat acc{0, 0, 0, 0};
    for (int c = 0; c < 8; ++c) {
      Quat q = solution[size_t(idx[size_t(c)])];
      if (q.dot(ref) < 0) q = {-q.w, -q.x, -q.y, -q.z};
      acc = {acc.w + w[size_t(c)] * q.w, acc.x + w[size_t(c)] * q.x, acc.y + w[size_t(c)] * q.y, acc.z + w[size_t(c)] * q.z};
    }
    return acc.normalized();
  }
  int nearest(const Vec3& p) const {
    int c[3];
    const double o[3] = {origin.x, origin.y, origin.z};
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::lround((p[size_t(a)] - o[a]) / spacing)), 0, dims[size_t(a)] - 1);
    return index(c[0], c[1], c[2]);
  }
  Quat current_at(const Vec3& p) const { return field_at(p); }

  // Soft constraint on the interpolated value at p: w2 ||sum_c b_c q_c - qbar||^2.
  void constrain(const Vec3& p, const Quat& q, double w2) {
    std::array<int, 8> idx;
    std::array<double, 8> b;
    corners(p, idx, b);
    for (int c = 0; c < 8; ++c) {
      if (b[size_t(c)] == 0) continue;
      auto& r = rhs[size_t(idx[size_t(c)])];
      const double wb = w2 * b[size_t(c)];
      r[0] += wb * q.w;
      r[1] += wb * q.x;
      r[2] += wb * q.y;
      r[3] += wb * q.z;
      weight[size_t(idx[size_t(c)])] += wb;
      for (int e = 0; e < 8; ++e)
        if (b[size_t(e)] != 0) constraint.emplace_back(idx[size_t(c)], idx[size_t(e)], wb * b[size_t(e)]);
    }
  }

  // Solves for the current constraints. Until the solution is complete nothing but (a first
  // zero) raw_solution changes, so an interrupted solve leaves the previous field in place.
  Status solve(FieldSolveStats* stats, const Progress& progress) {
    if (progress.interrupted()) return cancelled();
    const auto t0 = std::chrono::steady_clock::now();
    Eigen::SparseMatrix<double> c(n, n);
    c.setFromTriplets(constraint.begin(), constraint.end());
    Eigen::SparseMatrix<double> a = ltl + c;
    // Conjugate gradients with an incomplete-Cholesky preconditioner, warm-started from the
    // previous solution (adding a curve changes little), to a tight relative tolerance.
    Cg cg;
    cg.setTolerance(1e-13);
    cg.setMaxIterations(20000);
    cg.compute(a);
    if (cg.info() != Eigen::Success)
      return Status(StatusCode::kInternal, "the field's linear system could not be preconditioned");
    Eigen::MatrixXd b(n, 4), q(n, 4);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 4; ++c) b(i, c) = rhs[size_t(i)][size_t(c)];
    if (raw_solution.rows() != n) raw_solution = Eigen::MatrixXd::Zero(n, 4);
    try {
      for (int c = 0; c < 4; ++c) {
        const Progress column = progress.part(c / 4.0, (c + 1) / 4.0);
        cg.preconditioner().progress = &column;
        Eigen::VectorXd col = cg.solveWithGuess(b.col(c), raw_solution.col(c));
        cg.preconditioner().progress = nullptr;
        q.col(c) = col;
      }
    } catch (const Interrupted&) {
      return cancelled();
    }
    raw_solution = q;
    const double bn = b.norm();
    const double residual = bn > 0 ? (a * q - b).norm() / bn : 0.0;
    int singular = 0, constrained = 0;
    std::vector<Quat> raw(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      raw[size_t(i)] = {q(i, 0), q(i, 1), q(i, 2), q(i, 3)};
      constrained += weight[size_t(i)] > 0;
    }
    solution.assign(size_t(n), Quat{});
    std::vector<char> ok(static_cast<size_t>(n), 0);
    for (int i = 0; i < n; ++i) {
      const double len = std::sqrt(raw[size_t(i)].dot(raw[size_t(i)]));
      if (len > 1e-9) {
        solution[size_t(i)] = raw[size_t(i)].normalized();
        ok[size_t(i)] = 1;
      }
    }
    // Singular nodes take a neighbour's frame (sweeps in a fixed order until all are set).
    bool changed = true;
    while (changed) {
      changed = false;
      for (int z = 0; z < dims[2]; ++z)
        for (int y = 0; y < dims[1]; ++y)
          for (int x = 0; x < dims[0]; ++x) {
            const int i = index(x, y, z);
            if (ok[size_t(i)]) continue;
            const int nb[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
            for (const auto& d : nb) {
              const int xx = x + d[0], yy = y + d[1], zz = z + d[2];
              if (xx < 0 || yy < 0 || zz < 0 || xx >= dims[0] || yy >= dims[1] || zz >= dims[2]) continue;
              const int j = index(xx, yy, zz);
              if (ok[size_t(j)] == 1) {
                solution[size_t(i)] = solution[size_t(j)];
                ok[size_t(i)] = 2;  // set this sweep; counts as singular
                ++singular;
                changed = true;
                break;
              }
            }
          }
      for (auto& o : ok)
        if (o == 2) o = 1;
    }
    if (stats) {
      stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      stats->residual = residual;
      stats->singular_nodes = singular;
      stats->constrained_nodes = constrained;
      stats->nodes = n;
    }
    return Status::ok();
  }
};

FieldSolver::FieldSolver() : impl_(std::make_unique<Impl>()) {}
FieldSolver::~FieldSolver() = default;

Result<std::unique_ptr<FieldSolver>> FieldSolver::create(const SketchDomain& d, int64_t max_nodes) {
  const double ext[3] = {d.max.x - d.min.x, d.max.y - d.min.y, d.max.z - d.min.z};
  if (!(ext[0] > 0 && ext[1] > 0 && ext[2] > 0)) return Status(StatusCode::kInvalidArgument, "domain is empty", "domain");
  if (!(std::isfinite(ext[0]) && std::isfinite(ext[1]) && std::isfinite(ext[2])))
    return Status(StatusCode::kInvalidArgument, "domain is too large (its extent is not a finite number)", "domain");
  if (d.shortest_side_cells < 2 || d.shortest_side_cells > 256)
    return Status(StatusCode::kInvalidArgument, "must be in [2, 256]", "domain.shortest_side_cells");
  const double spacing = std::min({ext[0], ext[1], ext[2]}) / d.shortest_side_cells;
  // Node counts in double precision (exact for any grid under the limits, inf at worst), so
  // that no extent overflows an integer before the limits are checked.
  double count[3];
  double total = 1;
  for (int a = 0; a < 3; ++a) {
    count[a] = std::ceil(ext[a] / spacing - 1e-9) + 1;
    total *= count[a];
  }
  static_assert(kMaxNodes == 2'000'000, "the message below says 2M");
  if (!(total <= double(kMaxNodes)))
    return Status(StatusCode::kTooLarge, "the field grid would have " + node_count_text(count, total) + " nodes (limit 2M)",
                  "domain.shortest_side_cells");
  if (!(total <= double(max_nodes)))
    return Status(StatusCode::kUnprocessable,
                  "the field grid would have " + node_count_text(count, total) + " nodes; the limit is " +
                      std::to_string(max_nodes) + " (lower shortest_side_cells or the domain's aspect)",
                  "domain.shortest_side_cells");
  auto s = std::unique_ptr<FieldSolver>(new FieldSolver());
  Impl& m = *s->impl_;
  m.domain = d;
  m.origin = d.min;
  m.spacing = spacing;
  for (int a = 0; a < 3; ++a) m.dims[size_t(a)] = int(count[a]);
  m.n = int(total);
  // The grid's combinatorial Laplacian (Dirichlet energy sum over edges of ||q_i - q_j||^2).
  std::vector<Eigen::Triplet<double>> trip;
  for (int z = 0; z < m.dims[2]; ++z)
    for (int y = 0; y < m.dims[1]; ++y)
      for (int x = 0; x < m.dims[0]; ++x) {
        const int i = m.index(x, y, z);
        int degree = 0;
        auto edge = [&](int j) {
          trip.emplace_back(i, j, -1.0);
          ++degree;
        };
        if (x > 0) edge(m.index(x - 1, y, z));
        if (x + 1 < m.dims[0]) edge(m.index(x + 1, y, z));
        if (y > 0) edge(m.index(x, y - 1, z));
        if (y + 1 < m.dims[1]) edge(m.index(x, y + 1, z));
        if (z > 0) edge(m.index(x, y, z - 1));
        if (z + 1 < m.dims[2]) edge(m.index(x, y, z + 1));
        trip.emplace_back(i, i, double(degree));
      }
  m.ltl = Eigen::SparseMatrix<double>(m.n, m.n);
  m.ltl.setFromTriplets(trip.begin(), trip.end());
  m.weight.assign(size_t(m.n), 0.0);
  m.rhs.assign(size_t(m.n), {0, 0, 0, 0});
  m.solution.assign(size_t(m.n), Quat{});
  return s;
}

Status FieldSolver::Impl::add_curve(const SketchCurve& c, int index, FieldSolveStats* stats, const Progress& progress) {
  Impl& m = *this;
  SOLIDTEX_RETURN_IF_ERROR(validate_curve(c, m.domain, index));
  const bool first = m.curves == 0;
  const double w2 = c.weight * c.weight;
  Quat previous;
  bool have_previous = false;
  const double step = m.spacing / 2;
  for (size_t s = 0; s + 1 < c.points.size(); ++s) {
    const Vec3 a = v3(c.points[s]), b = v3(c.points[s + 1]);
    const Vec3 seg = sub(b, a);
    const double len = std::sqrt(dot(seg, seg));
    const int samples = std::max(1, int(std::ceil(len / step)));
    const bool last_segment = s + 2 == c.points.size();
    for (int k = 0; k <= samples; ++k) {
      if (k == samples && !last_segment) break;  // the next segment starts here
      const double f = double(k) / samples;
      const Vec3 p = {a[0] + f * seg[0], a[1] + f * seg[1], a[2] + f * seg[2]};
      Vec3 nrm;
      if (c.normals.empty()) {
        nrm = v3(*c.plane_normal);
      } else {
        const Vec3 n0 = v3(c.normals[s]), n1 = v3(c.normals[s + 1]);
        nrm = {n0[0] * (1 - f) + n1[0] * f, n0[1] * (1 - f) + n1[1] * f, n0[2] * (1 - f) + n1[2] * f};
      }
      const Vec3 t = unit(seg);
      const Vec3 ortho = sub(nrm, scale(t, dot(nrm, t)));
      Quat q;
      if (c.axis || first) {
        if (!(dot(ortho, ortho) > 1e-12))
          return Status(StatusCode::kInvalidArgument, "tangent parallel to the normal",
                        "curves[" + std::to_string(index) + "].points[" + std::to_string(s) + "]");
        q = frame_from_tangent_normal({t[0], t[1], t[2]}, {nrm[0], nrm[1], nrm[2]}, c.axis.value_or(0));
      } else {
        // Rotate the current frame minimally so its closest +-axis follows the tangent.
        const Quat cur = m.current_at(p);
        int best_axis = 0;
        double best = -2;
        for (int ax = 0; ax < 3; ++ax) {
          Vec3 e{0, 0, 0};
          e[size_t(ax)] = 1;
          const Vec3 we = rotate(cur, e);
          for (double sign : {1.0, -1.0}) {
            const double d = sign * dot(we, t);
            if (d > best) {
              best = d;
              best_axis = ax * 2 + (sign < 0);
            }
          }
        }
        Vec3 e{0, 0, 0};
        e[size_t(best_axis / 2)] = best_axis % 2 ? -1 : 1;
        q = (shortest_arc(rotate(cur, e), t) * cur).normalized();
      }
      // Sign: continuity along the first curve (w >= 0 at its start); the current field later.
      if (first) {
        if (have_previous ? q.dot(previous) < 0 : q.w < 0) q = negate(q);
      } else if (q.dot(m.current_at(p)) < 0) {
        q = negate(q);
      }
      previous = q;
      have_previous = true;
      m.constrain(p, q, w2);
    }
  }
  ++m.curves;
  return m.solve(stats, progress);
}

Status FieldSolver::Impl::add_frames(const std::vector<SketchFrame>& frames, FieldSolveStats* stats,
                                     const Progress& progress) {
  Impl& m = *this;
  if (frames.empty()) return Status::ok();
  const bool first = m.curves == 0;
  for (const SketchFrame& f : frames) {
    const Vec3 p = v3(f.point);
    Quat q = f.frame.normalized();
    if (!first && q.dot(m.current_at(p)) < 0) q = negate(q);
    m.constrain(p, q, f.weight * f.weight);
  }
  ++m.curves;
  return m.solve(stats, progress);
}

Status FieldSolver::Impl::set_scales(const std::vector<ScalePoint>& scales, const Progress& progress) {
  Impl& m = *this;
  if (scales.empty()) {
    m.log_scales.clear();
    return Status::ok();
  }
  std::vector<Eigen::Triplet<double>> cons;
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(m.n, 3);
  for (size_t i = 0; i < scales.size(); ++i) {
    const ScalePoint& sp = scales[i];
    for (double v : sp.scale)
      if (!(v >= kMinScale && v <= kMaxScale))
        return Status(StatusCode::kInvalidArgument, "each factor must be in [0.25, 4]", "scales[" + std::to_string(i) + "].scale");
    std::array<int, 8> idx;
    std::array<double, 8> w;
    m.corners(v3(sp.point), idx, w);
    const double w2 = sp.weight * sp.weight;
    for (int c = 0; c < 8; ++c) {
      if (w[size_t(c)] == 0) continue;
      for (int a = 0; a < 3; ++a) b(idx[size_t(c)], a) += w2 * w[size_t(c)] * std::log(sp.scale[size_t(a)]);
      for (int e = 0; e < 8; ++e)
        if (w[size_t(e)] != 0) cons.emplace_back(idx[size_t(c)], idx[size_t(e)], w2 * w[size_t(c)] * w[size_t(e)]);
    }
  }
  SOLIDTEX_ASSIGN_OR_RETURN(const Eigen::MatrixXd x, m.cg_solve(cons, b, Eigen::MatrixXd::Zero(m.n, 3), progress));
  m.log_scales.resize(size_t(m.n));
  for (int i = 0; i < m.n; ++i)
    for (int a = 0; a < 3; ++a)
      m.log_scales[size_t(i)][size_t(a)] = std::clamp(x(i, a), std::log(kMinScale), std::log(kMaxScale));
  return Status::ok();
}

Status FieldSolver::add_curve(const SketchCurve& curve, int index, FieldSolveStats* stats, Interrupter& interrupter) {
  Task task(interrupter, "field solve");
  Impl::Saved saved = impl_->save();
  Status st = impl_->add_curve(curve, index, stats, Progress{&interrupter});
  if (!st.is_ok()) impl_->restore(std::move(saved));
  return st;
}

Status FieldSolver::add_frames(const std::vector<SketchFrame>& frames, FieldSolveStats* stats, Interrupter& interrupter) {
  Task task(interrupter, "field solve");
  Impl::Saved saved = impl_->save();
  Status st = impl_->add_frames(frames, stats, Progress{&interrupter});
  if (!st.is_ok()) impl_->restore(std::move(saved));
  return st;
}

Status FieldSolver::set_scales(const std::vector<ScalePoint>& scales, Interrupter& interrupter) {
  Task task(interrupter, "field solve");
  return impl_->set_scales(scales, Progress{&interrupter});  // changes nothing unless it succeeds
}

Result<std::unique_ptr<FieldSolver>> FieldSolver::solve(const Sketch& sketch, FieldSolveStats* stats,
                                                        Interrupter& interrupter, int64_t max_nodes) {
  SOLIDTEX_ASSIGN_OR_RETURN(auto solver, create(sketch.domain, max_nodes));
  Task task(interrupter, "field solve");
  Impl& m = *solver->impl_;
  const auto t0 = std::chrono::steady_clock::now();
  // Each linear solve (the frames, every curve, the scales) is an equal share of the progress.
  const size_t steps = (sketch.frames.empty() ? 0 : 1) + sketch.curves.size() + (sketch.scales.empty() ? 0 : 1);
  size_t step = 0;
  auto next = [&] {
    const Progress p = Progress{&interrupter}.part(double(step) / double(steps), double(step + 1) / double(steps));
    ++step;
    return p;
  };
  if (!sketch.frames.empty()) SOLIDTEX_RETURN_IF_ERROR(m.add_frames(sketch.frames, stats, next()));
  for (size_t i = 0; i < sketch.curves.size(); ++i) SOLIDTEX_RETURN_IF_ERROR(m.add_curve(sketch.curves[i], int(i), stats, next()));
  if (!sketch.scales.empty()) SOLIDTEX_RETURN_IF_ERROR(m.set_scales(sketch.scales, next()));
  if (stats) stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return solver;
}

Result<std::shared_ptr<const QuatGridField>> FieldSolver::field() const {
  if (impl_->curves == 0) return Status(StatusCode::kInvalidArgument, "the sketch has no curves", "curves");
  return QuatGridField::create(impl_->origin, impl_->spacing, impl_->dims, impl_->solution, impl_->log_scales);
}
const std::vector<Quat>& FieldSolver::nodes() const { return impl_->solution; }
const std::vector<std::array<double, 3>>& FieldSolver::log_scales() const { return impl_->log_scales; }

std::array<int, 3> FieldSolver::dims() const { return impl_->dims; }
WorldPoint FieldSolver::origin() const { return impl_->origin; }
double FieldSolver::spacing() const { return impl_->spacing; }
int FieldSolver::curve_count() const { return impl_->curves; }

}  // namespace solidtex
