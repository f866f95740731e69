#include "field/sketch.h"

#include "core/json_fields.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <set>

namespace solidtex {
namespace {

using nlohmann::json;

Status bad(const std::string& field, const std::string& msg) { return Status(StatusCode::kInvalidArgument, msg, field); }

Result<WorldPoint> point(const json& j, const std::string& where) { return json_point(j, where); }

double len(const WorldPoint& p) { return std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z); }
WorldPoint sub(const WorldPoint& a, const WorldPoint& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

Result<SketchCurve> curve_from_json(const json& j, int index) {
  const std::string where = "curves[" + std::to_string(index) + "]";
  SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"points", "normals", "plane_normal", "axis", "weight"}, where));
  SketchCurve c;
  if (!j.contains("points") || !j["points"].is_array()) return bad(where + ".points", "is required (an array of [x,y,z])");
  for (size_t i = 0; i < j["points"].size(); ++i) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto p, point(j["points"][i], where + ".points[" + std::to_string(i) + "]"));
    c.points.push_back(p);
  }
  if (j.contains("normals")) {
    if (!j["normals"].is_array()) return bad(where + ".normals", "must be an array of [x,y,z]");
    for (size_t i = 0; i < j["normals"].size(); ++i) {
      SOLIDTEX_ASSIGN_OR_RETURN(auto p, point(j["normals"][i], where + ".normals[" + std::to_string(i) + "]"));
      c.normals.push_back(p);
    }
  }
  if (j.contains("plane_normal")) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto p, point(j["plane_normal"], where + ".plane_normal"));
    c.plane_normal = p;
  }
  if (j.contains("axis")) {
    const json& a = j["axis"];
    if (!a.is_string() || (a != "x" && a != "y" && a != "z")) return bad(where + ".axis", "must be \"x\", \"y\" or \"z\"");
    c.axis = a == "x" ? 0 : a == "y" ? 1 : 2;
  }
  if (j.contains("weight")) {
    if (!j["weight"].is_number()) return bad(where + ".weight", "must be a number");
    c.weight = j["weight"].get<double>();
  }
  return c;
}

}  // namespace

Status validate_curve(const SketchCurve& c, const SketchDomain& d, int index) {
  const std::string where = "curves[" + std::to_string(index) + "]";
  if (c.points.size() < 2) return bad(where + ".points", "needs at least 2 points");
  if (c.points.size() > 100000) return bad(where + ".points", "has more than 100000 points");
  if (c.normals.empty() == !c.plane_normal.has_value())
    return bad(where, "give either per-point \"normals\" (a curve on a surface) or one \"plane_normal\"");
  if (!c.normals.empty() && c.normals.size() != c.points.size())
    return bad(where + ".normals", "has " + std::to_string(c.normals.size()) + " entries for " +
                                       std::to_string(c.points.size()) + " points");
  if (!(c.weight > 0 && c.weight <= 1e6)) return bad(where + ".weight", "must be in (0, 1e6]");
  const double eps = 1e-9 * std::max(1.0, len(sub(d.max, d.min)));
  for (size_t i = 0; i < c.points.size(); ++i) {
    const WorldPoint& p = c.points[i];
    const std::string pw = where + ".points[" + std::to_string(i) + "]";
    if (p.x < d.min.x || p.y < d.min.y || p.z < d.min.z || p.x > d.max.x || p.y > d.max.y || p.z > d.max.z)
      return bad(pw, "lies outside the domain");
    if (i > 0 && len(sub(p, c.points[i - 1])) <= eps) return bad(pw, "repeats the previous point");
  }
  for (size_t i = 0; i < c.points.size(); ++i) {
    const std::string pw = where + ".points[" + std::to_string(i) + "]";
    const WorldPoint n = c.normals.empty() ? *c.plane_normal : c.normals[i];
    const std::string nw = c.normals.empty() ? where + ".plane_normal" : where + ".normals[" + std::to_string(i) + "]";
    if (!(len(n) > 1e-12)) return bad(nw, "must be non-zero");
    // Tangent at the point: the adjacent segments' mean direction.
    const WorldPoint a = c.points[i > 0 ? i - 1 : i], b = c.points[i + 1 < c.points.size() ? i + 1 : i];
    const WorldPoint t = sub(b, a);
    const double tl = len(t);
    if (!(tl > eps)) return bad(pw, "has no tangent (the curve folds back on itself)");
    const double cosang = std::abs((t.x * n.x + t.y * n.y + t.z * n.z) / (tl * len(n)));
    if (cosang > 0.999) return bad(pw, "its tangent is parallel to the normal, so it defines no frame");
  }
  return Status::ok();
}

