// Per-sample building blocks: random numbers, warps, filter sampling, ray queries.
#include "image/film_rgb.h"
#include "scene/embree_scene.h"
#include "util/alias_table.h"

#include <penumbra/rng.h>
#include <penumbra/sampling.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

using namespace penumbra;

static void BM_Pcg32Float(benchmark::State& state) {
  Pcg32 rng(1, 2);
  for (auto _ : state) benchmark::DoNotOptimize(rng.next_float());
}
BENCHMARK(BM_Pcg32Float);

static void BM_Pcg32AdvanceToSample(benchmark::State& state) {
  Pcg32 rng(1, 2);
  uint64_t i = 0;
  for (auto _ : state) {
    rng.set_sequence(hash_ints(i & 255, i >> 8), 0);
    rng.advance(++i * 65536ull);
    benchmark::DoNotOptimize(rng.next_u32());
  }
}
BENCHMARK(BM_Pcg32AdvanceToSample);

static void BM_CosineHemisphere(benchmark::State& state) {
  Pcg32 rng(1, 2);
  for (auto _ : state) benchmark::DoNotOptimize(sample_cosine_hemisphere(Vec2(rng.next_float(), rng.next_float())));
}
BENCHMARK(BM_CosineHemisphere);

static void BM_FilterSample(benchmark::State& state, const char* type) {
  ParamSet p;
  p.validate(pixel_filter_params(type), "filter");
  PixelFilter f(type, p, {});
  Pcg32 rng(1, 2);
  for (auto _ : state) benchmark::DoNotOptimize(f.sample(Vec2(rng.next_float(), rng.next_float())));
}
BENCHMARK_CAPTURE(BM_FilterSample, box, "box");
BENCHMARK_CAPTURE(BM_FilterSample, triangle, "triangle");
BENCHMARK_CAPTURE(BM_FilterSample, gaussian, "gaussian");

// Choosing one of N lights by power: the alias table the scene uses against a CDF's search
// (Distribution1D::sample_discrete), over weights spread across four decades.
static std::vector<float> light_powers(int n) {
  Pcg32 rng(3, 4);
  std::vector<float> w(n);
  for (float& v : w) v = std::pow(10.f, 4.f * rng.next_float());
  return w;
}
static void BM_LightChoiceAliasTable(benchmark::State& state) {
  AliasTable table(light_powers(int(state.range(0))));
  Pcg32 rng(1, 2);
  for (auto _ : state) benchmark::DoNotOptimize(table.sample(rng.next_float()));
}
BENCHMARK(BM_LightChoiceAliasTable)->Arg(2)->Arg(64)->Arg(100'000);
static void BM_LightChoiceCdfSearch(benchmark::State& state) {
  Distribution1D cdf(light_powers(int(state.range(0))));
  Pcg32 rng(1, 2);
  for (auto _ : state) benchmark::DoNotOptimize(cdf.sample_discrete(rng.next_float()));
}
BENCHMARK(BM_LightChoiceCdfSearch)->Arg(2)->Arg(64)->Arg(100'000);

static void BM_SceneIntersectInsideSphere(benchmark::State& state) {
  EmbreeScene scene;
  scene.add_sphere(std::make_unique<Sphere>(Mat4(1.f), 1.f, true), nullptr, nullptr);
  scene.commit();
  Pcg32 rng(1, 2);
  for (auto _ : state)
    benchmark::DoNotOptimize(scene.intersect(Ray{Vec3(0.f), sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()))}));
}
BENCHMARK(BM_SceneIntersectInsideSphere);
