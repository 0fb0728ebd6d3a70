// A whole render with named spectra against pbrt-v4: scenes/spectra/gold-sphere.pbrt (a rough gold
// conductor given as "metal-Au-eta"/"metal-Au-k", a D65 sky given as "stdillum-D65", a 3200 K
// blackbody area light) rendered by Penumbra and compared with pbrt-v4's image means.
//
// pbrt-v4's means were made with pbrt-v4 (mmp/pbrt-v4 at 5f7a606, CPU build), from scenes/spectra:
//   pbrt --nthreads 2 --spp 1024 --seed 1 --outfile ref.exr gold-sphere.pbrt
//   oiiotool ref.exr --ch R,G,B --printstats        (Stats Avg)
// giving 0.395421 0.358707 0.311295 over the 96x72 image.
#include "render/render_session.h"
#include "support/image_stats.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr double kPbrtMeans[3] = {0.395421, 0.358707, 0.311295};

// pbrt-v4 renders spectrally; Penumbra converts each spectrum to RGB once. Measured ratios
// Penumbra / pbrt-v4 at 1024 spp: R 0.9916, G 1.0048, B 1.0049 (at 64 spp, this test's count, the
// same to 3e-4: the sampling noise of a 96x72 mean is far smaller). The difference is the
// non-linearity of Fresnel: the RGB of the reflectance of the spectral n + ik is not the Fresnel
// reflectance of the RGB of n and of k (gold reflects 3 % less red and 5 % more blue over the sphere
// alone; docs/scene-format.md). The tolerance, 1 %, is the measured 0.84 % plus margin, and a 2 %
// error in either direction would fail it in some channel (checked below).
constexpr double kTolerance = 0.01;

TEST(SpectraRender, GoldSphereMatchesPbrtV4Means) {
  RenderSettings s;
  s.scene_file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/spectra/gold-sphere.pbrt";
  s.output = "";
  s.spp = 64;
  s.quiet = true;
  RenderResult r = render(s);
  ASSERT_EQ(count_nonfinite(r.image), 0);
  double ratio[3];
  for (int c = 0; c < 3; ++c) {
    ratio[c] = mean_channel(r.image, c) / kPbrtMeans[c];
    EXPECT_NEAR(ratio[c], 1.0, kTolerance) << "channel " << c;
  }
  std::printf("Penumbra / pbrt-v4 means: R %.4f G %.4f B %.4f\n", ratio[0], ratio[1], ratio[2]);
  // Negative control: an image 2 % too bright or too dark fails in at least one channel.
  for (double scale : {0.98, 1.02}) {
    bool fails = false;
    for (int c = 0; c < 3; ++c) fails |= std::abs(ratio[c] * scale - 1.0) > kTolerance;
    EXPECT_TRUE(fails) << scale;
  }
}

// The real scene that needed named spectra: coffee (Bitterli, CC-BY) uses "metal-Ag-eta"/"metal-Ag-k".
// It loads unchanged and renders without NaN/Inf with each integrator at low resolution. (At 160x200,
// 64 spp, Penumbra / pbrt-v4 is R 1.091, G 0.993, B 1.016 with the layered coateddiffuse; the red is
// the saturated orange base, see docs/materials.md. With coateddiffuse replaced by diffuse in both
// renderers it was R 1.005, G 1.000, B 1.001.)
TEST(SpectraRender, CoffeeSceneLoadsAndRenders) {
  for (const char* integrator : {"path", "bdpt", "sppm"}) {
    RenderSettings s;
    s.scene_file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/pbrt-v4/coffee/scene-v4.pbrt";
    s.integrator = integrator;
    s.spp = 2;
    s.resolution = std::make_pair(40, 50);
    s.quiet = true;
    RenderResult r = render(s);
    EXPECT_EQ(count_nonfinite(r.image), 0) << integrator;
    EXPECT_GT(mean_channel(r.image, 1), 0.0) << integrator;
  }
}

}  // namespace
