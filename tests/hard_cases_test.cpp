// Hard cases (CTest label "hard"): tiny scenes that break careless renderers, rendered by every
// integrator with every sampler at low resolution. Each render must finish, contain no NaN, Inf or
// negative value, discard no non-finite sample, and, where the answer is known, hit it.
#include "image/image_io.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <functional>

using namespace penumbra;
using namespace penumbra::test;

namespace {

struct HardCase {
  std::string name;
  std::string world;          // scene text after WorldBegin
  std::string camera = "LookAt 0 1 4  0 0.5 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 40 ]";
  std::string integrator_params;  // e.g. "\"integer maxdepth\" [ 0 ]"
  double expected_mean = -1;  // mean over pixels and channels when known
  double tolerance = 0;       // relative
};

// Expected answers: a closed sphere of albedo a emitting Le has radiance Le * sum_{k<=D} a^k inside.
std::string furnace_world(float a) {
  return fmt::format("Material \"diffuse\" \"rgb reflectance\" [ {0} {0} {0} ]\nAreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\n"
                     "ReverseOrientation\nShape \"sphere\" \"float radius\" [ 2 ]\n", a);
}

const char* kFloorAndLight = R"(
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 2 1  0 3 2 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 5 5 5 ]
  Shape "trianglemesh" "point3 P" [ -0.5 3 -0.5  0.5 3 -0.5  0.5 3 0.5  -0.5 3 0.5 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
)";

std::string sphere_with(const std::string& material) {
  return std::string(kFloorAndLight) + "AttributeBegin\n" + material + "\nTranslate 0 0.5 0\nShape \"sphere\" \"float radius\" [ 0.5 ]\nAttributeEnd\n";
}

