#include "field/frame_field.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "field/field_file.h"
#include "core/number_list.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace solidtex {

Quat Quat::normalized() const {
  const double d = dot(*this);
  // The common case: the squared norm is a normal finite number.
  if (d >= std::numeric_limits<double>::min() && d <= std::numeric_limits<double>::max()) {
    const double n = std::sqrt(d);
    return {w / n, x / n, y / n, z / n};
  }
  // Components beyond ~1.3e154 overflow the squared norm to infinity (dividing by it gave the
  // zero quaternion, which callers then read as the identity), components below ~1e-154
  // underflow it: scale by the largest component first. Non-finite or zero: the identity.
  if (!std::isfinite(w) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return {};
  const double m = std::max({std::fabs(w), std::fabs(x), std::fabs(y), std::fabs(z)});
  if (!(m > 0)) return {};
  const Quat s{w / m, x / m, y / m, z / m};
  const double n = std::sqrt(s.dot(s));
  return {s.w / n, s.x / n, s.y / n, s.z / n};
}

Quat Quat::from_axis_angle(double ax, double ay, double az, double radians) {
  const double n = std::sqrt(ax * ax + ay * ay + az * az);
  if (!(n > 0)) return {};
  const double s = std::sin(radians / 2) / n;
  return {std::cos(radians / 2), ax * s, ay * s, az * s};
}

Quat operator*(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

Rot3 Rot3::from_quat(const Quat& qin, const std::array<double, 3>& scale) {
  const Quat q = qin.normalized();
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  Rot3 r;
  r.m = {float(1 - 2 * (y * y + z * z)), float(2 * (x * y - w * z)),     float(2 * (x * z + w * y)),
         float(2 * (x * y + w * z)),     float(1 - 2 * (x * x + z * z)), float(2 * (y * z - w * x)),
         float(2 * (x * z - w * y)),     float(2 * (y * z + w * x)),     float(1 - 2 * (x * x + y * y))};
  const std::array<float, 9> rot = r.m;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) {
      r.m[size_t(row * 3 + col)] = rot[size_t(row * 3 + col)] * float(scale[size_t(col)]);
      r.inv[size_t(row * 3 + col)] = rot[size_t(col * 3 + row)] / float(scale[size_t(row)]);
    }
  return r;
}

std::string ConstantField::describe() const {
  std::ostringstream s;
  s.precision(17);
  if (q_.w == 1 && q_.x == 0 && q_.y == 0 && q_.z == 0) s << "identity";
  else s << "quat:" << q_.w << "," << q_.x << "," << q_.y << "," << q_.z;
  if (scale_ != std::array<double, 3>{1, 1, 1}) s << ";scale:" << scale_[0] << "," << scale_[1] << "," << scale_[2];
  return s.str();
}

Result<std::shared_ptr<const QuatGridField>> QuatGridField::create(WorldPoint origin, double spacing,
                                                                   std::array<int, 3> dims, std::vector<Quat> values,
                                                                   std::vector<std::array<double, 3>> log_scales) {
  if (!(spacing > 0) || !std::isfinite(spacing)) return Status(StatusCode::kInvalidArgument, "must be > 0", "spacing");
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z))
    return Status(StatusCode::kInvalidArgument, "must be finite", "origin");
  for (int d : dims)
    if (d < 2 || d > kMaxGridSide)
      return Status(StatusCode::kInvalidArgument, "each must be in [2, " + std::to_string(kMaxGridSide) + "]", "dims");
  if (values.size() != size_t(dims[0]) * dims[1] * dims[2])
    return Status(StatusCode::kInvalidArgument,
                  "has " + std::to_string(values.size()) + " entries; dims need " +
                      std::to_string(size_t(dims[0]) * dims[1] * dims[2]),
                  "quaternions");
  for (size_t i = 0; i < values.size(); ++i) {
    const Quat& q = values[i];
    if (!std::isfinite(q.w) || !std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !(q.dot(q) > 1e-12))
      return Status(StatusCode::kInvalidArgument, "entry " + std::to_string(i) + " is not a valid rotation", "quaternions");
    values[i] = q.normalized();
  }
  if (!log_scales.empty() && log_scales.size() != values.size())
    return Status(StatusCode::kInvalidArgument, "needs one entry per node", "scales");
  double max_scale = 1;
  for (const auto& ls : log_scales)
    for (double v : ls) {
      if (!std::isfinite(v) || std::exp(v) < kMinScale * 0.999 || std::exp(v) > kMaxScale * 1.001)
        return Status(StatusCode::kInvalidArgument, "scales must lie in [0.25, 4]", "scales");
      max_scale = std::max(max_scale, std::exp(v));
    }
  auto f = std::make_shared<QuatGridField>();
  f->log_scales_ = std::move(log_scales);
  f->max_scale_ = max_scale;
  f->origin_ = origin;
  f->spacing_ = spacing;
  f->dims_ = dims;
  f->values_ = std::move(values);
  return std::shared_ptr<const QuatGridField>(std::move(f));
}

