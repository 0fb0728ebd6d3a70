// Whole renders with spectral transport (--spectral, docs/spectral.md). One bounce off a surface
// under a white sky has the colour of its reflectance in both transports (the spectrum's colour under
// D65 is the RGB given), so the spectral image must equal the RGB one within its noise; two or more
// bounces off a saturated coated surface must not (the spectral effect the transport is for). And
// what does not support spectral transport yet says so before rendering.
#include "render/render_session.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

using namespace penumbra;
using namespace penumbra::test;

namespace {

// A sphere of `material` under a white constant sky: the sky seen directly (1) around it.
std::string sphere_scene(const std::string& material) {
  return "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [30]\n"
         "Film \"rgb\" \"integer xresolution\" [32] \"integer yresolution\" [32]\n"
         "Sampler \"independent\" \"integer pixelsamples\" [64]\nIntegrator \"path\" \"integer maxdepth\" [5]\n"
         "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n" +
         material + "\nShape \"sphere\" \"float radius\" [1.5]\n";
}

ImageRgb render_file(const std::string& file, bool spectral, int seed, int spp) {
  RenderSettings s;
  s.scene_file = file;
  s.output = "";
  s.spp = spp;
  s.seed = static_cast<uint32_t>(seed);
  s.spectral = spectral;
  s.quiet = true;
  s.threads = 2;
  return render(s).image;
}

TEST(SpectralRender, OneBounceKeepsTheColourOfASaturatedReflectance) {
  std::string dir = temp_dir("spectral-one-bounce");
  std::string file = write_file(dir, "scene.pbrt", sphere_scene("Material \"diffuse\" \"rgb reflectance\" [1 0.378676 0.013473]"));
  ImageRgb rgb = render_file(file, false, 1, 64);  // a convex diffuse sphere under a uniform sky: exact
  for (int c = 0; c < 3; ++c) {
    SeedMean spectral = mean_over_seeds(4, [&](int seed) { return mean_channel(render_file(file, true, seed, 128), c); });
    double expected = mean_channel(rgb, c);
    double tol = 4.0 * spectral.standard_error + 3e-3 * expected;  // noise, and the table's 2.6e-3
    std::printf("channel %d: spectral %.5f +- %.5f, RGB %.5f\n", c, spectral.mean, spectral.standard_error, expected);
    EXPECT_NEAR(spectral.mean, expected, tol);
    // Negative control: 2 % brighter or darker is told apart.
    EXPECT_GT(std::abs(1.02 * spectral.mean - expected), tol);
    EXPECT_GT(std::abs(0.98 * spectral.mean - expected), tol);
  }
}

TEST(SpectralRender, InterreflectionInsideAColouredCoatIsSpectral) {
  // pbrt-v4's coffee scene's orange under a coat: light bounces between base and coat, so the base
  // reflectance enters as a^2, a^3, ...; the spectrum's powers fall faster in red than the red
  // channel's (docs/pbrt-v4-comparison.md measured RGB +9 % against pbrt-v4 in the coffee scene).
  std::string dir = temp_dir("spectral-coat");
  std::string file = write_file(dir, "scene.pbrt", sphere_scene("Material \"coateddiffuse\" \"rgb reflectance\" "
                                                               "[1 0.378676 0.013473] \"float roughness\" [0]"));
  SeedMean rgb = mean_over_seeds(4, [&](int seed) { return mean_channel(render_file(file, false, seed, 64), 0); });
  SeedMean spectral = mean_over_seeds(4, [&](int seed) { return mean_channel(render_file(file, true, seed, 64), 0); });
  std::printf("red: RGB %.5f +- %.5f, spectral %.5f +- %.5f\n", rgb.mean, rgb.standard_error, spectral.mean,
              spectral.standard_error);
  EXPECT_LT(spectral.mean, rgb.mean - 4.0 * (rgb.standard_error + spectral.standard_error));
}

TEST(SpectralRender, WhatDoesNotSupportItYetIsRefusedBeforeRendering) {
  std::string dir = temp_dir("spectral-refused");
  std::string file = write_file(dir, "scene.pbrt", sphere_scene("Material \"diffuse\""));
  for (const char* integrator : {"bdpt", "lighttracing", "sppm"}) {
    CommandResult r = run_penumbra({"render", file, "--spectral", "--integrator", integrator, "-o", dir + "/x.exr"});
    EXPECT_EQ(r.exit_code, 1) << integrator;
    EXPECT_THAT(r.err, ::testing::HasSubstr(std::string("--spectral: integrator '") + integrator +
                                            "' does not support spectral transport yet"));
  }
  std::string disney = write_file(dir, "disney.pbrt", sphere_scene("Material \"disney\""));
  CommandResult r = run_penumbra({"render", disney, "--spectral", "-o", dir + "/x.exr"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, ::testing::HasSubstr("disney.pbrt:8:1: error: material 'disney' does not support spectral"));
  // The scene can ask for it itself.
  std::string in_film = sphere_scene("Material \"diffuse\"");
  in_film.replace(in_film.find("Film \"rgb\""), 10, "Film \"rgb\" \"bool spectral\" [true]");
  std::string film_file = write_file(dir, "film.pbrt", in_film);
  CommandResult bdpt = run_penumbra({"render", film_file, "--integrator", "bdpt", "-o", dir + "/x.exr"});
  EXPECT_EQ(bdpt.exit_code, 1);
  EXPECT_THAT(bdpt.err, ::testing::HasSubstr("film.pbrt:3:"));
}

}  // namespace
