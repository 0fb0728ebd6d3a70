// Renders split across machines: parts taking disjoint ranges of one sample sequence merge into the
// single render (within float rounding: each part's mean is stored as a 32-bit float and the merge
// sums parts in another order than the film summed samples), the variance AOV matches the spread of
// independent renders, and `penumbra merge` refuses parts that do not belong together.
#include "render/render_session.h"
#include "support/command.h"
#include "support/exr_channels.h"

#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {

const std::string kCornell = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";

// Renders the Cornell box into dir/name with extra options; fails the test on an error.
std::string render_cornell(const std::string& dir, const std::string& name, std::vector<std::string> extra,
                   const std::string& res = "32x32") {
  std::vector<std::string> args = {"render", kCornell, "--res", res, "-o", dir + "/" + name, "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  test::CommandResult r = test::run_penumbra(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return dir + "/" + name;
}

// Largest relative difference over every channel of two images with the same channels.
double max_relative_difference(const test::ExrChannels& a, const test::ExrChannels& b, const std::string& prefix = "") {
  double worst = 0;
  for (const auto& [name, values] : a.channels) {
    if (name.rfind(prefix, 0) != 0) continue;
    const std::vector<float>& other = b.channels.at(name);
    for (size_t i = 0; i < values.size(); ++i) {
      double x = values[i], y = other[i];
      double scale = std::max({std::abs(x), std::abs(y), 1e-30});
      worst = std::max(worst, std::abs(x - y) / scale);
    }
  }
  return worst;
}

test::CommandResult merge(const std::vector<std::string>& parts, const std::string& out) {
  std::vector<std::string> args = {"merge"};
  args.insert(args.end(), parts.begin(), parts.end());
  args.insert(args.end(), {"-o", out});
  return test::run_penumbra(args);
}

}  // namespace

TEST(SplitRender, FourPartsOf64SamplesMergeIntoTheSingleRender) {
  std::string dir = test::temp_dir("split-cornell");
  std::string single = render_cornell(dir, "single.exr", {"--spp", "64", "--aov", "samples,variance", "--seed", "5"});
  std::vector<std::string> parts;
  for (int k = 0; k < 4; ++k)
    parts.push_back(render_cornell(dir, "part" + std::to_string(k) + ".exr",
                           {"--spp-total", "64", "--spp-offset", std::to_string(16 * k), "--spp-count", "16",
                            "--aov", "variance", "--seed", "5"}));
  test::ExrChannels part1 = test::read_exr_channels(parts[1]);
  EXPECT_EQ(part1.meta.at("penumbra:sample_range"), "16-32");
  EXPECT_EQ(part1.meta.at("penumbra:spp"), "16");
  EXPECT_EQ(part1.meta.at("penumbra:spp_total"), "64");

  test::CommandResult r = merge({parts[2], parts[0], parts[3], parts[1]}, dir + "/merged.exr");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("merged 4 parts (64 of 64 samples per pixel)"));
  test::ExrChannels a = test::read_exr_channels(single), b = test::read_exr_channels(dir + "/merged.exr");
  ASSERT_EQ(a.names.size(), b.names.size());
  EXPECT_EQ(a.channels.at("samples.count"), b.channels.at("samples.count"));
  EXPECT_LT(max_relative_difference(a, b, "R"), 1e-6);
  EXPECT_LT(max_relative_difference(a, b, "G"), 1e-6);
  EXPECT_LT(max_relative_difference(a, b, "B"), 1e-6);
  EXPECT_LT(max_relative_difference(a, b, "samples"), 1e-6);
  // The variance is recombined from four rounded variances and means: a few float roundings more.
  EXPECT_LT(max_relative_difference(a, b, "variance"), 1e-4);
  EXPECT_EQ(b.meta.at("penumbra:sample_range"), "0-64");
  EXPECT_EQ(b.meta.at("penumbra:spp"), "64");
  EXPECT_EQ(b.meta.at("penumbra:scene_hash"), a.meta.at("penumbra:scene_hash"));
}

TEST(SplitRender, UnevenPartsOfAQuasiRandomSequenceMergeToo) {
  std::string dir = test::temp_dir("split-sobol");
  std::string single = render_cornell(dir, "single.exr", {"--spp", "32", "--sampler", "sobol"});
  std::vector<std::string> parts = {
      render_cornell(dir, "a.exr", {"--spp-total", "32", "--spp-count", "5", "--sampler", "sobol"}),
      render_cornell(dir, "b.exr", {"--spp-total", "32", "--spp-offset", "5", "--spp-count", "19", "--sampler", "sobol"}),
      render_cornell(dir, "c.exr", {"--spp-total", "32", "--spp-offset", "24", "--sampler", "sobol"})};
  ASSERT_EQ(merge(parts, dir + "/merged.exr").exit_code, 0);
  EXPECT_LT(max_relative_difference(test::read_exr_channels(single), test::read_exr_channels(dir + "/merged.exr"), "R"),
            1e-6);
}