void QuatGridField::cell(const WorldPoint& p, int i0[3], double f[3]) const {
  const double g[3] = {(p.x - origin_.x) / spacing_, (p.y - origin_.y) / spacing_, (p.z - origin_.z) / spacing_};
  for (int a = 0; a < 3; ++a) {
    // NaN (a non-finite query point) takes the first cell instead of an undefined int cast.
    double c = std::isnan(g[a]) ? 0.0 : std::clamp(g[a], 0.0, double(dims_[a] - 1));
    i0[a] = std::min(int(std::floor(c)), dims_[a] - 2);
    f[a] = c - i0[a];
  }
}

std::array<double, 3> QuatGridField::scale_at(const WorldPoint& p) const {
  if (log_scales_.empty()) return {1, 1, 1};
  int i0[3];
  double f[3];
  cell(p, i0, f);
  std::array<double, 3> acc{0, 0, 0};
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
    const auto& v = log_scales_[(size_t(i0[2] + dz) * dims_[1] + (i0[1] + dy)) * dims_[0] + (i0[0] + dx)];
    for (int a = 0; a < 3; ++a) acc[size_t(a)] += w * v[size_t(a)];
  }
  return {std::exp(acc[0]), std::exp(acc[1]), std::exp(acc[2])};
}

Quat QuatGridField::at(const WorldPoint& p) const {
  int i0[3];
  double f[3];
  cell(p, i0, f);
  auto val = [&](int dx, int dy, int dz) {
    return values_[(size_t(i0[2] + dz) * dims_[1] + (i0[1] + dy)) * dims_[0] + (i0[0] + dx)];
  };
  const Quat ref = val(0, 0, 0);
  Quat acc{0, 0, 0, 0};
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
    Quat q = val(dx, dy, dz);
    if (q.dot(ref) < 0) q = {-q.w, -q.x, -q.y, -q.z};
    acc.w += w * q.w;
    acc.x += w * q.x;
    acc.y += w * q.y;
    acc.z += w * q.z;
  }
  return acc.normalized();
}

std::string QuatGridField::describe() const {
  return "grid:" + std::to_string(dims_[0]) + "x" + std::to_string(dims_[1]) + "x" + std::to_string(dims_[2]);
}

namespace {

// Beyond this a quaternion's or axis's squared norm, or an angle's sine, loses all precision
// (1e308 squared is infinite), and the field would silently become something else.
constexpr double kMaxSpecMagnitude = 1e6;

Status check_magnitudes(const std::vector<double>& v, const char* what) {
  for (double x : v)
    if (!(std::fabs(x) <= kMaxSpecMagnitude))
      return Status(StatusCode::kInvalidArgument, std::string(what) + " must be finite and within +-1e6", "field");
  return Status::ok();
}

}  // namespace

