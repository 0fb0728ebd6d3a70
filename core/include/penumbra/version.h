// Penumbra SDK version and compiler identity. A plugin records both in its entry point; the loader
// refuses a plugin whose SDK version or compiler identity differs from the runtime's: the ABI of
// every header in this folder may change between SDK versions, and C++20 code compiled by another
// compiler, another major version of it (GCC documents its C++20 ABI as unstable across major
// releases) or against another standard library does not link reliably with the core.
#pragma once

#include <version>  // defines the standard library's identification macros

#ifndef PENUMBRA_SDK_VERSION
// 2: PluginInfo gained the compiler identity after sdk_version.
// 3: Object gained statistics() (a new virtual function changes every plugin class's vtable).
// 4: the core render loop (SampleIntegrator with pass hooks, PixelIntegrator on top).
// 5: SampleIntegrator::save_state/load_state (checkpoints).
// 6: Camera gained connectible() (orthographic cameras: light paths cannot connect to them).
// 7: texture plugins (PluginKind::Texture, texture.h); ShadingContext carries a TextureEvalContext;
//    SurfaceInteraction gained a pixel footprint; Camera::approximate_dp_dxy().
// 8: absorbing media: SurfaceInteraction::media (MediumInterface), Scene::has_media(),
//    Scene::transmittance(); Param::from_attribute.
// 9: Shape::present() (alpha cut-outs on area lights).
// 10: LightSampleContext::allow_incomplete_pdf; Light::li_density_depends_on_receiver().
// 11: spectral transport: penumbra/spectrum.h (SampledWavelengths), RenderOptions::spectral,
//     PixelSample::wavelengths, PixelIntegrator::Li takes the wavelengths,
//     TextureEvalContext::wavelengths, TexturedRgb kinds (RgbKind), CreateContext::spectral,
//     SampleIntegrator::supports_spectral(), ParamSet::set_bool.
// 12: SampleIntegrator::wavelengths_per_pass(), Pass::wavelengths.
// 13: CameraWiSample::pdf_pos and pdf_dir.
// 14: PixelSample::first_hit; PixelIntegrator::Li() takes it, takes_first_hit().
// 15: ShapeSample::wi and distance (sample_solid_angle() gives the direction it computed).
#define PENUMBRA_SDK_VERSION 15
#endif

#define PENUMBRA_VERSION_STRING "0.1.0"

#define PENUMBRA_STRINGIFY_(x) #x
#define PENUMBRA_STRINGIFY(x) PENUMBRA_STRINGIFY_(x)

// Compiler family and major version; patch releases keep the ABI.
#if defined(__clang__)
#define PENUMBRA_COMPILER_NAME_ "clang " PENUMBRA_STRINGIFY(__clang_major__)
#elif defined(__GNUC__)
#define PENUMBRA_COMPILER_NAME_ "gcc " PENUMBRA_STRINGIFY(__GNUC__)
#elif defined(_MSC_VER)
#define PENUMBRA_COMPILER_NAME_ "msvc " PENUMBRA_STRINGIFY(_MSC_VER)
#else
#define PENUMBRA_COMPILER_NAME_ "unknown compiler"
#endif

#if defined(_LIBCPP_VERSION)
#define PENUMBRA_STDLIB_NAME_ "libc++"
#elif defined(__GLIBCXX__) && _GLIBCXX_USE_CXX11_ABI
#define PENUMBRA_STDLIB_NAME_ "libstdc++ cxx11-abi"
#elif defined(__GLIBCXX__)
#define PENUMBRA_STDLIB_NAME_ "libstdc++ old-abi"
#else
#define PENUMBRA_STDLIB_NAME_ "unknown standard library"
#endif

#ifndef PENUMBRA_COMPILER_ID
/// e.g. "gcc 12, libstdc++ cxx11-abi". Overridable only so that tests can fake a foreign plugin.
#define PENUMBRA_COMPILER_ID PENUMBRA_COMPILER_NAME_ ", " PENUMBRA_STDLIB_NAME_
#endif