Result<SketchCurve> parse_curve_json(const std::string& text, int index) {
  SOLIDTEX_ASSIGN_OR_RETURN(json j, parse_json_text(text, "curve"));
  return curve_from_json(j, index);
}

Result<Sketch> parse_sketch_json(const std::string& text) {
  SOLIDTEX_ASSIGN_OR_RETURN(json j, parse_json_text(text, "sketch"));
  SOLIDTEX_RETURN_IF_ERROR(check_keys(j, {"domain", "curves", "scales", "frames"}, "sketch"));
  Sketch s;
  if (!j.contains("domain")) return bad("domain", "is required");
  SOLIDTEX_RETURN_IF_ERROR(check_keys(j["domain"], {"min", "max", "shortest_side_cells"}, "domain"));
  if (!j["domain"].contains("min") || !j["domain"].contains("max")) return bad("domain", "needs \"min\" and \"max\"");
  SOLIDTEX_ASSIGN_OR_RETURN(s.domain.min, point(j["domain"]["min"], "domain.min"));
  SOLIDTEX_ASSIGN_OR_RETURN(s.domain.max, point(j["domain"]["max"], "domain.max"));
  if (!(s.domain.max.x > s.domain.min.x && s.domain.max.y > s.domain.min.y && s.domain.max.z > s.domain.min.z))
    return bad("domain.max", "must exceed domain.min on every axis");
  if (j["domain"].contains("shortest_side_cells")) {
    const json& c = j["domain"]["shortest_side_cells"];
    if (!c.is_number_integer() || c.get<int64_t>() < 2 || c.get<int64_t>() > 256)
      return bad("domain.shortest_side_cells", "must be an integer in [2, 256]");
    s.domain.shortest_side_cells = c.get<int>();
  }
  const SketchDomain& dom = s.domain;
  auto inside = [&](const WorldPoint& p) {
    return p.x >= dom.min.x && p.y >= dom.min.y && p.z >= dom.min.z && p.x <= dom.max.x && p.y <= dom.max.y && p.z <= dom.max.z;
  };
  if (j.contains("frames")) {
    if (!j["frames"].is_array()) return bad("frames", "must be an array");
    for (size_t i = 0; i < j["frames"].size(); ++i) {
      const std::string where = "frames[" + std::to_string(i) + "]";
      const json& e = j["frames"][i];
      SOLIDTEX_RETURN_IF_ERROR(check_keys(e, {"point", "quaternion", "weight"}, where));
      if (!e.contains("point") || !e.contains("quaternion")) return bad(where, "needs \"point\" and \"quaternion\"");
      SketchFrame f;
      SOLIDTEX_ASSIGN_OR_RETURN(f.point, point(e["point"], where + ".point"));
      if (!inside(f.point)) return bad(where + ".point", "lies outside the domain");
      const json& q = e["quaternion"];
      if (!q.is_array() || q.size() != 4) return bad(where + ".quaternion", "must be [w, x, y, z]");
      double v[4];
      for (size_t k = 0; k < 4; ++k) {
        if (!q[k].is_number() || !std::isfinite(q[k].get<double>())) return bad(where + ".quaternion", "must be 4 finite numbers");
        v[k] = q[k].get<double>();
      }
      f.frame = {v[0], v[1], v[2], v[3]};
      if (!(std::sqrt(f.frame.dot(f.frame)) > 1e-9)) return bad(where + ".quaternion", "must be non-zero");
      f.frame = f.frame.normalized();
      if (e.contains("weight")) {
        if (!e["weight"].is_number() || !(e["weight"].get<double>() > 0 && e["weight"].get<double>() <= 1e6))
          return bad(where + ".weight", "must be in (0, 1e6]");
        f.weight = e["weight"].get<double>();
      }
      s.frames.push_back(f);
    }
  }
  if (j.contains("curves") && !j["curves"].is_array()) return bad("curves", "must be an array");
  if (!j.contains("curves") && s.frames.empty()) return bad("curves", "is required (an array)");
  if (j.contains("curves") && j["curves"].empty() && s.frames.empty()) return bad("curves", "needs at least one curve");
  for (size_t i = 0; j.contains("curves") && i < j["curves"].size(); ++i) {
    SOLIDTEX_ASSIGN_OR_RETURN(auto c, curve_from_json(j["curves"][i], int(i)));
    SOLIDTEX_RETURN_IF_ERROR(validate_curve(c, s.domain, int(i)));
    s.curves.push_back(std::move(c));
  }
  if (j.contains("scales")) {
    if (!j["scales"].is_array()) return bad("scales", "must be an array");
    for (size_t i = 0; i < j["scales"].size(); ++i) {
      const std::string where = "scales[" + std::to_string(i) + "]";
      const json& e = j["scales"][i];
      SOLIDTEX_RETURN_IF_ERROR(check_keys(e, {"point", "scale", "weight"}, where));
      if (!e.contains("point") || !e.contains("scale")) return bad(where, "needs \"point\" and \"scale\"");
      ScalePoint sp;
      SOLIDTEX_ASSIGN_OR_RETURN(sp.point, point(e["point"], where + ".point"));
      SOLIDTEX_ASSIGN_OR_RETURN(auto sc, point(e["scale"], where + ".scale"));
      sp.scale = {sc.x, sc.y, sc.z};
      for (double v : sp.scale)
        if (!(v >= 0.25 && v <= 4.0)) return bad(where + ".scale", "each factor must be in [0.25, 4]");
      if (!inside(sp.point)) return bad(where + ".point", "lies outside the domain");
      if (e.contains("weight")) {
        if (!e["weight"].is_number() || !(e["weight"].get<double>() > 0 && e["weight"].get<double>() <= 1e6))
          return bad(where + ".weight", "must be in (0, 1e6]");
        sp.weight = e["weight"].get<double>();
      }
      s.scales.push_back(sp);
    }
  }
  return s;
}

