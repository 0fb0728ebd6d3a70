#include "scene/bilinear_patches.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

template <typename T>
T bilerp(const T& a00, const T& a10, const T& a01, const T& a11, float u, float v) {
  return (1.f - u) * (1.f - v) * a00 + u * (1.f - v) * a10 + (1.f - u) * v * a01 + u * v * a11;
}

float twist(const Vec3& p00, const Vec3& p10, const Vec3& p01, const Vec3& p11) {
  return glm::length(glm::dvec3(p00) - glm::dvec3(p10) - glm::dvec3(p01) + glm::dvec3(p11));
}

}  // namespace

int bilinear_grid_size(const Vec3& p00, const Vec3& p10, const Vec3& p01, const Vec3& p11) {
  float c = twist(p00, p10, p01, p11);
  float tol = kBilinearTolerance * std::max(glm::length(p11 - p00), glm::length(p10 - p01));
  if (!(c > 4.f * tol)) return 1;  // c / (4 n^2) <= tol at n = 1 (also degenerate patches)
  return std::clamp(int(std::ceil(std::sqrt(c / (4.f * tol)))), 1, 64);
}

float bilinear_deviation_bound(const Vec3& p00, const Vec3& p10, const Vec3& p01, const Vec3& p11, int n) {
  return twist(p00, p10, p01, p11) / (4.f * float(n) * float(n));
}

TessellatedPatches tessellate_bilinear_patches(const std::vector<Vec3>& P, const std::vector<int>& indices_in,
                                               const std::vector<Vec2>& uv, const std::vector<Vec3>& N,
                                               const FileLoc& shape_loc, const FileLoc& indices_loc,
                                               const FileLoc& uv_loc, const FileLoc& n_loc) {
  if (P.empty()) throw Error(shape_loc, "bilinearmesh has no vertices (\"point3 P\")");
  std::vector<int> indices = indices_in;
  if (indices.empty()) {
    if (P.size() != 4)
      throw Error(shape_loc, fmt::format("bilinearmesh has {} vertices and no \"indices\"", P.size()));
    indices = {0, 1, 2, 3};
  }
  if (indices.size() % 4 != 0)
    throw Error(indices_loc, fmt::format("\"indices\" has {} values, not a multiple of 4 (p00 p10 p01 p11 per patch)",
                                         indices.size()));
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || size_t(indices[i]) >= P.size())
      throw Error(indices_loc, fmt::format("index {} (value {}) is out of range: the mesh has {} vertices", i,
                                           indices[i], P.size()));
  if (!uv.empty() && uv.size() != P.size())
    throw Error(uv_loc, fmt::format("\"uv\" has {} values for {} vertices", uv.size(), P.size()));
  if (!N.empty() && N.size() != P.size())
    throw Error(n_loc, fmt::format("\"N\" has {} normals for {} vertices", N.size(), P.size()));

  TessellatedPatches out;
  for (size_t k = 0; k < indices.size() / 4; ++k) {
    const int* c = &indices[4 * k];
    const Vec3 &p00 = P[c[0]], &p10 = P[c[1]], &p01 = P[c[2]], &p11 = P[c[3]];
    Vec2 t00(0.f, 0.f), t10(1.f, 0.f), t01(0.f, 1.f), t11(1.f, 1.f);
    if (!uv.empty()) t00 = uv[c[0]], t10 = uv[c[1]], t01 = uv[c[2]], t11 = uv[c[3]];
    int n = bilinear_grid_size(p00, p10, p01, p11);
    int base = int(out.P.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        float u = float(i) / float(n), v = float(j) / float(n);
        // Corners exactly, so that neighbouring patches meet without cracks.
        out.P.push_back(bilerp(p00, p10, p01, p11, u, v));
        out.uv.push_back(bilerp(t00, t10, t01, t11, u, v));
        if (!N.empty()) out.N.push_back(bilerp(N[c[0]], N[c[1]], N[c[2]], N[c[3]], u, v));
      }
    // Cell (i, j): a = (i, j), b = (i+1, j), d = (i+1, j+1), e = (i, j+1); triangles (a b d) and
    // (a d e) wind like dp/du x dp/dv, pbrt-v4's normal of the patch.
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        int a = base + j * (n + 1) + i, b = a + 1, e = a + (n + 1), d = e + 1;
        int tri[6] = {a, b, d, a, d, e};
        out.indices.insert(out.indices.end(), tri, tri + 6);
      }
  }
  return out;
}

}  // namespace penumbra
