#include "scene/scene_builder.h"
#include "scene/composite_materials.h"
#include "scene/cutout_shape.h"

#include "parser/ply_reader.h"
#include "scene/bilinear_patches.h"
#include "scene/loop_subdivision.h"
#include "scene/gltf_loader.h"
#include "scene/media.h"
#include "scene/orthographic_camera.h"
#include "scene/perspective_camera.h"
#include "scene/spherical_camera.h"
#include "scene/surface_params.h"

#include <penumbra/memory.h>

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>

namespace penumbra {

namespace {

const ParamSpec kTriangleMeshParams[] = {
    {"point3[]", "P", "", "vertex positions"},
    {"integer[]", "indices", "", "three vertex indices per triangle (optional for a single triangle)"},
    {"normal[]", "N", "", "per-vertex shading normals"},
    {"point2[]", "uv", "", "per-vertex texture coordinates"},
    {"unsupported", "S", "", "tangents are not used"},
    {"unsupported", "faceIndices", "", ""},
    {"float texture", "alpha", "1", "opacity in [0, 1] (0: cut out; fractions: stochastic), or a float texture"},
};
const ParamSpec kPlyMeshParams[] = {
    {"string", "filename", "", "PLY file (ASCII or binary; triangles and polygons)"},
    {"unsupported", "displacement", "", "displacement of PLY meshes is not supported (bump maps are: give the material \"texture displacement\")"},
    {"unsupported", "edgelength", "", "displacement of PLY meshes is not supported"},
    {"float texture", "alpha", "1", "opacity in [0, 1] (0: cut out; fractions: stochastic), or a float texture"},
};
const ParamSpec kLoopSubdivParams[] = {
    {"integer", "levels", "3", "refinement steps before the vertices go to their limit positions"},
    {"integer[]", "indices", "", "three vertex indices per triangle of the control mesh"},
    {"point3[]", "P", "", "control mesh vertex positions"},
    {"float texture", "alpha", "1", "opacity in [0, 1] (0: cut out; fractions: stochastic), or a float texture"},
};
const ParamSpec kBilinearMeshParams[] = {
    {"point3[]", "P", "", "vertex positions"},
    {"integer[]", "indices", "", "four vertex indices per patch: p00 p10 p01 p11 (optional for one patch)"},
    {"point2[]", "uv", "", "per-vertex texture coordinates (default (0,0) (1,0) (0,1) (1,1) per patch)"},
    {"normal[]", "N", "", "per-vertex shading normals"},
    {"unsupported", "emissionfilename", "", "image-textured emission of bilinear patches is not supported"},
    {"unsupported", "faceIndices", "", ""},
    {"float texture", "alpha", "1", "opacity in [0, 1] (0: cut out; fractions: stochastic), or a float texture"},
};
const ParamSpec kGltfParams[] = {
    {"string", "filename", "", "glTF 2.0 file (.gltf or .glb): all triangle meshes of its default scene"},
};
const ParamSpec kSphereParams[] = {
    {"float", "radius", "1", "radius in object space"},
    {"float", "zmin", "", "must cover the full sphere (partial spheres are not supported)"},
    {"float", "zmax", "", "must cover the full sphere (partial spheres are not supported)"},
    {"float", "phimax", "360", "must be 360 (partial spheres are not supported)"},
    {"float texture", "alpha", "1", "opacity in [0, 1] (0: cut out; fractions: stochastic), or a float texture"},
};

const ParamSpec kDiskParams[] = {
    {"float", "height", "0", "z of the disk's plane in object space"},
    {"float", "radius", "1", "outer radius"},
    {"float", "innerradius", "0", "inner radius (an annulus when > 0)"},
    {"float", "phimax", "360", "largest azimuth in degrees (a sector when < 360)"},
    {"float texture", "alpha", "1", "opacity in [0, 1] (0: cut out; fractions: stochastic), or a float texture"},
};
const ParamSpec kCylinderParams[] = {
    {"float", "radius", "1", "radius in object space"},
    {"float", "zmin", "-1", "lower end along z"},
    {"float", "zmax", "1", "upper end along z"},
    {"float", "phimax", "360", "largest azimuth in degrees"},
    {"float texture", "alpha", "1", "opacity in [0, 1] (0: cut out; fractions: stochastic), or a float texture"},
};

std::string resolve(const std::string& base_dir, const std::string& file) {
  std::filesystem::path p(file);
  return p.is_absolute() || base_dir.empty() ? file : (std::filesystem::path(base_dir) / p).string();
}

bool swaps_handedness(const Mat4& m) { return glm::determinant(glm::mat3(m)) < 0.f; }

// Moves the mesh to world space and checks it: every index in range, array sizes consistent.
std::unique_ptr<TriangleMesh> make_mesh(const ShapeEntity& e, std::vector<Vec3> P, std::vector<int> idx,
                                        std::vector<Vec3> N, std::vector<Vec2> uv, const FileLoc& idx_loc,
                                        const FileLoc& n_loc, const FileLoc& uv_loc) {
  if (P.empty()) throw Error(e.loc, "triangle mesh has no vertices");
  if (idx.empty()) {
    if (P.size() != 3)
      throw Error(e.loc, fmt::format("triangle mesh has {} vertices and no \"indices\"", P.size()));
    idx = {0, 1, 2};
  }
  if (idx.size() % 3 != 0)
    throw Error(idx_loc, fmt::format("\"indices\" has {} values, not a multiple of 3", idx.size()));
  for (size_t i = 0; i < idx.size(); ++i)
    if (idx[i] < 0 || static_cast<size_t>(idx[i]) >= P.size())
      throw Error(idx_loc, fmt::format("index {} (value {}) is out of range: the mesh has {} vertices",
                                       i, idx[i], P.size()));
  if (!N.empty() && N.size() != P.size())
    throw Error(n_loc, fmt::format("\"N\" has {} normals for {} vertices", N.size(), P.size()));
  if (!uv.empty() && uv.size() != P.size())
    throw Error(uv_loc, fmt::format("\"uv\" has {} values for {} vertices", uv.size(), P.size()));

  auto mesh = std::make_unique<TriangleMesh>();
  const Mat4& m = e.to_world;
  glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(m)));
  mesh->P.reserve(P.size());
  for (const Vec3& p : P) mesh->P.push_back(Vec3(m * Vec4(p, 1.f)));
  for (const Vec3& n : N) {
    Vec3 w = normal_matrix * n;
    float len = glm::length(w);
    w = len > 0.f ? w / len : w;
    mesh->N.push_back(e.reverse_orientation ? -w : w);
  }
  mesh->uv = std::move(uv);
  mesh->indices.assign(idx.begin(), idx.end());
  mesh->flip_normal = e.reverse_orientation != swaps_handedness(m);
  for (const Vec3& p : mesh->P)
    if (!is_finite(p)) throw Error(e.loc, "triangle mesh has a non-finite vertex position");
  return mesh;
}

