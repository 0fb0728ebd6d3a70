// Turns a parsed SceneDescription into everything a render needs, loading exactly the plugins the
// description names (plus the documented defaults for what it leaves out).
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/integrator.h>
#include <penumbra/light.h>
#include <penumbra/sampler.h>
#include <penumbra/texture.h>

#include "image/film_rgb.h"
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/embree_scene.h"
#include "texture/texture_table.h"

#include <memory>
#include <string>
#include <vector>

namespace penumbra {

/// Defaults for directives a scene leaves out (pbrt-v4's, where Penumbra has the plugin).
inline constexpr const char* kDefaultIntegrator = "path";
inline constexpr const char* kDefaultSampler = "independent";
inline constexpr const char* kDefaultFilter = "gaussian";
inline constexpr const char* kDefaultMaterial = "diffuse";

struct BuiltScene {
  std::vector<std::unique_ptr<Object>> textures;  // FloatTexture / SpectrumTexture; materials refer to them
  TextureTable texture_table;
  std::vector<std::unique_ptr<Bsdf>> bsdfs;
  std::vector<std::unique_ptr<Light>> lights;
  std::unique_ptr<EmbreeScene> scene;  // refers to bsdfs and lights: declared after them
  std::unique_ptr<FilmRgb> film;
  std::unique_ptr<Sampler> sampler;
  std::unique_ptr<Integrator> integrator;
  std::string integrator_name, sampler_name;
  std::string output_filename;         // Film "filename"
  bool spectral = false;               // Film "spectral": materials were made for spectral transport
  std::vector<std::string> structures_built;
};

/// Loads plugins and builds the scene. Throws Error located in the scene file.
BuiltScene build_scene(SceneDescription& desc, Registry& registry);

}  // namespace penumbra
