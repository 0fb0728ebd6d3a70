// Hair on curves (plugins/bsdfs/hair on core/src/scene/curves.*) rendered and compared with
// pbrt-v4's images of the same files: a strand in the shadow of others, strands lit from one side, a
// head of 24 strands as flat and cylinder strands; and with every integrator (docs/hair.md).
#include "render/render_session.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <regex>

using namespace penumbra;
using namespace penumbra::test;

namespace {

struct RenderMean {
  double mean, standard_error;  // relative standard error
};

// Mean over `seeds` renders (all three channels) of scene text `scene`.
RenderMean render_mean(const std::string& scene, const std::string& name, int seeds,
                       const std::string& integrator = "", std::optional<std::pair<int, int>> res = std::nullopt,
                       std::optional<int> spp = std::nullopt) {
  std::string file = write_file(temp_dir(name), "scene.pbrt", scene);
  SeedMean m = mean_over_seeds(seeds, [&](int seed) {
    RenderSettings s;
    s.scene_file = file;
    s.quiet = true;
    s.seed = static_cast<uint32_t>(seed);
    s.image_written = false;
    s.integrator = integrator;
    s.resolution = res;
    s.spp = spp;
    RenderResult r = render(s);
    EXPECT_EQ(count_nonfinite(r.image), 0) << integrator;
    return mean_luminance_free(r.image);
  });
  return {m.mean, m.standard_error / m.mean};
}

// Against a pbrt-v4 mean with its own relative standard error: 4 combined standard errors, which must
// stay below 2 %, and a pbrt-v4 mean 2 % off is rejected.
void expect_agrees_with_pbrt(const RenderMean& m, double pbrt, double pbrt_se, const char* what) {
  double tol = 4.0 * std::sqrt(m.standard_error * m.standard_error + pbrt_se * pbrt_se);
  std::printf("[ measured ] %s: Penumbra %.6f, pbrt-v4 %.6f, ratio %.4f (tolerance %.2f %%)\n", what, m.mean, pbrt,
              m.mean / pbrt, 100.0 * tol);
  EXPECT_NEAR(m.mean / pbrt, 1.0, tol) << what;
  EXPECT_LT(tol, 0.02) << what;
  EXPECT_GT(std::abs(m.mean / (1.02 * pbrt) - 1.0), tol) << what;  // negative control
}

const char* const kShadowedStrand = R"(LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" [ 64 ] "integer yresolution" [ 64 ]
Sampler "independent" "integer pixelsamples" [ 128 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
LightSource "distant" "point3 from" [ 0.3 0 -2 ] "point3 to" [ 0 0 0 ] "rgb L" [ 3 3 3 ]
Material "hair" "rgb sigma_a" [ 0.6 0.6 0.6 ] "float beta_m" [ 0.3 ] "float beta_n" [ 0.3 ]
Shape "curve" "point3 P" [ -0.8 0 0  -0.3 0 0  0.3 0 0  0.8 0 0 ] "float width" [ 0.2 ]
Shape "curve" "point3 P" [ -0.8 0.02 -0.3  -0.3 0.02 -0.3  0.3 0.02 -0.3  0.8 0.02 -0.3 ] "float width" [ 0.2 ]
Shape "curve" "point3 P" [ 0.1 -0.8 -0.3  0.1 -0.3 -0.3  0.1 0.3 -0.3  0.1 0.8 -0.3 ] "float width" [ 0.2 ]
)";

std::string hair_scene(bool grey) {
  std::string text = read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/curves/hair.pbrt");
  if (grey)
    text = std::regex_replace(text, std::regex(R"(Material "hair" "float eumelanin" \[ 0.3 \])"),
                              R"(Material "hair" "rgb sigma_a" [ 0.6 0.6 0.6 ])");
  return text;
}

}  // namespace

// A hair strand lit from behind, in the shadow of two strands 1.5 widths behind it (only its lower
// edge gets light): pbrt-v4 at 64x64, 128 spp, seeds 1-4 (`pbrt --nthreads 2 --seed S --outfile o.exr
// scene.pbrt`, mean of the channels) gives 0.105706 (standard error 0.23 %). Before rays near a strand
// were started further back (Curves.StrandsCloseToTheRayOriginAreHit) Penumbra gave 0.162.
TEST(HairRender, ShadowedStrandAgreesWithPbrtV4) {
  RenderMean m = render_mean(kShadowedStrand, "hair-shadowed", 8);
  expect_agrees_with_pbrt(m, 0.105706, 0.0023, "shadowed strand");
}