std::unique_ptr<TriangleMesh> load_mesh(ShapeEntity& e) {
  if (e.type == "trianglemesh") {
    e.params.validate(kTriangleMeshParams, "shape 'trianglemesh'");
    return make_mesh(e, e.params.get_point3s("P"), e.params.get_ints("indices"),
                     e.params.get_point3s("N"), e.params.get_point2s("uv"), e.params.loc_of("indices"),
                     e.params.loc_of("N"), e.params.loc_of("uv"));
  }
  if (e.type == "loopsubdiv") {
    e.params.validate(kLoopSubdivParams, "shape 'loopsubdiv'");
    FileLoc idx_loc = e.params.has("indices") ? e.params.loc_of("indices") : e.loc;
    FileLoc levels_loc = e.params.has("levels") ? e.params.loc_of("levels") : e.loc;
    LoopSurface s = loop_subdivide(e.params.get_point3s("P"), e.params.get_ints("indices"),
                                   e.params.get_int("levels"), idx_loc, levels_loc);
    return make_mesh(e, std::move(s.P), std::move(s.indices), std::move(s.N), {}, idx_loc, idx_loc, idx_loc);
  }
  if (e.type == "bilinearmesh") {
    e.params.validate(kBilinearMeshParams, "shape 'bilinearmesh'");
    TessellatedPatches t = tessellate_bilinear_patches(
        e.params.get_point3s("P"), e.params.get_ints("indices"), e.params.get_point2s("uv"),
        e.params.get_point3s("N"), e.loc, e.params.loc_of("indices"), e.params.loc_of("uv"), e.params.loc_of("N"));
    return make_mesh(e, std::move(t.P), std::move(t.indices), std::move(t.N), std::move(t.uv), e.loc, e.loc, e.loc);
  }
  e.params.validate(kPlyMeshParams, "shape 'plymesh'");
  std::string file = e.params.get_string("filename");
  if (file.empty()) throw Error(e.loc, "plymesh needs \"string filename\"");
  FileLoc loc = e.params.loc_of("filename");
  TriangleMeshData data = read_ply(resolve(e.base_dir, file), loc);
  return make_mesh(e, std::move(data.P), std::move(data.indices), std::move(data.N),
                   std::move(data.uv), loc, loc, loc);
}

