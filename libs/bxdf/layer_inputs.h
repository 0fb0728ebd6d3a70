// Scene parameters of the coated materials (pbrt-v4's names): the slab's "thickness", "albedo",
// "g", "maxdepth" and "nsamples", and microfacet roughness under a name prefix ("interface.",
// "conductor."). Constants are checked at their parameters; textured values are clamped per lookup.
#pragma once

#include "layered_bxdf.h"

#include <penumbra/microfacet.h>
#include <penumbra/plugin.h>

#include <string>

namespace penumbra::bxdf {

struct LayerInputs {
  TexturedFloat thickness, g;
  TexturedRgb albedo;
  int max_depth = 10, n_samples = 1;

  bool is_constant() const { return thickness.is_constant() && g.is_constant() && albedo.is_constant(); }
  LayerParams at(const TextureEvalContext& tc) const;
};

/// Reads and checks thickness (>= 0), albedo (in [0, 1]), g (in (-1, 1)), maxdepth and nsamples (>= 1).
LayerInputs layer_inputs(const CreateContext& ctx);

/// microfacet_roughness() for "<prefix>roughness", "<prefix>uroughness", "<prefix>vroughness" and
/// "remaproughness"; negative constants are errors at their parameter.
MicrofacetRoughness prefixed_roughness(const CreateContext& ctx, const std::string& prefix);

/// A "float|spectrum" index of refraction that must be positive and finite (pbrt-v4 turns 0 into 1).
float checked_eta(const ParamSet& p, const std::string& name);

}  // namespace penumbra::bxdf