Result<std::shared_ptr<const FrameField>> parse_field_spec(const std::string& full_spec) {
  std::string spec = full_spec;
  std::array<double, 3> scale{1, 1, 1};
  if (auto semi = full_spec.find(";scale:"); semi != std::string::npos) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto v, parse_number_list(full_spec.substr(semi + 7), 3, "field"));
    for (int a = 0; a < 3; ++a) {
      if (!(v[size_t(a)] >= kMinScale && v[size_t(a)] <= kMaxScale))
        return Status(StatusCode::kInvalidArgument, "scales must lie in [0.25, 4]", "field");
      scale[size_t(a)] = v[size_t(a)];
    }
    spec = full_spec.substr(0, semi);
  }
  if (spec == "identity") return std::shared_ptr<const FrameField>(std::make_shared<ConstantField>(Quat{}, scale));
  if (spec.rfind("quat:", 0) == 0) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto v, parse_number_list(spec.substr(5), 4, "field"));
    SOLIDTEX_RETURN_IF_ERROR(check_magnitudes(v, "quaternion components"));
    Quat q{v[0], v[1], v[2], v[3]};
    if (!(q.dot(q) > 1e-12)) return Status(StatusCode::kInvalidArgument, "quaternion must be non-zero", "field");
    return std::shared_ptr<const FrameField>(std::make_shared<ConstantField>(q, scale));
  }
  if (spec.rfind("axis:", 0) == 0) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto v, parse_number_list(spec.substr(5), 4, "field"));
    SOLIDTEX_RETURN_IF_ERROR(check_magnitudes(v, "axis components and angle"));
    if (!(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > 1e-12))
      return Status(StatusCode::kInvalidArgument, "rotation axis must be non-zero", "field");
    return std::shared_ptr<const FrameField>(
        std::make_shared<ConstantField>(Quat::from_axis_angle(v[0], v[1], v[2], v[3] * M_PI / 180.0), scale));
  }
  {
    std::ifstream probe(spec, std::ios::binary);
    char magic[8] = {};
    if (probe && probe.read(magic, 8) && std::memcmp(magic, "STXFIELD", 8) == 0) {
      SOLIDTEX_ASSIGN_OR_RETURN(auto field, load_field(spec));
      return std::shared_ptr<const FrameField>(field);
    }
  }
  std::ifstream in(spec);
  if (!in) return Status(StatusCode::kInvalidArgument, "'" + spec + "' is not identity, quat:W,X,Y,Z, axis:X,Y,Z,DEG or a readable .stf/.json file", "field");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    return Status(StatusCode::kInvalidArgument, std::string("field file is not valid JSON: ") + e.what(), "field");
  }
  static const std::set<std::string> kKeys = {"origin", "spacing", "dims", "quaternions"};
  if (!j.is_object()) return Status(StatusCode::kInvalidArgument, "field file must hold a JSON object", "field");
  for (auto& [k, _] : j.items())
    if (!kKeys.count(k)) return Status(StatusCode::kInvalidArgument, "unknown key '" + k + "'", "field." + k);
  try {
    auto o = j.at("origin").get<std::vector<double>>();
    auto d = j.at("dims").get<std::vector<int>>();
    if (o.size() != 3 || d.size() != 3) return Status(StatusCode::kInvalidArgument, "origin and dims need 3 entries", "field");
    std::vector<Quat> qs;
    for (const auto& q : j.at("quaternions")) {
      auto v = q.get<std::vector<double>>();
      if (v.size() != 4) return Status(StatusCode::kInvalidArgument, "each quaternion needs 4 numbers", "field.quaternions");
      qs.push_back({v[0], v[1], v[2], v[3]});
    }
    SOLIDTEX_ASSIGN_OR_RETURN(auto grid, QuatGridField::create({o[0], o[1], o[2]}, j.at("spacing").get<double>(),
                                                               {d[0], d[1], d[2]}, std::move(qs)));
    return std::shared_ptr<const FrameField>(grid);
  } catch (const nlohmann::json::exception& e) {
    return Status(StatusCode::kInvalidArgument, std::string("field file: ") + e.what(), "field");
  }
}

}  // namespace solidtex
