#include "scene/curves.h"

#include "parser/scene_description.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace penumbra {

namespace {

const ParamSpec kCurveParams[] = {
    {"point3[]", "P", "", "control points"},
    {"string", "basis", "bezier", "bezier or bspline"},
    {"integer", "degree", "3", "2 or 3"},
    {"string", "type", "flat", "flat (faces the ray), cylinder (shaded as a tube) or ribbon (oriented by N)"},
    {"normal[]", "N", "", "ribbon normals at the segment ends (one more than segments)"},
    {"float", "width", "1", "width at both ends"},
    {"float", "width0", "", "width at the start (default: width)"},
    {"float", "width1", "", "width at the end (default: width)"},
    {"integer", "splitdepth", "3", "pbrt-v4's refinement depth for its own intersector: accepted, not needed by Embree's"},
    {"unsupported", "alpha", "", "alpha cut-outs on curves are not supported"},
};

Vec3 lerp3(float t, const Vec3& a, const Vec3& b) { return (1.f - t) * a + t * b; }

// The cubic Bezier control points of segment `i` of pbrt-v4's curve with the given basis and degree.
std::array<Vec3, 4> bezier_segment(const std::vector<Vec3>& cp, size_t i, bool bspline, int degree) {
  if (!bspline && degree == 3) return {cp[3 * i], cp[3 * i + 1], cp[3 * i + 2], cp[3 * i + 3]};
  if (!bspline) {  // quadratic Bezier, elevated
    const Vec3 &p0 = cp[2 * i], &p1 = cp[2 * i + 1], &p2 = cp[2 * i + 2];
    return {p0, lerp3(2.f / 3.f, p0, p1), lerp3(1.f / 3.f, p1, p2), p2};
  }
  if (degree == 3) {  // uniform cubic B-spline segment to Bezier
    const Vec3 &p0 = cp[i], &p1 = cp[i + 1], &p2 = cp[i + 2], &p3 = cp[i + 3];
    return {(p0 + 4.f * p1 + p2) / 6.f, (2.f * p1 + p2) / 3.f, (p1 + 2.f * p2) / 3.f, (p1 + 4.f * p2 + p3) / 6.f};
  }
  // uniform quadratic B-spline segment to a quadratic Bezier, elevated
  const Vec3 &p0 = cp[i], &p1 = cp[i + 1], &p2 = cp[i + 2];
  Vec3 b0 = 0.5f * (p0 + p1), b2 = 0.5f * (p1 + p2);
  return {b0, lerp3(2.f / 3.f, b0, p1), lerp3(1.f / 3.f, p1, b2), b2};
}

Vec3 slerp(float t, const Vec3& a, const Vec3& b) {
  float c = std::clamp(glm::dot(a, b), -1.f, 1.f);
  float theta = std::acos(c);
  if (theta < 1e-4f) return glm::normalize(lerp3(t, a, b));
  float s = std::sin(theta);
  return glm::normalize((std::sin((1.f - t) * theta) / s) * a + (std::sin(t * theta) / s) * b);
}

// A cubic Bezier with control values c[0..3] at t (positions with radii, normals).
template <class T>
T bezier(const T* c, float t) {
  float s = 1.f - t;
  return (s * s * s) * c[0] + (3.f * s * s * t) * c[1] + (3.f * s * t * t) * c[2] + (t * t * t) * c[3];
}

}  // namespace

Vec3 Curves::center(size_t segment, float t) const { return Vec3(bezier(&control[4 * segment], t)); }

Vec3 Curves::derivative(size_t segment, float t) const {
  const Vec4* c = &control[4 * segment];
  float s = 1.f - t;
  return 3.f * (s * s * Vec3(c[1] - c[0]) + 2.f * s * t * Vec3(c[2] - c[1]) + t * t * Vec3(c[3] - c[2]));
}

float Curves::width(size_t segment, float t) const { return 2.f * bezier(&control[4 * segment], t).w; }

