// Directives that create scene objects (camera, options, materials, lights, shapes) or that
// Penumbra accepts and ignores. Objects are only recorded here; the scene builder loads their
// plugins.
#include "parser/scene_parser.h"

#include <fmt/core.h>

#include <algorithm>

#include "parser/param_list.h"
#include "parser/spectrum_params.h"

namespace penumbra {

Token SceneParser::expect_string(const Token& d, const char* what) {
  Token t = tok_->next();
  if (t.kind != TokenKind::String)
    throw Error(t.loc, fmt::format("{} needs a quoted {}, got {}", d.text, what, describe(t)));
  return t;
}

SceneEntity SceneParser::make_entity(const Token& d, const char* what) {
  std::string type = expect_string(d, what).text;
  return entity_at(d, std::move(type), parse_param_list(*tok_));
}

// The Attribute target whose defaults a directive takes ("" for none).
static const char* attribute_target(const std::string& directive) {
  if (directive == "Shape") return "shape";
  if (directive == "LightSource" || directive == "AreaLightSource") return "light";
  if (directive == "Material" || directive == "MakeNamedMaterial") return "material";
  if (directive == "MakeNamedMedium") return "medium";
  if (directive == "Texture") return "texture";
  return "";
}

SceneEntity SceneParser::entity_at(const Token& d, std::string type, ParamSet params) {
  SceneEntity e;
  e.type = std::move(type);
  if (auto it = state_.attributes.find(attribute_target(d.text)); it != state_.attributes.end())
    for (const Param& p : it->second.params())
      if (!params.has(p.name)) params.add(p);  // keeps the Attribute's location for errors
  e.params = resolve_spectra(params, spectrum_use_of(d.text), base_dir_);
  e.loc = d.loc;
  e.base_dir = base_dir_;
  e.to_world = Mat4(state_.ctm);
  e.reverse_orientation = state_.reverse_orientation;
  return e;
}

// pbrt-v4 separates rendering options (before WorldBegin) from the scene (after it); mixing them
// is an error there, and keeping that rule keeps Penumbra's scenes valid pbrt-v4.
void SceneParser::require_options(const Token& d) {
  if (in_world_)
    throw Error(d.loc, fmt::format("{} must come before WorldBegin (WorldBegin is at {})", d.text,
                                   world_begin_loc_.str()));
}

void SceneParser::require_world(const Token& d) {
  if (!in_world_) throw Error(d.loc, fmt::format("{} must come after WorldBegin", d.text));
}

void SceneParser::camera(const Token& d) {
  require_options(d);
  desc_.camera = make_entity(d, "camera type");
  glm::dmat4 world_from_camera = glm::inverse(state_.ctm);
  desc_.camera.to_world = Mat4(world_from_camera);
  desc_.camera_medium = state_.medium_outside;  // pbrt-v4: the camera sits in the outside medium
  desc_.camera_medium_loc = state_.medium_loc;
  named_coordinate_systems_["camera"] = world_from_camera;
}

void SceneParser::set_option_entity(const Token& d, SceneEntity& slot, const char* what) {
  require_options(d);
  slot = make_entity(d, what);  // the last one given wins, as in pbrt
}

void SceneParser::film(const Token& d) { set_option_entity(d, desc_.film, "film type"); }
void SceneParser::pixel_filter(const Token& d) {
  set_option_entity(d, desc_.filter, "filter type");
}
void SceneParser::sampler(const Token& d) { set_option_entity(d, desc_.sampler, "sampler type"); }
void SceneParser::integrator(const Token& d) {
  set_option_entity(d, desc_.integrator, "integrator type");
}

void SceneParser::material(const Token& d) {
  require_world(d);
  desc_.materials.push_back(make_entity(d, "material type"));
  state_.material = static_cast<int>(desc_.materials.size()) - 1;
  state_.material_name.clear();
}

void SceneParser::make_named_material(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "material name");
  if (auto it = desc_.named_materials.find(name.text); it != desc_.named_materials.end())
    throw Error(name.loc, fmt::format("named material '{}' redefined (first defined at {})",
                                      name.text, desc_.materials[it->second].loc.str()));
  ParamSet given = parse_param_list(*tok_);
  const Param* type = given.find("type");
  if (!type)
    throw Error(d.loc,
                fmt::format("MakeNamedMaterial '{}' needs a \"string type\" parameter", name.text));
  if (type->type != "string" || type->strings.size() != 1)
    throw Error(type->loc, "the 'type' of a named material must be one string");
  ParamSet params;
  for (const auto& p : given.params())
    if (p.name != "type") params.add(p);
  desc_.materials.push_back(entity_at(d, type->strings[0], std::move(params)));
  desc_.named_materials[name.text] = static_cast<int>(desc_.materials.size()) - 1;
}

void SceneParser::named_material(const Token& d) {
  require_world(d);
  state_.material_name = expect_string(d, "material name").text;
  state_.material_loc = d.loc;
  state_.material = -1;
}

void SceneParser::area_light_source(const Token& d) {
  require_world(d);
  desc_.area_lights.push_back(make_entity(d, "area light type"));
  state_.area_light = static_cast<int>(desc_.area_lights.size()) - 1;
}