std::string sketch_to_json(const Sketch& s) {
  auto p3 = [](const WorldPoint& p) { return json::array({p.x, p.y, p.z}); };
  json j;
  j["domain"] = {{"min", p3(s.domain.min)}, {"max", p3(s.domain.max)}, {"shortest_side_cells", s.domain.shortest_side_cells}};
  if (!s.frames.empty()) {
    json frames = json::array();
    for (const auto& f : s.frames)
      frames.push_back({{"point", p3(f.point)}, {"quaternion", {f.frame.w, f.frame.x, f.frame.y, f.frame.z}}, {"weight", f.weight}});
    j["frames"] = frames;
  }
  json curves = json::array();
  for (const auto& c : s.curves) {
    json cj;
    cj["points"] = json::array();
    for (const auto& p : c.points) cj["points"].push_back(p3(p));
    if (!c.normals.empty()) {
      cj["normals"] = json::array();
      for (const auto& n : c.normals) cj["normals"].push_back(p3(n));
    } else if (c.plane_normal) {
      cj["plane_normal"] = p3(*c.plane_normal);
    }
    if (c.axis) cj["axis"] = std::string(1, char('x' + *c.axis));
    cj["weight"] = c.weight;
    curves.push_back(cj);
  }
  j["curves"] = curves;
  if (!s.scales.empty()) {
    json scales = json::array();
    for (const auto& sp : s.scales)
      scales.push_back({{"point", p3(sp.point)}, {"scale", {sp.scale[0], sp.scale[1], sp.scale[2]}}, {"weight", sp.weight}});
    j["scales"] = scales;
  }
  return j.dump();
}

}  // namespace solidtex