std::unique_ptr<Sphere> load_sphere(ShapeEntity& e) {
  e.params.validate(kSphereParams, "shape 'sphere'");
  float r = e.params.get_float("radius");
  if (!(r > 0.f)) throw Error(e.params.loc_of("radius"), "sphere radius must be > 0");
  if ((e.params.has("zmin") && e.params.get_float("zmin") > -r) ||
      (e.params.has("zmax") && e.params.get_float("zmax") < r) || e.params.get_float("phimax") < 360.f)
    throw Error(e.loc, "partial spheres (zmin, zmax, phimax) are not supported");
  // Only similarity transforms keep a sphere a sphere.
  const Mat4& m = e.to_world;
  Vec3 c0(m[0]), c1(m[1]), c2(m[2]);
  float s0 = glm::length(c0), s1 = glm::length(c1), s2 = glm::length(c2);
  float tol = 1e-4f * std::max({s0, s1, s2});
  if (std::abs(s0 - s1) > tol || std::abs(s0 - s2) > tol || std::abs(glm::dot(c0, c1)) > tol * s0 ||
      std::abs(glm::dot(c0, c2)) > tol * s0 || std::abs(glm::dot(c1, c2)) > tol * s0 || m[0][3] != 0.f ||
      m[1][3] != 0.f || m[2][3] != 0.f)
    throw Error(e.loc, "a sphere under a non-uniform scale, shear or projection is not supported");
  return std::make_unique<Sphere>(m, r, e.reverse_orientation != swaps_handedness(m));
}

// pbrt-v4's anisotropic roughness parameters ("uroughness", "conductor.vroughness", Disney's
// "anisotropic"): such materials need the shading frame oriented by dp/du.
bool anisotropic(const ParamSet& params) {
  auto ends_with = [](const std::string& s, const char* tail) {
    size_t n = std::char_traits<char>::length(tail);
    return s.size() >= n && s.compare(s.size() - n, n, tail) == 0;
  };
  for (const auto& p : params.params())
    if (ends_with(p.name, "uroughness") || ends_with(p.name, "vroughness") || p.name == "anisotropic") return true;
  return false;
}

bool uses_textures(const ParamSet& params) {
  for (const auto& p : params.params())
    if (p.type == "texture") return true;
  return false;
}

// Every texture is created (pbrt-v4 does the same), each from its own plugin; the table lets later
// textures and the materials find them by name.
void build_textures(SceneDescription& desc, Registry& registry, BuiltScene& out) {
  for (const auto& t : desc.textures) out.texture_table.declare(t.name, t.spectrum, t.loc);
  for (auto& t : desc.textures) {
    CreateContext ctx{t.params, {}, t.base_dir, t.to_world};
    ctx.textures = &out.texture_table;
    ctx.spectrum_texture = t.spectrum;
    std::unique_ptr<Object> obj = registry.create<Object>(PluginKind::Texture, t.type, t.params, ctx, t.loc);
    if (t.spectrum) {
      auto* tex = dynamic_cast<const SpectrumTexture*>(obj.get());
      if (!tex) throw Error(t.loc, fmt::format("texture '{}' did not create a spectrum texture", t.type));
      out.texture_table.add(t.name, tex);
    } else {
      auto* tex = dynamic_cast<const FloatTexture*>(obj.get());
      if (!tex) throw Error(t.loc, fmt::format("texture '{}' did not create a float texture", t.type));
      out.texture_table.add(t.name, tex);
    }
    out.textures.push_back(std::move(obj));
  }
}

