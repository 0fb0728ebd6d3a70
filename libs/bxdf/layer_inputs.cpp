#include "layer_inputs.h"

#include <penumbra/error.h>

namespace penumbra::bxdf {

LayerParams LayerInputs::at(const TextureEvalContext& tc) const {
  LayerParams p;
  p.thickness = std::max(0.f, thickness.evaluate(tc));
  p.g = std::clamp(g.evaluate(tc), -0.99f, 0.99f);
  p.albedo = glm::clamp(albedo.evaluate(tc), Rgb(0.f), Rgb(1.f));
  p.max_depth = max_depth;
  p.n_samples = n_samples;
  return p;
}

LayerInputs layer_inputs(const CreateContext& ctx) {
  const ParamSet& ps = ctx.params;
  LayerInputs in;
  in.thickness = ctx.float_input("thickness");
  in.g = ctx.float_input("g");
  in.albedo = ctx.rgb_input("albedo");
  in.max_depth = ps.get_int("maxdepth");
  in.n_samples = ps.get_int("nsamples");
  if (in.thickness.is_constant() && !(in.thickness.constant() >= 0.f && std::isfinite(in.thickness.constant())))
    throw Error(ps.loc_of("thickness"), "thickness must be >= 0");
  if (in.g.is_constant() && !(in.g.constant() > -1.f && in.g.constant() < 1.f))
    throw Error(ps.loc_of("g"), "g must be in (-1, 1)");
  if (in.albedo.is_constant()) {
    Rgb a = in.albedo.constant();
    if (!(glm::all(glm::greaterThanEqual(a, Rgb(0.f))) && glm::all(glm::lessThanEqual(a, Rgb(1.f)))))
      throw Error(ps.loc_of("albedo"), "albedo must be in [0, 1]");
  }
  if (in.max_depth < 1) throw Error(ps.loc_of("maxdepth"), "maxdepth must be >= 1");
  if (in.n_samples < 1) throw Error(ps.loc_of("nsamples"), "nsamples must be >= 1");
  return in;
}

MicrofacetRoughness prefixed_roughness(const CreateContext& ctx, const std::string& prefix) {
  const ParamSet& p = ctx.params;
  const std::string r = prefix + "roughness", ur = prefix + "uroughness", vr = prefix + "vroughness";
  MicrofacetRoughness m;
  m.u = p.has(ur) ? ctx.float_input(ur) : ctx.float_input(r);
  m.v = p.has(vr) ? ctx.float_input(vr) : ctx.float_input(r);
  for (const std::string* name : {&r, &ur, &vr}) {
    if (!p.has(*name)) continue;
    TexturedFloat t = ctx.float_input(*name);
    if (t.is_constant() && !(t.constant() >= 0.f)) throw Error(p.loc_of(*name), *name + " must be >= 0");
  }
  m.remap = p.get_bool("remaproughness", true);
  return m;
}

float checked_eta(const ParamSet& p, const std::string& name) {
  float eta = p.get_float(name);
  if (eta == 0.f) eta = 1.f;
  if (!(eta > 0.f) || !std::isfinite(eta)) throw Error(p.loc_of(name), name + " must be a positive number");
  return eta;
}

}  // namespace penumbra::bxdf