Curves::Surface Curves::surface(size_t segment, float t, float v, const Vec3& p, const Vec3& d,
                                const Vec3& embree_ng) const {
  Surface s;
  s.p = p;
  float w = width(segment, t);
  s.p_error = Vec3(w);  // pbrt-v4's bound: the strand's width
  const Vec2 ur = u_range[segment];
  Vec3 tangent = derivative(segment, t);
  if (!(glm::dot(tangent, tangent) > 0.f)) tangent = Vec3(control[4 * segment + 3] - control[4 * segment]);
  Vec3 t_hat = glm::normalize(tangent);
  s.dpdu = tangent / std::max(ur.y - ur.x, 1e-8f);
  // The normal of a ribbon facing the ray: -d made perpendicular to the tangent.
  Vec3 facing = -(d - t_hat * glm::dot(d, t_hat));
  if (!(glm::dot(facing, facing) > 0.f)) facing = Frame(t_hat).s;  // a ray along the strand: any normal to it
  facing = glm::normalize(facing);
  // v runs across the width from 0 to 1 towards tangent x facing, for every type: where pbrt-v4 puts
  // it (its ray-space dp/dv, the tangent turned by +90 degrees in its left-handed ray frame). Hair's
  // offset h = -1 + 2 v follows it, so hair highlights land on the side pbrt-v4 puts them. Which side
  // of the centre line a hit is on comes from the geometry; Embree's v gives only the distance.
  const Vec3 v_dir = glm::cross(t_hat, facing);
  const float side = glm::dot(p - center(segment, t), v_dir) >= 0.f ? 1.f : -1.f;
  auto v_at = [&](float distance) { return 0.5f * (1.f + side * std::min(distance, 1.f)); };
  if (type == CurveType::Ribbon) {
    Vec3 n = glm::normalize(embree_ng);
    // Orient as the given normals (slerped along the segment) say.
    if (glm::dot(n, bezier(&normals[4 * segment], t)) < 0.f) n = -n;
    s.ng = s.ns = n;
    s.dpdv = glm::normalize(glm::cross(n, t_hat)) * w;  // pbrt-v4's ribbon dp/dv
    s.uv = Vec2(ur.x + t * (ur.y - ur.x), v_at(std::abs(2.f * v - 1.f)));
    return s;
  }
  float v01 = v_at(std::abs(v));
  s.ng = s.ns = facing;
  if (type == CurveType::Cylinder) {
    // pbrt-v4 turns the normal itself (it rotates dp/dv by -theta about dp/du), so the geometric
    // normal turns with the shading one (integrators' test that the two agree on a direction's side
    // must not cut the fake tube's edges away), and towards the far edge on the side facing the ray.
    // Rays leave the strand along it: the other sense made a dense head 3 % brighter than pbrt-v4's.
    float theta = (v01 - 0.5f) * Pi;  // -90 to 90 degrees across the width
    s.ng = s.ns = glm::normalize(std::cos(theta) * facing - std::sin(theta) * v_dir);
  }
  s.dpdv = v_dir * w;
  s.uv = Vec2(ur.x + t * (ur.y - ur.x), v01);
  return s;
}