std::vector<HardCase> hard_cases(const std::string& dir) {
  std::vector<HardCase> cases;
  // Depth conventions and long paths.
  HardCase c0{"maxdepth0", furnace_world(0.5f), "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"", "\"integer maxdepth\" [ 0 ]", 1.0, 0.001};
  HardCase c1{"maxdepth1", furnace_world(0.5f), c0.camera, "\"integer maxdepth\" [ 1 ]", 1.5, 0.03};
  HardCase c100{"maxdepth100", furnace_world(0.5f), c0.camera, "\"integer maxdepth\" [ 100 ]", 2.0, 0.03};
  cases.insert(cases.end(), {c0, c1, c100});
  // The camera inside a closed diffuse box lit by a point light: finite, positive.
  cases.push_back({"camera-inside-closed-object",
                   "LightSource \"point\" \"rgb I\" [ 1 1 1 ] \"point3 from\" [ 0 0.5 0 ]\nMaterial \"diffuse\"\n"
                   "Scale 2 2 2\nInclude \"" + std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/unit-cube.pbrt\"\n",
                   "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\""});
  // Grazing camera and grazing light over a plane.
  cases.push_back({"grazing", R"(
Material "diffuse" "rgb reflectance" [ 0.8 0.8 0.8 ]
Shape "trianglemesh" "point3 P" [ -100 0 -100  100 0 -100  100 0 100  -100 0 100 ] "integer indices" [ 0 2 1  0 3 2 ]
LightSource "distant" "rgb L" [ 3 3 3 ] "point3 from" [ 1 0.0001 0 ] "point3 to" [ 0 0 0 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 10 10 10 ] "bool twosided" true
  Shape "trianglemesh" "point3 P" [ -1 0.001 -3  1 0.001 -3  1 0.02 -3 ] "integer indices" [ 0 1 2 ]
AttributeEnd
)", "LookAt 0 0.001 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 20 ]"});
  // Materials at their limits.
  for (auto [name, mat] : std::vector<std::pair<std::string, std::string>>{
           {"disney-roughness-0", "Material \"disney\" \"float roughness\" [ 0 ] \"float metallic\" [ 0 ]"},
           {"disney-roughness-1e-4", "Material \"disney\" \"float roughness\" [ 0.0001 ]"},
           {"disney-roughness-1", "Material \"disney\" \"float roughness\" [ 1 ] \"float sheen\" [ 1 ]"},
           {"disney-metal-mirror", "Material \"disney\" \"float metallic\" [ 1 ] \"float roughness\" [ 0 ]"},
           // Deltas next to other lobes: mirror + diffuse, smooth glass + diffuse, thin pass-through.
           {"disney-mirror-on-diffuse", "Material \"disney\" \"float metallic\" [ 0.5 ] \"float roughness\" [ 0 ]"},
           {"disney-glass-roughness-0", "Material \"disney\" \"float spectrans\" [ 0.5 ] \"float roughness\" [ 0 ]"},
           {"disney-thin-roughness-0", "Material \"disney\" \"bool thin\" [ true ] \"float spectrans\" [ 0.5 ] \"float roughness\" [ 0 ] \"float difftrans\" [ 1 ]"},
           {"disney-glass-eta-1", "Material \"disney\" \"float spectrans\" [ 1 ] \"float eta\" [ 1 ] \"float roughness\" [ 0 ]"},
           {"disney-glass-eta-1.0001", "Material \"disney\" \"float spectrans\" [ 1 ] \"float eta\" [ 1.0001 ] \"float roughness\" [ 0.0001 ]"},
           {"dielectric-eta-1", "Material \"dielectric\" \"float eta\" [ 1 ]"},
           {"dielectric-eta-1.0001-rough", "Material \"dielectric\" \"float eta\" [ 1.0001 ] \"float roughness\" [ 0.3 ]"},
           {"conductor-mirror", "Material \"conductor\" \"float roughness\" [ 0 ]"},
           {"coateddiffuse", "Material \"coateddiffuse\" \"float roughness\" [ 0 ]"}})
    cases.push_back({name, sphere_with(mat)});
  // A tiny emitter of huge radiance (1e-4 wide) and a point light touching the floor.
  cases.push_back({"tiny-hot-light", R"(
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 2 1  0 3 2 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1e9 1e9 1e9 ]
  Shape "trianglemesh" "point3 P" [ 0 1 0  0.0001 1 0  0 1 0.0001 ] "integer indices" [ 0 2 1 ]
AttributeEnd
)"});
  cases.push_back({"point-light-touching-surface", std::string(kFloorAndLight) +
                   "LightSource \"point\" \"rgb I\" [ 5 5 5 ] \"point3 from\" [ 0.3 0 0.2 ]\n"});
  // Environment maps: one bright texel, and all black (expected image: exactly 0).
  {
    ImageRgb sun, black;
    sun.width = black.width = 32, sun.height = black.height = 16;
    sun.pixels.assign(32 * 16 * 3, 0.05f);
    black.pixels.assign(32 * 16 * 3, 0.f);
    for (int c = 0; c < 3; ++c) sun.pixels[3 * (3 * 32 + 7) + c] = 5e4f;
    write_image(dir + "/sun.exr", sun);
    write_image(dir + "/black.exr", black);
    std::string floor = "Material \"diffuse\"\nShape \"trianglemesh\" \"point3 P\" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] \"integer indices\" [ 0 2 1  0 3 2 ]\n";
    cases.push_back({"environment-one-bright-texel", "AttributeBegin\nRotate -90 1 0 0\nLightSource \"infinite\" \"string filename\" [ \"" + dir +
                     "/sun.exr\" ]\nAttributeEnd\n" + floor});
    cases.push_back({"environment-all-black", "LightSource \"infinite\" \"string filename\" [ \"" + dir + "/black.exr\" ]\n" + floor,
                     HardCase{}.camera, "", 0.0, 0.0});
  }
  // Degenerate and zero-area triangles next to a valid one, lit.
  cases.push_back({"degenerate-triangles", std::string(kFloorAndLight) + R"(
Shape "trianglemesh" "point3 P" [ 0 1 0  0 1 0  0 1 0   1 1 0  2 1 0  3 1 0   -1 0.5 0  -0.5 0.5 0  -1 1 0 ]
  "integer indices" [ 0 1 2  3 4 5  6 7 8 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 3 3 3 ]
  Shape "trianglemesh" "point3 P" [ 0 2 0  1 2 0  2 2 0   0 2.5 0  0 2.5 0  0.5 2.5 0.2 ] "integer indices" [ 0 1 2  3 4 5 ]
AttributeEnd
)"});
  return cases;
}

std::vector<std::string> integrators() {
  Registry r(Registry::default_search_dirs());
  return r.available(PluginKind::Integrator);
}

// An integrator plugin with extra parameters: "bdpt+hrr+pc" is bdpt with its cached techniques on.
struct Variant {
  std::string label, plugin, params;
};
std::vector<Variant> variants() {
  std::vector<Variant> out;
  for (const std::string& name : integrators()) {
    out.push_back({name, name, ""});
    if (name == "bdpt") {
      out.push_back({"bdpt+hrr", name, "\"bool hrr\" true \"float hrrmaxalpha\" 1"});
      out.push_back({"bdpt+hrr+pc", name, "\"bool hrr\" true \"float hrrmaxalpha\" 1 \"bool probconnect\" true \"integer pcrecords\" 16"});
    }
  }
  return out;
}

// Failures of one render, as text (empty: it passed). The guards under test: discarding non-finite
// samples before the film, and producing no negative radiance.
std::string check_render(const RenderResult& r, const HardCase& c) {
  std::string problems;
  int nonfinite = count_nonfinite(r.image), negative = 0;
  for (float v : r.image.pixels) negative += v < 0.f;
  if (nonfinite) problems += fmt::format("{} non-finite pixel values; ", nonfinite);
  if (negative) problems += fmt::format("{} negative pixel values; ", negative);
  if (r.stats.nonfinite_samples) problems += fmt::format("{} non-finite samples discarded; ", r.stats.nonfinite_samples);
  if (c.expected_mean >= 0) {
    double m = mean_luminance_free(r.image);
    double tol = c.expected_mean == 0 ? 0.0 : c.tolerance * c.expected_mean;
    if (std::abs(m - c.expected_mean) > tol)
      problems += fmt::format("mean {} instead of {} (tolerance {}); ", m, c.expected_mean, tol);
  }
  return problems;
}

RenderResult render_case(const HardCase& c, const std::string& dir, const Variant& integrator, const std::string& sampler,
                         int spp = 16) {
  std::string scene = c.camera + "\nFilm \"rgb\" \"integer xresolution\" [ 16 ] \"integer yresolution\" [ 16 ]\nPixelFilter \"box\"\n"
                      "Integrator \"" + integrator.plugin + "\" " + c.integrator_params + " " + integrator.params +
                      "\nWorldBegin\n" + c.world;
  RenderSettings s;
  s.scene_file = write_file(dir, c.name + "-" + integrator.label + ".pbrt", scene);
  s.sampler = sampler;
  s.spp = spp;
  s.seed = 7;
  s.quiet = true;
  return render(s);
}

}  // namespace