// The same three strands lit from the front and one side only, where the highlights of the front
// strand fall on one of its sides and the strands behind it are partly in its shadow: pbrt-v4 at
// 64x64, 512 spp, seeds 1-4 gives 0.0028425 (standard error 0.11 %). With v (and so h) mirrored
// across each strand Penumbra gave 0.973 of that.
TEST(HairRender, StrandsLitFromOneSideAgreeWithPbrtV4) {
  std::string scene = std::regex_replace(std::string(kShadowedStrand), std::regex(R"(LightSource "distant".*\n)"),
                                         "LightSource \"distant\" \"point3 from\" [ 1 1 2 ] \"point3 to\" [ 0 0 0 ] \"rgb L\" [ 2 2 2 ]\n");
  RenderMean m = render_mean(scene, "hair-one-side", 4, "", std::nullopt, 512);
  expect_agrees_with_pbrt(m, 0.0028425, 0.0011, "three strands lit from one side");
}

// scenes/curves/hair.pbrt, 24 bent strands lit from both sides, with grey absorption (so that
// pbrt-v4's spectral rendering does not enter), as flat strands and as the file has them (cylinders).
// pbrt-v4 at 64x64, 512 spp, seeds 1-4: flat 0.055913 (standard error 0.11 %), cylinder 0.054353
// (0.16 %). The cylinders' turned normals change where rays leave the strands: pbrt-v4 turns them
// the other way from a real tube's (docs/hair.md), and so must Penumbra to agree (with outward normals
// its cylinder image equalled its flat one, 1.03 of pbrt-v4's). Before v ran across strands in
// pbrt-v4's direction the flat mean was also off by 0.9 %.
TEST(HairRender, HeadOfHairAgreesWithPbrtV4) {
  std::string flat = std::regex_replace(hair_scene(true), std::regex(R"("string type" "cylinder")"), R"("string type" "flat")");
  RenderMean m = render_mean(flat, "hair-grey-flat", 4, "", std::make_pair(64, 64), 512);
  expect_agrees_with_pbrt(m, 0.055913, 0.0011, "24 flat strands, grey");
  RenderMean cylinder = render_mean(hair_scene(true), "hair-grey-cylinder", 4, "", std::make_pair(64, 64), 512);
  expect_agrees_with_pbrt(cylinder, 0.054353, 0.0016, "24 cylinder strands, grey");
}

// Every integrator renders hair without NaN or infinity. Only sppm is held to agree with path: on
// hair (no diffuse surface) its camera paths are a path tracer with the same next-event estimation
// (8 seeds each, 4 combined standard errors asserted below 2 %, a 2 % offset rejected; with 4 seeds the
// seeds' own estimate of the standard error scattered so widely that it once came out at 2.1 %). bdpt and
// light tracing reach a strand from the light, where the ray-facing ribbon faces the light ray and
// not the camera ray, so their estimates of ray-facing strands differ from path's by several percent
// (here +7 % and +4 %), as pbrt-v4's bdpt differs from its path (+4.9 % on this scene, 64x64, 1024 spp).
TEST(HairRender, EveryIntegratorRendersHairAndSppmAgreesWithPath) {
  std::string scene = std::regex_replace(std::string(kShadowedStrand), std::regex(R"(Camera "orthographic")"),
                                         R"(Camera "perspective" "float fov" [ 30 ])");
  scene = std::regex_replace(scene, std::regex(R"("integer maxdepth" \[ 1 \])"), R"("integer maxdepth" [ 4 ])");
  scene += "LightSource \"distant\" \"point3 from\" [ 1 1 2 ] \"point3 to\" [ 0 0 0 ] \"rgb L\" [ 2 2 2 ]\n";
  for (const char* integrator : {"bdpt", "lighttracing"}) {
    RenderMean m = render_mean(scene, std::string("hair-") + integrator, 2, integrator, std::make_pair(24, 24), 64);
    EXPECT_GT(m.mean, 0.0) << integrator;
  }
  const auto res = std::make_pair(24, 24);
  RenderMean path = render_mean(scene, "hair-path", 8, "path", res, 4096);
  RenderMean sppm = render_mean(scene, "hair-sppm", 8, "sppm", res, 4096);
  double tol = 4.0 * std::sqrt(sqr(sppm.standard_error) + sqr(path.standard_error));
  std::printf("[ measured ] sppm / path: %.4f (tolerance %.2f %%; standard errors: sppm %.2f %%, path %.2f %%)\n",
              sppm.mean / path.mean, 100.0 * tol, 100.0 * sppm.standard_error, 100.0 * path.standard_error);
  EXPECT_LT(tol, 0.02);
  EXPECT_NEAR(sppm.mean / path.mean, 1.0, tol);
  EXPECT_GT(std::abs(sppm.mean / (1.02 * path.mean) - 1.0), tol);
}