Curves load_curves(ShapeEntity& e) {
  e.params.validate(kCurveParams, "shape 'curve'");
  Curves c;
  std::vector<Vec3> cp = e.params.get_point3s("P");
  const FileLoc p_loc = e.params.has("P") ? e.params.loc_of("P") : e.loc;
  std::string basis = e.params.get_string("basis");
  if (basis != "bezier" && basis != "bspline")
    throw Error(e.params.loc_of("basis"), fmt::format("curve basis '{}' is not supported; available: bezier, bspline", basis));
  const bool bspline = basis == "bspline";
  int degree = e.params.get_int("degree");
  if (degree != 2 && degree != 3)
    throw Error(e.params.loc_of("degree"), fmt::format("curve degree {} is not supported; available: 2, 3", degree));
  std::string type = e.params.get_string("type");
  if (type == "flat") c.type = CurveType::Flat;
  else if (type == "cylinder") c.type = CurveType::Cylinder;
  else if (type == "ribbon") c.type = CurveType::Ribbon;
  else
    throw Error(e.params.loc_of("type"), fmt::format("curve type '{}' is not supported; available: flat, cylinder, ribbon", type));

  // pbrt-v4's control point counts: Bezier segments share their end points, B-spline segments
  // share degree points.
  size_t n = cp.size(), segments = 0;
  bool valid = false;
  if (!bspline) {
    valid = n > static_cast<size_t>(degree) && (n - 1) % degree == 0;
    segments = valid ? (n - 1) / degree : 0;
  } else {
    valid = n > static_cast<size_t>(degree);
    segments = valid ? n - degree : 0;
  }
  if (!valid)
    throw Error(p_loc, bspline ? fmt::format("a degree-{} bspline curve needs at least {} control points, not {}", degree,
                                             degree + 1, n)
                               : fmt::format("a degree-{} bezier curve needs {}k + 1 control points (k >= 1), not {}",
                                             degree, degree, n));
  for (const Vec3& p : cp)
    if (!is_finite(p)) throw Error(p_loc, "curve control points must be finite");

  float width = e.params.get_float("width");
  float w0 = e.params.has("width0") ? e.params.get_float("width0") : width;
  float w1 = e.params.has("width1") ? e.params.get_float("width1") : width;
  for (const char* name : {"width", "width0", "width1"})
    if (e.params.has(name) && !(e.params.get_float(name) >= 0.f && std::isfinite(e.params.get_float(name))))
      throw Error(e.params.loc_of(name), fmt::format("curve {} must be finite and >= 0", name));
  if (!(std::max(w0, w1) > 0.f)) throw Error(e.loc, "a curve of width 0 is invisible");

  std::vector<Vec3> N = e.params.get_point3s("N");
  if (c.type == CurveType::Ribbon) {
    if (N.size() != segments + 1)
      throw Error(e.params.has("N") ? e.params.loc_of("N") : e.loc,
                  fmt::format("a ribbon curve needs \"normal N\" at its {} segment ends, not {} normals", segments + 1,
                              N.size()));
    for (Vec3& nn : N) {
      if (!(glm::dot(nn, nn) > 0.f) || !is_finite(nn)) throw Error(e.params.loc_of("N"), "ribbon normals must be non-zero");
      nn = glm::normalize(nn);
    }
  }
  if (e.params.get_int("splitdepth") < 0) throw Error(e.params.loc_of("splitdepth"), "splitdepth must be >= 0");

  const Mat4& m = e.to_world;
  if (m[0][3] != 0.f || m[1][3] != 0.f || m[2][3] != 0.f || m[3][3] != 1.f)
    throw Error(e.loc, "a curve under a projective transform is not supported");
  float det = glm::determinant(glm::mat3(m));
  if (det == 0.f) throw Error(e.loc, "the curve's transform is singular");
  const float width_scale = std::cbrt(std::abs(det));
  const glm::mat3 normal_to_world = glm::transpose(glm::inverse(glm::mat3(m)));
  // pbrt-v4 flips a ribbon's normal with ReverseOrientation or a handedness-changing transform.
  const float normal_sign = e.reverse_orientation != (det < 0.f) ? -1.f : 1.f;

  c.control.reserve(4 * segments);
  c.u_range.reserve(segments);
  for (size_t i = 0; i < segments; ++i) {
    std::array<Vec3, 4> b = bezier_segment(cp, i, bspline, degree);
    float u0 = static_cast<float>(i) / segments, u1 = static_cast<float>(i + 1) / segments;
    Vec4 control[4];
    Vec3 normals[4];
    for (int k = 0; k < 4; ++k) {
      float u = u0 + (u1 - u0) * k / 3.f;
      float r = 0.5f * width_scale * ((1.f - u) * w0 + u * w1);
      control[k] = Vec4(Vec3(m * Vec4(b[k], 1.f)), r);
    }
    if (c.type == CurveType::Ribbon) {
      Vec3 a = normal_sign * glm::normalize(normal_to_world * N[i]);
      Vec3 z = normal_sign * glm::normalize(normal_to_world * N[i + 1]);
      for (int k = 0; k < 4; ++k) normals[k] = slerp(k / 3.f, a, z);
    }
    c.control.insert(c.control.end(), control, control + 4);
    if (c.type == CurveType::Ribbon) c.normals.insert(c.normals.end(), normals, normals + 4);
    c.u_range.emplace_back(u0, u1);
  }
  return c;
}

}  // namespace penumbra