TEST(HardCases, EveryIntegratorAndSamplerStaysFiniteAndCorrect) {
  std::string dir = temp_dir("hard");
  std::vector<HardCase> cases = hard_cases(dir);
  std::vector<Variant> ints = variants();
  ASSERT_FALSE(ints.empty());
  int renders = 0;
  for (const HardCase& c : cases)
    for (const Variant& integrator : ints)
      for (const char* sampler : {"independent", "halton", "sobol"}) {
        // Light tracing cannot see emitters directly and photon mapping is biased at low iteration
        // counts: their means are checked only where the case says nothing.
        HardCase checked = c;
        if ((integrator.plugin == "lighttracing" || integrator.plugin == "sppm") && c.expected_mean > 0)
          checked.expected_mean = -1;
        RenderResult r;
        try {
          r = render_case(c, dir, integrator, sampler);
        } catch (const Error& e) {
          ADD_FAILURE() << c.name << " / " << integrator.label << " / " << sampler << ": " << e.formatted();
          continue;
        }
        std::string problems = check_render(r, checked);
        EXPECT_TRUE(problems.empty()) << c.name << " / " << integrator.label << " / " << sampler << ": " << problems;
        ++renders;
      }
  std::printf("hard cases: %zu cases x %zu integrators x 3 samplers = %d renders\n", cases.size(), ints.size(), renders);
}