TEST(SplitRender, OnePartHoldingEverySampleIsTheSingleRenderBitForBit) {
  std::string dir = test::temp_dir("split-whole");
  test::ExrChannels a = test::read_exr_channels(render_cornell(dir, "a.exr", {"--spp", "8", "--aov", "samples"}));
  test::ExrChannels b = test::read_exr_channels(render_cornell(dir, "b.exr", {"--spp-total", "8"}));
  for (const char* c : {"R", "G", "B", "samples.count", "samples.weight"}) EXPECT_EQ(a.channels.at(c), b.channels.at(c)) << c;
}

TEST(SplitRender, PhotonMappingPartsAreIndependentRendersWeightedByIterations) {
  // SPPM is not a mean of per-iteration estimates: a part runs its own iterations (its own random
  // streams, its own shrinking radii), and the merge weighs the parts by their iteration counts.
  std::string dir = test::temp_dir("split-sppm");
  auto part = [&](const std::string& name, int offset, int count) {
    return test::read_exr_channels(render_cornell(dir, name, {"--integrator", "sppm", "--spp-total", "8", "--spp-offset",
                                                              std::to_string(offset), "--spp-count", std::to_string(count)},
                                                  "16x16"));
  };
  test::ExrChannels a = part("a.exr", 0, 2), b = part("b.exr", 2, 6), c = part("c.exr", 2, 2);
  EXPECT_EQ(a.at("samples.weight", 3, 3), 2.f);
  EXPECT_EQ(b.at("samples.weight", 3, 3), 6.f);
  EXPECT_NE(a.channels.at("R"), c.channels.at("R"));  // same length, other iterations: other streams
  ASSERT_EQ(merge({dir + "/a.exr", dir + "/b.exr"}, dir + "/m.exr").exit_code, 0);
  test::ExrChannels m = test::read_exr_channels(dir + "/m.exr");
  for (size_t i = 0; i < m.channels.at("R").size(); ++i) {
    double expected = (2.0 * a.channels.at("R")[i] + 6.0 * b.channels.at("R")[i]) / 8.0;
    ASSERT_NEAR(m.channels.at("R")[i], expected, 1e-6 * std::max(1.0, std::abs(expected))) << i;
  }
}

TEST(SplitRender, VarianceAovAgreesWithTheSpreadOfIndependentRenders) {
  // A floor under a square light, direct lighting only: a light-tailed estimator, so that the spread
  // of 32 renders is a steady measure (on the Cornell box, path tracing's long tail left the spread
  // of 16 renders between 0.85 and 1.25 of the variance AOV in trials).
  std::string dir = test::temp_dir("split-variance");
  std::string scene = test::write_file(dir, "lit.pbrt", R"(
LookAt 0 3 0.01  0 0 0  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 2 1  0 3 2 ]
AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
Shape "trianglemesh" "point3 P" [ -1 1 -1  1 1 -1  1 1 1  -1 1 1 ] "integer indices" [ 0 1 2  0 2 3 ]
)");
  // In-process renders: 32 of them cost less than 32 program starts.
  const int runs = 32;
  std::vector<RenderResult> results;
  for (int k = 0; k < runs; ++k) {
    RenderSettings settings;
    settings.scene_file = scene;
    settings.seed = uint32_t(k + 1);
    settings.aovs = {"variance"};
    settings.quiet = true;
    settings.plugin_dirs = {std::string(PENUMBRA_BINARY_DIR) + "/lib/penumbra/plugins"};
    results.push_back(render(settings));
    ASSERT_EQ(results.back().aovs.size(), 1u);
  }
  // Summed over pixels and channels: the spread across renders against the mean variance AOV.
  double spread = 0, predicted = 0;
  for (size_t i = 0; i < results[0].image.pixels.size(); ++i) {
    double mean = 0, m2 = 0, v = 0;
    for (const auto& r : results) mean += r.image.pixels[i] / runs;
    for (const auto& r : results) {
      double d = r.image.pixels[i] - mean;
      m2 += d * d;
      v += r.aovs[0].pixels[i] / runs;  // variance.R, .G, .B interleaved like the beauty
    }
    spread += m2 / (runs - 1);
    predicted += v;
  }
  EXPECT_GT(predicted, 0.0);
  EXPECT_NEAR(spread / predicted, 1.0, 0.08) << "spread " << spread << ", variance AOV " << predicted;
}