void SceneParser::light_source(const Token& d) {
  require_world(d);
  desc_.lights.push_back(make_entity(d, "light type"));
}

void SceneParser::shape(const Token& d) {
  require_world(d);
  ShapeEntity s;
  static_cast<SceneEntity&>(s) = make_entity(d, "shape type");
  take_graphics_state(s);
  desc_.shapes.push_back(std::move(s));
}

// pbrt-v4's `Attribute "target" params`: defaults for the shapes, lights, materials, media or
// textures that follow in the attribute block; a later Attribute of the same parameter replaces it.
void SceneParser::attribute(const Token& d) {
  Token target = expect_string(d, "attribute target (\"shape\", \"light\", \"material\", \"medium\" or \"texture\")");
  static const char* const kTargets[] = {"shape", "light", "material", "medium", "texture"};
  if (std::find(std::begin(kTargets), std::end(kTargets), target.text) == std::end(kTargets))
    throw Error(target.loc, fmt::format("unknown attribute target \"{}\"; available: light, material, medium, shape, "
                                        "texture",
                                        target.text));
  ParamSet given = parse_param_list(*tok_);
  ParamSet& defaults = state_.attributes[target.text];
  ParamSet merged;
  for (const Param& p : defaults.params())
    if (!given.has(p.name)) merged.add(p);
  for (Param p : given.params()) {
    p.from_attribute = true;
    merged.add(std::move(p));
  }
  defaults = std::move(merged);
}

void SceneParser::take_graphics_state(ShapeEntity& s) const {
  s.material = state_.material;
  s.material_name = state_.material_name;
  s.material_loc = state_.material_loc;
  s.area_light = state_.area_light;
  s.medium_inside = state_.medium_inside;
  s.medium_outside = state_.medium_outside;
  s.medium_loc = state_.medium_loc;
  s.object = current_object_;
}

// pbrt-v4: media are named globally, before or after WorldBegin, with their kind in "string type".
// Which kinds Penumbra simulates is the scene builder's question (only media that are used matter).
void SceneParser::make_named_medium(const Token& d) {
  Token name = expect_string(d, "medium name");
  if (auto it = desc_.named_media.find(name.text); it != desc_.named_media.end())
    throw Error(name.loc, fmt::format("named medium '{}' redefined (first defined at {})", name.text,
                                      desc_.media[it->second].loc.str()));
  ParamSet given = parse_param_list(*tok_);
  const Param* type = given.find("type");
  if (!type) throw Error(d.loc, fmt::format("MakeNamedMedium '{}' needs a \"string type\" parameter", name.text));
  if (type->type != "string" || type->strings.size() != 1)
    throw Error(type->loc, "the 'type' of a named medium must be one string");
  ParamSet params;
  for (const auto& p : given.params())
    if (p.name != "type") params.add(p);
  MediumEntity m;
  static_cast<SceneEntity&>(m) = entity_at(d, type->strings[0], std::move(params));
  m.name = name.text;
  desc_.media.push_back(std::move(m));
  desc_.named_media[name.text] = static_cast<int>(desc_.media.size()) - 1;
}

// `MediumInterface "inside" "outside"`, or one name for both sides; "" is vacuum. The names are
// resolved when the scene is built (a medium may be defined after the interface that names it).
void SceneParser::medium_interface(const Token& d) {
  Token inside = expect_string(d, "medium name (inside)");
  std::string outside = inside.text;
  if (tok_->peek().kind == TokenKind::String) outside = tok_->next().text;
  state_.medium_inside = inside.text;
  state_.medium_outside = outside;
  state_.medium_loc = d.loc;
}

// pbrt-v4: textures are named globally (not scoped by attributes); float and spectrum textures
// have separate names, and defining one twice is an error.
void SceneParser::texture(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "texture name");
  Token kind = expect_string(d, "texture type (\"float\" or \"spectrum\")");
  if (kind.text != "float" && kind.text != "spectrum")
    throw Error(kind.loc, fmt::format("texture type must be \"float\" or \"spectrum\", got \"{}\"", kind.text));
  bool spectrum = kind.text == "spectrum";
  for (const auto& t : desc_.textures)
    if (t.name == name.text && t.spectrum == spectrum)
      throw Error(name.loc, fmt::format("{} texture '{}' redefined (first defined at {})", kind.text,
                                        name.text, t.loc.str()));
  TextureEntity t;
  static_cast<SceneEntity&>(t) = make_entity(d, "texture class");
  t.name = name.text;
  t.spectrum = spectrum;
  desc_.textures.push_back(std::move(t));
}

void SceneParser::reverse_orientation(const Token&) {
  state_.reverse_orientation = !state_.reverse_orientation;
}

void SceneParser::accelerator(const Token& d) {
  warn_once(d, "Accelerator is ignored: Penumbra always uses Embree's BVH");
  make_entity(d, "accelerator type");
}

void SceneParser::color_space(const Token& d) {
  warn_once(d, "ColorSpace is ignored: Penumbra renders in linear Rec.709 (sRGB primaries)");
  expect_string(d, "color space name");
}

void SceneParser::option(const Token& d) {
  warn_once(d, "Option is ignored by Penumbra");
  parse_param(*tok_);
}

}  // namespace penumbra