// Disks and cylinders take any affine transform (not a projection).
void check_affine(const ShapeEntity& e) {
  const Mat4& m = e.to_world;
  if (m[0][3] != 0.f || m[1][3] != 0.f || m[2][3] != 0.f || m[3][3] != 1.f)
    throw Error(e.loc, fmt::format("a {} under a projective transform is not supported", e.type));
  if (glm::determinant(glm::mat3(m)) == 0.f) throw Error(e.loc, fmt::format("the {}'s transform is singular", e.type));
}

float phimax_of(ShapeEntity& e) {
  float phimax = e.params.get_float("phimax");
  if (!(phimax > 0.f && phimax <= 360.f)) throw Error(e.params.loc_of("phimax"), "phimax must be in (0, 360]");
  return phimax;
}

std::unique_ptr<Quadric> load_quadric(ShapeEntity& e) {
  bool flip = e.reverse_orientation != swaps_handedness(e.to_world);
  if (e.type == "disk") {
    e.params.validate(kDiskParams, "shape 'disk'");
    check_affine(e);
    float r = e.params.get_float("radius"), ri = e.params.get_float("innerradius");
    if (!(r > 0.f) || !std::isfinite(r)) throw Error(e.params.loc_of("radius"), "disk radius must be > 0");
    if (!(ri >= 0.f && ri < r)) throw Error(e.params.loc_of("innerradius"), "innerradius must be in [0, radius)");
    return std::make_unique<Disk>(e.to_world, flip, e.params.get_float("height"), r, ri, phimax_of(e));
  }
  e.params.validate(kCylinderParams, "shape 'cylinder'");
  check_affine(e);
  float r = e.params.get_float("radius"), z0 = e.params.get_float("zmin"), z1 = e.params.get_float("zmax");
  if (!(r > 0.f) || !std::isfinite(r)) throw Error(e.params.loc_of("radius"), "cylinder radius must be > 0");
  if (!(z0 != z1) || !std::isfinite(z0) || !std::isfinite(z1))
    throw Error(e.params.has("zmax") ? e.params.loc_of("zmax") : e.loc, "cylinder zmin and zmax must differ");
  return std::make_unique<Cylinder>(e.to_world, flip, r, z0, z1, phimax_of(e));
}

}  // namespace