TEST(SplitRender, MergeRefusesPartsThatDoNotBelongTogether) {
  std::string dir = test::temp_dir("split-refuse");
  std::string a = render_cornell(dir, "a.exr", {"--spp-total", "8", "--spp-count", "4"});
  std::string b = render_cornell(dir, "b.exr", {"--spp-total", "8", "--spp-offset", "4"});
  std::string overlap = render_cornell(dir, "overlap.exr", {"--spp-total", "8", "--spp-offset", "2", "--spp-count", "4"});
  std::string seed = render_cornell(dir, "seed.exr", {"--spp-total", "8", "--spp-offset", "4", "--seed", "9"});
  std::string plain = render_cornell(dir, "plain.exr", {"--spp", "4"});

  // Another scene: the Cornell box with one more (tiny) sphere.
  test::write_file(dir, "unit-cube.pbrt", test::read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/unit-cube.pbrt"));
  std::string other_scene = test::write_file(dir, "cornell-other.pbrt",
                                             test::read_file(kCornell) + "\nShape \"sphere\" \"float radius\" [ 0.01 ]\n");
  test::CommandResult r = test::run_penumbra({"render", other_scene, "--res", "32x32", "-o", dir + "/other.exr", "-q",
                                              "--spp-total", "8", "--spp-offset", "4"});
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // Another version: part b with its header rewritten.
  {
    auto in = OIIO::ImageInput::open(b);
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> pixels(size_t(spec.width) * spec.height * spec.nchannels);
    in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
    spec.attribute("penumbra:version", "0.0.1");
    auto out = OIIO::ImageOutput::create(dir + "/old.exr");
    ASSERT_TRUE(out->open(dir + "/old.exr", spec) && out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) && out->close());
  }

  struct Case {
    std::string part, message;
  } cases[] = {
      {dir + "/other.exr", "cannot merge " + a + " and " + dir + "/other.exr: the scene (scene hash) differs"},
      {dir + "/old.exr", "cannot merge " + a + " and " + dir + "/old.exr: the Penumbra version differs (0.1.0 vs 0.0.1)"},
      {seed, "cannot merge " + a + " and " + seed + ": the seed differs (0 vs 9)"},
      {overlap, "cannot merge " + a + " and " + overlap + ": both contain samples 2-4"},
      {plain, plain + " has no 'samples' layer (count, weight) to weight it by"},
  };
  for (const auto& c : cases) {
    test::CommandResult m = merge({a, c.part}, dir + "/m.exr");
    EXPECT_EQ(m.exit_code, 1) << c.part;
    EXPECT_THAT(m.err, HasSubstr(c.message));
  }
  EXPECT_EQ(merge({a, b}, dir + "/m.exr").exit_code, 0);
  test::CommandResult png = merge({a, b}, dir + "/m.png");
  EXPECT_EQ(png.exit_code, 1);
  EXPECT_THAT(png.err, HasSubstr("must end in .exr"));
  // A part alone is a valid, noisier estimate: merged with a note.
  test::CommandResult alone = merge({b}, dir + "/m.exr");
  EXPECT_EQ(alone.exit_code, 0);
  EXPECT_THAT(alone.err, HasSubstr("the parts hold samples 4-8 of 0-8"));
}

TEST(SplitRender, SlurmScriptRehearsesLocally) {
  // scripts/slurm-render.sh --local runs the array's parts here and merges them: the same arithmetic
  // and commands as the Slurm tasks (submission itself needs a cluster).
  std::string dir = test::temp_dir("split-slurm");
  std::string cmd = std::string("PENUMBRA='") + PENUMBRA_BINARY + "' bash '" + PENUMBRA_SOURCE_DIR +
                    "/scripts/slurm-render.sh' --local '" + kCornell + "' '" + dir + "/out.exr' 10 3 --res 8x8 --seed 2 >'" +
                    dir + "/log' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << test::read_file(dir + "/log");
  EXPECT_EQ(test::read_exr_channels(dir + "/out.parts/part-0001.exr").meta.at("penumbra:sample_range"), "3-6");
  test::ExrChannels merged = test::read_exr_channels(dir + "/out.exr");
  EXPECT_EQ(merged.meta.at("penumbra:sample_range"), "0-10");
  EXPECT_EQ(merged.meta.at("penumbra:seed"), "2");
  EXPECT_EQ(merged.at("samples.count", 4, 4), 10.f);
}

TEST(SplitRender, SplitOptionsAreCheckedBeforeRendering) {
  std::string dir = test::temp_dir("split-options");
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", kCornell, "--res", "8x8", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    if (std::find(extra.begin(), extra.end(), "-o") == extra.end()) args.insert(args.end(), {"-o", dir + "/o.exr"});
    return test::run_penumbra(args);
  };
  struct Case {
    std::vector<std::string> args;
    std::string message;
  } cases[] = {
      {{"--spp-offset", "4"}, "--spp-offset requires --spp-total"},
      {{"--spp-total", "8", "--spp", "4"}, "--spp and --spp-total exclude each other"},
      {{"--spp-total", "8", "--time", "1"}, "--time cannot split a render"},
      {{"--spp-total", "8", "--spp-offset", "8"}, "--spp-offset 8 is outside the 8 samples of --spp-total"},
      {{"--spp-total", "8", "--spp-offset", "4", "--spp-count", "5"}, "--spp-count 5 does not fit"},
      {{"--spp-total", "8", "-o", dir + "/o.png"}, "a part of a split render must be written as .exr"},
  };
  for (const auto& c : cases) {
    test::CommandResult r = run(c.args);
    EXPECT_EQ(r.exit_code, 1) << c.message;
    EXPECT_THAT(r.err, HasSubstr(c.message));
  }
}