// Geometry far from the origin and at a tiny scale renders like the same scene at unit scale near
// the origin: self-intersection acne would darken it.
TEST(HardCases, FarAndTinyGeometryMatchesTheSceneNearTheOrigin) {
  std::string dir = temp_dir("hard-scale");
  // The same scene and camera, translated by (1e5, 1e5, -1e5) or scaled by 1e-4.
  auto mean_of = [&](const HardCase& c) { return mean_luminance_free(render_case(c, dir, Variant{"path", "path", ""}, "sobol", 1024).image); };
  HardCase near{"scaled", sphere_with("Material \"diffuse\" \"rgb reflectance\" [ 0.7 0.7 0.7 ]")};
  near.camera = "LookAt 0 1 4  0 0.5 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 40 ]";
  double m0 = mean_of(near);
  HardCase far = near, tiny = near;
  far.world = "AttributeBegin\nTranslate 1e5 1e5 -1e5\n" + sphere_with("Material \"diffuse\" \"rgb reflectance\" [ 0.7 0.7 0.7 ]") + "AttributeEnd\n";
  far.camera = "LookAt 100000 100001 -99996  100000 100000.5 -100000  0 1 0\nCamera \"perspective\" \"float fov\" [ 40 ]";
  tiny.world = "AttributeBegin\nScale 1e-4 1e-4 1e-4\n" + sphere_with("Material \"diffuse\" \"rgb reflectance\" [ 0.7 0.7 0.7 ]") + "AttributeEnd\n";
  tiny.camera = "LookAt 0 0.0001 0.0004  0 0.00005 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 40 ]";
  double m_far = mean_of(far), m_tiny = mean_of(tiny);
  EXPECT_NEAR(m_far, m0, 0.03 * m0) << "far from the origin";
  EXPECT_NEAR(m_tiny, m0, 0.03 * m0) << "at scale 1e-4";
}

// The checks have teeth: an image with a NaN, or a negative value, or a wrong mean, is reported.
TEST(HardCases, CheckerReportsTheFailuresItGuardsAgainst) {
  RenderResult r;
  r.image.width = 2, r.image.height = 1;
  r.image.pixels = {1, 1, 1, 1, 1, 1};
  HardCase c;
  c.expected_mean = 1.0;
  c.tolerance = 0.01;
  EXPECT_EQ(check_render(r, c), "");
  r.image.pixels[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(check_render(r, c).find("1 non-finite pixel values"), std::string::npos);
  r.image.pixels[0] = -1.f;
  EXPECT_NE(check_render(r, c).find("1 negative pixel values"), std::string::npos);
  r.image.pixels[0] = 1.f;
  r.stats.nonfinite_samples = 3;
  EXPECT_NE(check_render(r, c).find("3 non-finite samples discarded"), std::string::npos);
  r.stats.nonfinite_samples = 0;
  c.expected_mean = 2.0;
  EXPECT_NE(check_render(r, c).find("mean 1 instead of 2"), std::string::npos);
}

// Firefly guard: the stats count samples above the threshold, for every integrator, without
// clamping them. A 1e9-radiance pinpoint light seen directly produces them; a dim scene does not.
TEST(HardCases, FireflySamplesAreCountedPerIntegrator) {
  std::string dir = temp_dir("hard-fireflies");
  std::string hot = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 10 ]\n"
                    "Film \"rgb\" \"integer xresolution\" [ 8 ] \"integer yresolution\" [ 8 ]\nWorldBegin\n"
                    "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 1e9 1e9 1e9 ]\nShape \"sphere\" \"float radius\" [ 0.2 ]\nAttributeEnd\n";
  for (const std::string& integrator : integrators()) {
    RenderSettings s;
    s.scene_file = write_file(dir, "hot.pbrt", hot);
    s.integrator = integrator;
    s.spp = 4;
    s.quiet = true;
    s.firefly_threshold = 1e6f;
    RenderResult r = render(s);
    if (integrator != "lighttracing") EXPECT_GT(r.stats.firefly_samples, 0u) << integrator;
    s.firefly_threshold = 1e12f;
    EXPECT_EQ(render(s).stats.firefly_samples, 0u) << integrator;
  }
}
