// Cost of a texture lookup as a BSDF sees it: f() of a diffuse material whose reflectance is an
// imagemap (512 x 512, each filter) at random uv with a pixel footprint of 1/512 (one texel), against
// the same material with a constant reflectance. The difference is the lookup.
#include "image/image_io.h"
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"

#include <penumbra/bsdf.h>
#include <penumbra/rng.h>

#include <benchmark/benchmark.h>
#include <fmt/core.h>

#include <filesystem>

using namespace penumbra;

namespace {

// A 512 x 512 image of smooth noise, written once.
std::string texture_file() {
  static std::string path = [] {
    std::string p = (std::filesystem::temp_directory_path() / "penumbra-bench-texture.exr").string();
    ImageRgb img;
    img.width = img.height = 512;
    img.pixels.resize(3 * 512 * 512);
    Pcg32 rng(3, 4);
    for (float& v : img.pixels) v = 0.2f + 0.6f * rng.next_float();
    write_image(p, img);
    return p;
  }();
  return path;
}

void BM_DiffuseF(benchmark::State& state, const char* filter) {
  std::string material = filter[0] ? "Material \"diffuse\" \"texture reflectance\" \"t\"\n"
                                   : "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n";
  std::string text = fmt::format("WorldBegin\nTexture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"{}\" "
                                 "\"string filter\" \"{}\"\n{}Shape \"sphere\"\n",
                                 texture_file(), filter[0] ? filter : "bilinear", material);
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string(text, "bench.pbrt");
  BuiltScene b = build_scene(d, registry);
  const Bsdf& bsdf = *b.bsdfs.back();
  Pcg32 rng(1, 2);
  ShadingContext ctx;
  ctx.tex.dudx = ctx.tex.dvdy = 1.f / 512.f;
  Vec3 wo(0.f, 0.f, 1.f), wi = glm::normalize(Vec3(0.3f, 0.2f, 1.f));
  for (auto _ : state) {
    ctx.tex.uv = Vec2(rng.next_float(), rng.next_float());
    benchmark::DoNotOptimize(bsdf.f(wo, wi, ctx));
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_DiffuseF, constant, "");
BENCHMARK_CAPTURE(BM_DiffuseF, point, "point");
BENCHMARK_CAPTURE(BM_DiffuseF, bilinear, "bilinear");
BENCHMARK_CAPTURE(BM_DiffuseF, trilinear, "trilinear");
BENCHMARK_CAPTURE(BM_DiffuseF, ewa, "ewa");