BuiltScene build_scene(SceneDescription& desc, Registry& registry) {
  BuiltScene out;

  // Film, filter and camera are part of the core.
  if (!desc.film.type.empty() && desc.film.type != "rgb")
    throw Error(desc.film.loc, fmt::format("unsupported film '{}'; available: rgb", desc.film.type));
  desc.film.params.validate(film_rgb_params(), "film 'rgb'");
  Point2i res(desc.film.params.get_int("xresolution"), desc.film.params.get_int("yresolution"));
  const Param* aovs = desc.film.params.find("aovs");
  AovSet aov_set = aovs ? parse_aovs(aovs->strings, aovs->loc) : AovSet{};
  // Announced before the film is allocated, and before the size limit below, so that an absurd
  // resolution says what it would cost (penumbra/memory.h).
  uint64_t film_bytes = FilmRgb::estimated_bytes(res, aov_set);
  if (film_bytes > 0)
    require_memory(film_bytes, fmt::format("the {}x{} film", res.x, res.y),
                   fmt::format("{} bytes per pixel{}", film_bytes / (uint64_t(res.x) * uint64_t(res.y)),
                               aov_set.any() ? fmt::format(" with the AOVs {}", aov_set.names()) : ""));
  if (res.x <= 0 || res.y <= 0 || res.x > 65536 || res.y > 65536)
    throw Error(desc.film.loc, fmt::format("film resolution {}x{} is out of range", res.x, res.y));
  out.output_filename = desc.film.params.get_string("filename");
  out.spectral = desc.film.params.get_bool("spectral");

  std::string filter_type = desc.filter.type.empty() ? kDefaultFilter : desc.filter.type;
  if (pixel_filter_params(filter_type).empty())
    throw Error(desc.filter.loc,
                fmt::format("unsupported pixel filter '{}'; available: box, gaussian, triangle", filter_type));
  desc.filter.params.validate(pixel_filter_params(filter_type), fmt::format("filter '{}'", filter_type));
  PixelFilter filter(filter_type, desc.filter.params, desc.filter.loc);
  const Vec2 filter_radius = filter.radius();
  out.film = std::make_unique<FilmRgb>(res, std::move(filter), aov_set);

  std::unique_ptr<Camera> camera;
  if (desc.camera.type.empty() || desc.camera.type == "perspective") {
    desc.camera.params.validate(perspective_camera_params(), "camera 'perspective'");
    camera = std::make_unique<PerspectiveCamera>(desc.camera.params, desc.camera.to_world, res, filter_radius);
  } else if (desc.camera.type == "orthographic") {
    desc.camera.params.validate(orthographic_camera_params(), "camera 'orthographic'");
    camera = std::make_unique<OrthographicCamera>(desc.camera.params, desc.camera.to_world, res);
  } else if (desc.camera.type == "spherical") {
    desc.camera.params.validate(spherical_camera_params(), "camera 'spherical'");
    camera = std::make_unique<SphericalCamera>(desc.camera.params, desc.camera.to_world, res, desc.camera.loc);
  } else {
    throw Error(desc.camera.loc, fmt::format("unsupported camera '{}'; available: orthographic, perspective, spherical",
                                             desc.camera.type));
  }

  // Sampler and integrator plugins.
  out.sampler_name = desc.sampler.type.empty() ? kDefaultSampler : desc.sampler.type;
  out.sampler = registry.create<Sampler>(PluginKind::Sampler, out.sampler_name, desc.sampler.params,
                                         CreateContext{desc.sampler.params, {}, desc.sampler.base_dir},
                                         desc.sampler.loc);
  out.integrator_name = desc.integrator.type.empty() ? kDefaultIntegrator : desc.integrator.type;
  out.integrator = registry.create<Integrator>(
      PluginKind::Integrator, out.integrator_name, desc.integrator.params,
      CreateContext{desc.integrator.params, {}, desc.integrator.base_dir}, desc.integrator.loc);

  // Textures in file order (a texture may use those defined before it), then materials in file
  // order; the default material only if some shape needs it.
  build_textures(desc, registry, out);
  std::vector<bool> material_textured;
  std::vector<SurfaceDetail> material_detail;  // bump and normal maps, taken off the plugins' parameters
  std::vector<bool> material_anisotropic;
  for (auto& m : desc.materials) {
    if (m.type.empty()) throw Error(m.loc, "material has no type");
    if (is_composite_material(m.type)) {  // "mix" and "interface": built below from the others
      out.bsdfs.push_back(nullptr);
      material_textured.push_back(true);  // its parts may be textured: give its hits a footprint
      material_detail.emplace_back();
      material_anisotropic.push_back(true);  // its parts may be
      continue;
    }
    material_detail.push_back(take_surface_detail(m.params, m.base_dir, out.texture_table));
    material_anisotropic.push_back(anisotropic(m.params));
    CreateContext ctx{m.params, {}, m.base_dir};
    ctx.textures = &out.texture_table;
    ctx.spectral = out.spectral;
    out.bsdfs.push_back(registry.create<Bsdf>(PluginKind::Bsdf, m.type, m.params, ctx, m.loc));
    // A bump map evaluates its texture over the pixel footprint too.
    material_textured.push_back(uses_textures(m.params) || material_detail.back().bump);
  }
  // A mix picks one of its materials per lookup, not per hit: their bump and normal maps cannot follow.
  for (auto& m : desc.materials) {
    const Param* names = m.type == "mix" ? m.params.find("materials") : nullptr;
    if (!names) continue;
    for (const std::string& name : names->strings)
      if (auto it = desc.named_materials.find(name); it != desc.named_materials.end() && material_detail[it->second].any())
        throw Error(names->loc, fmt::format("material '{}' has a bump or normal map: mixing it is not supported", name));
  }
  build_composite_materials(desc, out.bsdfs);
  const Bsdf* default_bsdf = nullptr;
  ParamSet default_params;
  auto material_index = [&](const ShapeEntity& s) {
    int i = s.material;
    if (i < 0 && !s.material_name.empty()) {
      auto it = desc.named_materials.find(s.material_name);
      i = it == desc.named_materials.end() ? -1 : it->second;
    }
    return i;
  };
  auto textured = [&](const ShapeEntity& s) {
    int i = material_index(s);
    return i >= 0 && material_textured[i];
  };
  // The material's bump or normal map (unless a glTF primitive brings its own material) and the
  // shape's alpha; a constant alpha of 0 drops the shape, as pbrt-v4 does.
  auto surface_options = [&](const ShapeEntity& s, bool scene_material) {
    SurfaceOptions o;
    int i = material_index(s);
    if (i >= 0 && scene_material) {
      o.detail = material_detail[i];
      o.tangent_frame = material_anisotropic[i];
    }
    o.cutout = shape_alpha(s.params, s.base_dir, out.texture_table);
    return o;
  };
  auto invisible = [](const SurfaceOptions& o) { return o.cutout.alpha.is_constant() && o.cutout.alpha.constant() <= 0.f; };
  auto material_of = [&](const ShapeEntity& s) -> const Bsdf* {
    if (s.material >= 0) return out.bsdfs[s.material].get();
    if (!s.material_name.empty()) {
      auto it = desc.named_materials.find(s.material_name);
      if (it == desc.named_materials.end())
        throw Error(s.material_loc, fmt::format("named material '{}' is not defined", s.material_name));
      return out.bsdfs[it->second].get();
    }
    if (!default_bsdf) {
      CreateContext ctx{default_params, s.loc, {}};
      ctx.spectral = out.spectral;
      out.bsdfs.push_back(registry.create<Bsdf>(PluginKind::Bsdf, kDefaultMaterial, default_params, ctx, s.loc));
      default_bsdf = out.bsdfs.back().get();
    }
    return default_bsdf;
  };

  // glTF materials become Disney materials with the factors of pbrMetallicRoughness.
  auto gltf_bsdf = [&](const GltfMaterial& m, const FileLoc& loc) -> const Bsdf* {
    ParamSet p;
    p.add(Param{"rgb", "color", loc, {m.base_color.r, m.base_color.g, m.base_color.b}, {}, {}});
    p.add(Param{"float", "metallic", loc, {m.metallic}, {}, {}});
    p.add(Param{"float", "roughness", loc, {m.roughness}, {}, {}});
    CreateContext ctx{p, loc, {}};
    ctx.spectral = out.spectral;
    out.bsdfs.push_back(registry.create<Bsdf>(PluginKind::Bsdf, "disney", p, ctx, loc));
    return out.bsdfs.back().get();
  };

  // Shapes and the area lights on them.
  out.scene = std::make_unique<EmbreeScene>();
  std::vector<const Light*> all_lights, infinite_lights;
  // `shape_area`: the whole shape's (a mesh's triangles together), for pbrt-v4's "power".
  auto make_area_light = [&](const ShapeEntity& s, const Shape* shape, float shape_area) -> const Light* {
    SceneEntity& a = desc.area_lights[s.area_light];
    CreateContext ctx{a.params, {}, a.base_dir, a.to_world, shape};
    ctx.reverse_orientation = s.reverse_orientation;
    ctx.shape_area = shape_area;
    auto light = registry.create<Light>(PluginKind::Light, a.type, a.params, ctx, a.loc);
    if (light->type() != LightType::Area)
      throw Error(a.loc, fmt::format("light '{}' is not an area light", a.type));
    out.lights.push_back(std::move(light));
    all_lights.push_back(out.lights.back().get());
    return out.lights.back().get();
  };
  MediaTable media(desc);
  std::vector<std::unique_ptr<Shape>> light_shapes;
  // The shape an emitter samples: with an alpha cut-out, wrapped so that it emits only where the
  // surface is there (cutout_shape.h).
  auto emitter_shape = [&](const Shape* shape, const SurfaceOptions& o) -> const Shape* {
    if (!o.cutout.active()) return shape;
    light_shapes.push_back(std::make_unique<CutoutShape>(*shape, o.cutout));
    return light_shapes.back().get();
  };
  auto add_mesh = [&](const ShapeEntity& s, std::unique_ptr<TriangleMesh> mesh, const Bsdf* bsdf,
                      bool is_textured, bool scene_material = true) {
    SurfaceOptions options = surface_options(s, scene_material);
    if (invisible(options)) return;
    std::vector<const Light*> lights;
    if (s.area_light >= 0) {
      float total_area = 0.f;
      for (uint32_t i = 0; i < mesh->triangle_count(); ++i) total_area += mesh->area(i);
      for (uint32_t i = 0; i < mesh->triangle_count(); ++i) {
        if (mesh->area(i) <= 0.f) {  // degenerate: never hit, never sampled
          lights.push_back(nullptr);
          continue;
        }
        light_shapes.push_back(std::make_unique<Triangle>(mesh.get(), i));
        lights.push_back(make_area_light(s, emitter_shape(light_shapes.back().get(), options), total_area));
      }
    }
    out.scene->add_mesh(std::move(mesh), bsdf, std::move(lights), is_textured, media.interface_of(s), options);
  };
  auto add_shape = [&](ShapeEntity& s) {
    if (!material_of(s)) {  // "interface": no surface, rays pass
      if (s.area_light >= 0) throw Error(s.loc, "an area light on a shape with material 'interface' is not supported");
      if (media.interface_of(s).is_transition())
        throw Error(s.loc, "a shape with material 'interface' that bounds a medium is not supported yet (give it a "
                           "dielectric material with eta 1 to bound the medium)");
      return;
    }
    if (s.type == "trianglemesh" || s.type == "plymesh" || s.type == "loopsubdiv" || s.type == "bilinearmesh") {
      const Bsdf* bsdf = material_of(s);
      add_mesh(s, load_mesh(s), bsdf, textured(s));
    } else if (s.type == "gltf") {
      s.params.validate(kGltfParams, "shape 'gltf'");
      FileLoc loc = s.params.has("filename") ? s.params.loc_of("filename") : s.loc;
      std::string file = s.params.get_string("filename");
      if (file.empty()) throw Error(s.loc, "shape 'gltf' needs \"string filename\"");
      for (GltfPrimitive& g : load_gltf(resolve(s.base_dir, file), loc)) {
        const Bsdf* bsdf = g.material ? gltf_bsdf(*g.material, s.loc) : material_of(s);
        add_mesh(s, make_mesh(s, std::move(g.P), std::move(g.indices), std::move(g.N), std::move(g.uv), loc, loc, loc), bsdf,
                 !g.material && textured(s), !g.material);
      }
    } else if (s.type == "sphere") {
      const Bsdf* bsdf = material_of(s);
      std::unique_ptr<Sphere> sphere = load_sphere(s);
      SurfaceOptions options = surface_options(s, true);
      if (invisible(options)) return;
      const Light* light =
          s.area_light >= 0 ? make_area_light(s, emitter_shape(sphere.get(), options), sphere->area()) : nullptr;
      out.scene->add_sphere(std::move(sphere), bsdf, light, textured(s), media.interface_of(s), options);
    } else if (s.type == "disk" || s.type == "cylinder") {
      const Bsdf* bsdf = material_of(s);
      std::unique_ptr<Quadric> quadric = load_quadric(s);
      SurfaceOptions options = surface_options(s, true);
      if (invisible(options)) return;
      const Light* light = nullptr;
      if (s.area_light >= 0) {
        if (!quadric->area_is_uniform())
          throw Error(s.loc, "a cylinder area light whose transform stretches its cross-section unevenly is not "
                             "supported (its emission could not be sampled uniformly by area)");
        light = make_area_light(s, emitter_shape(quadric.get(), options), quadric->area());
      }
      out.scene->add_quadric(std::move(quadric), bsdf, light, textured(s), media.interface_of(s), options);
    } else if (s.type == "curve") {
      if (s.area_light >= 0)
        throw Error(s.loc, "an area light on a curve is not supported (pbrt-v4 cannot sample curves either)");
      const Bsdf* bsdf = material_of(s);
      auto curves = std::make_unique<Curves>(load_curves(s));
      SurfaceOptions options = surface_options(s, true);
      out.scene->add_curves(std::move(curves), bsdf, textured(s), media.interface_of(s), options);
    } else {
      throw Error(s.loc, fmt::format("unsupported shape '{}'; available: bilinearmesh, curve, cylinder, disk, gltf, loopsubdiv, plymesh, sphere, "
                                     "trianglemesh",
                                     s.type));
    }
  };
  for (auto& s : desc.shapes)
    if (s.object < 0) add_shape(s);
  // Object instancing: each object's shapes become one Embree prototype, placed by its instances.
  std::vector<int> prototype_of(desc.objects.size(), -1);
  for (size_t k = 0; k < desc.objects.size(); ++k) {
    prototype_of[k] = out.scene->begin_prototype();
    for (auto& s : desc.shapes) {
      if (s.object != static_cast<int>(k)) continue;
      if (s.area_light >= 0)
        throw Error(s.loc, fmt::format("an area light in object '{}' (ObjectBegin at {}) is not supported, as in "
                                       "pbrt-v4: instanced shapes cannot emit",
                                       desc.objects[k].name, desc.objects[k].loc.str()));
      add_shape(s);
    }
    out.scene->end_prototype();
  }
  for (const InstanceEntity& inst : desc.instances) {
    auto it = std::find_if(desc.objects.begin(), desc.objects.end(),
                           [&](const ObjectEntity& o) { return o.name == inst.name; });
    if (it == desc.objects.end())
      throw Error(inst.loc, fmt::format("ObjectInstance of '{}', which no ObjectBegin defines", inst.name));
    out.scene->add_instance(prototype_of[it - desc.objects.begin()], inst.to_world);
  }
  if (!desc.instances.empty()) out.structures_built.push_back("embree_instances");
  out.scene->adopt_shapes(std::move(light_shapes));
  if (!media.sigma_a().empty()) out.structures_built.push_back("absorbing_media");
  out.scene->set_media(media.sigma_a());

  for (auto& l : desc.lights) {
    auto light = registry.create<Light>(PluginKind::Light, l.type, l.params,
                                        CreateContext{l.params, {}, l.base_dir, l.to_world}, l.loc);
    if (light->type() == LightType::Area)
      throw Error(l.loc, fmt::format("'{}' is an area light: use AreaLightSource", l.type));
    if (light->type() == LightType::Infinite) infinite_lights.push_back(light.get());
    out.lights.push_back(std::move(light));
    all_lights.push_back(out.lights.back().get());
  }

  out.scene->set_camera(std::move(camera));
  out.scene->commit();
  out.structures_built.push_back("embree_scene");
  Bounds3 b = out.scene->bounds();
  bool empty = b.min.x > b.max.x;
  Vec3 center = empty ? Vec3(0.f) : 0.5f * (b.min + b.max);
  float radius = empty ? 1.f : std::max(1e-3f, 0.5f * glm::length(b.max - b.min));
  for (auto& light : out.lights) light->preprocess(center, radius);
  out.scene->set_lights(all_lights, infinite_lights);
  if (!all_lights.empty()) out.structures_built.push_back("light_power_distribution");
  auto collect = [&](const Object& o) {
    for (auto& name : o.structures_built())
      if (std::find(out.structures_built.begin(), out.structures_built.end(), name) == out.structures_built.end())
        out.structures_built.push_back(name);
  };
  for (auto& l : out.lights) collect(*l);
  for (auto& m : out.bsdfs)
    if (m) collect(*m);
  return out;
}

}  // namespace penumbra
