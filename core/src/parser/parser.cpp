// pbrt-v4 scene files: the directive loop, attribute blocks and Include. Semantics follow pbrt-v4's
// scene builder; the subset Penumbra supports is documented in docs/scene-format.md.
#include "parser/scene_parser.h"

#include "util/input_file.h"

#include <fmt/core.h>

#include <algorithm>

namespace penumbra {

namespace fs = std::filesystem;

namespace {

// pbrt-v4 directives Penumbra knowingly leaves out: naming them gives a clear message instead of
// "unknown directive".
const std::set<std::string> kUnsupported = {
    "ActiveTransform", "TransformTimes",
};


std::string closest_directive(const std::string& word, const std::vector<std::string>& names) {
  std::string best;
  size_t best_d = SIZE_MAX;
  for (const auto& n : names) {
    size_t d = edit_distance(word, n);
    if (d < best_d) {
      best_d = d;
      best = n;
    }
  }
  return best_d <= std::max<size_t>(2, word.size() / 3) ? best : "";
}

}  // namespace

const std::map<std::string, SceneParser::Handler>& SceneParser::handlers() {
  static const std::map<std::string, Handler> table = {
      {"Accelerator", &SceneParser::accelerator},
      {"AreaLightSource", &SceneParser::area_light_source},
      {"Attribute", &SceneParser::attribute},
      {"AttributeBegin", &SceneParser::attribute_begin},
      {"AttributeEnd", &SceneParser::attribute_end},
      {"Camera", &SceneParser::camera},
      {"ColorSpace", &SceneParser::color_space},
      {"ConcatTransform", &SceneParser::concat_transform},
      {"CoordinateSystem", &SceneParser::coordinate_system},
      {"CoordSysTransform", &SceneParser::coord_sys_transform},
      {"Film", &SceneParser::film},
      {"Identity", &SceneParser::identity},
      {"Import", &SceneParser::include},
      {"Include", &SceneParser::include},
      {"Integrator", &SceneParser::integrator},
      {"LightSource", &SceneParser::light_source},
      {"LookAt", &SceneParser::look_at},
      {"MakeNamedMaterial", &SceneParser::make_named_material},
      {"MakeNamedMedium", &SceneParser::make_named_medium},
      {"Material", &SceneParser::material},
      {"MediumInterface", &SceneParser::medium_interface},
      {"NamedMaterial", &SceneParser::named_material},
      {"ObjectBegin", &SceneParser::object_begin},
      {"ObjectEnd", &SceneParser::object_end},
      {"ObjectInstance", &SceneParser::object_instance},
      {"Option", &SceneParser::option},
      {"PixelFilter", &SceneParser::pixel_filter},
      {"ReverseOrientation", &SceneParser::reverse_orientation},
      {"Rotate", &SceneParser::rotate},
      {"Sampler", &SceneParser::sampler},
      {"Scale", &SceneParser::scale},
      {"Shape", &SceneParser::shape},
      {"Texture", &SceneParser::texture},
      {"Transform", &SceneParser::transform},
      {"TransformBegin", &SceneParser::transform_begin},
      {"TransformEnd", &SceneParser::transform_end},
      {"Translate", &SceneParser::translate},
      {"WorldBegin", &SceneParser::world_begin},
      {"WorldEnd", &SceneParser::world_end},
  };
  return table;
}

void SceneParser::dispatch(const Token& d) {
  if (d.kind != TokenKind::Word)
    throw Error(d.loc, fmt::format("expected a directive, got {}", describe(d)));
  auto it = handlers().find(d.text);
  if (it != handlers().end()) return (this->*(it->second))(d);
  if (kUnsupported.count(d.text))
    throw Error(d.loc, fmt::format("unsupported directive '{}' (Penumbra supports a subset of "
                                   "pbrt-v4: see docs/scene-format.md)",
                                   d.text));
  std::vector<std::string> names;
  for (const auto& [name, handler] : handlers()) names.push_back(name);
  std::string best = closest_directive(d.text, names);
  throw Error(d.loc, fmt::format("unknown directive '{}'{}", shorten(d.text),
                                 best.empty() ? "" : fmt::format("; did you mean '{}'?", best)));
}

bool SceneParser::looks_like_directive(const Token& t) {
  if (t.kind != TokenKind::Word) return false;
  if (handlers().count(t.text) || kUnsupported.count(t.text)) return true;
  std::vector<std::string> names;
  for (const auto& [name, handler] : handlers()) names.push_back(name);
  return !closest_directive(t.text, names).empty();
}

void SceneParser::parse_text(const std::string& text, const std::string& name,
                             const std::string& base_dir) {
  auto filename = std::make_shared<const std::string>(name);
  Tokenizer tok(std::make_shared<const std::string>(text), filename);
  Tokenizer* outer_tok = tok_;
  std::string outer_dir = base_dir_;
  tok_ = &tok;
  base_dir_ = base_dir;
  // A file shows itself to be a scene file by its first token, a directive (or a near miss of one,
  // which gets its did-you-mean). Until then nothing of its text reaches a message: a file that is
  // not a scene (a key, a password list named by Include) must not be quoted to whoever reads the
  // error. A file without tokens is an empty scene.
  bool recognised = false, rejected = false;
  try {
    for (Token t = tok.next(); t.kind != TokenKind::End; t = tok.next()) {
      if (!recognised && !looks_like_directive(t)) {
        rejected = true;
        break;
      }
      recognised = true;
      dispatch(t);
    }
  } catch (const Error& e) {
    if (recognised || e.loc().filename != filename) throw;
    rejected = true;  // the first token could not even be read
  }
  if (rejected)
    throw Error(FileLoc{filename, nullptr, 1, 1},
                fmt::format("'{}' does not look like a pbrt-v4 scene file: it does not begin with a directive "
                            "(its text is not quoted)",
                            name));
  tok_ = outer_tok;
  base_dir_ = outer_dir;
}

void SceneParser::parse_file(const fs::path& path, const FileLoc& included_from) {
  const char* what = included_from.filename ? "included file" : "scene file";
  std::error_code exists_error;
  if (!fs::exists(path, exists_error))
    throw Error(included_from, fmt::format("cannot open {} '{}'", what, path.string()));
  // Only regular files, read up to their size (util/input_file.h): not /dev/zero, not a FIFO.
  std::string text = read_input_file(path.string(), what, included_from);
  std::error_code ec;
  std::string key = fs::weakly_canonical(path, ec).string();
  if (ec) key = path.lexically_normal().string();
  if (std::find(open_files_.begin(), open_files_.end(), key) != open_files_.end()) {
    std::string chain;
    for (const auto& f : open_files_) chain += fs::path(f).filename().string() + " -> ";
    throw Error(included_from, fmt::format("include cycle: '{}' is already being read ({}{})",
                                           path.string(), chain, path.filename().string()));
  }
  open_files_.push_back(key);
  parse_text(text, path.string(), path.parent_path().string());
  open_files_.pop_back();
}

void SceneParser::include(const Token& d) {
  Token file = expect_string(d, "file name");
  fs::path path(file.text);
  // Importing a glTF file places its meshes like a Shape "gltf" would (Penumbra's extension).
  std::string ext = path.extension().string();
  if (d.text == "Import" && (ext == ".gltf" || ext == ".glb")) {
    require_world(d);
    ShapeEntity s;
    ParamSet params;
    params.add(Param{"string", "filename", file.loc, {}, {file.text}, {}});
    static_cast<SceneEntity&>(s) = entity_at(d, "gltf", std::move(params));
    take_graphics_state(s);
    desc_.shapes.push_back(std::move(s));
    return;
  }
  if (path.is_relative()) path = fs::path(base_dir_) / path;
  parse_file(path, d.loc);
}

void SceneParser::finish() {
  if (current_object_ >= 0)
    throw Error(desc_.objects[current_object_].loc,
                fmt::format("ObjectBegin '{}' has no matching ObjectEnd", desc_.objects[current_object_].name));
  for (const auto& b : blocks_)
    warning(b.loc,
            fmt::format("{} has no matching {}", b.attribute ? "AttributeBegin" : "TransformBegin",
                        b.attribute ? "AttributeEnd" : "TransformEnd"));
}

void SceneParser::attribute_begin(const Token& d) { blocks_.push_back({true, d.loc, state_}); }

void SceneParser::attribute_end(const Token& d) {
  if (current_object_ >= 0 && blocks_.size() == object_depth_)
    throw Error(d.loc, fmt::format("AttributeEnd closes the ObjectBegin at {} (use ObjectEnd)",
                                   desc_.objects[current_object_].loc.str()));
  close_block(d, true);
}

// pbrt-v4: ObjectBegin opens an attribute block and ObjectEnd closes it; objects do not nest, and
// instances are placed outside object definitions. Names are global; redefining one is an error.
void SceneParser::object_begin(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "object name");
  if (current_object_ >= 0)
    throw Error(d.loc, fmt::format("ObjectBegin inside the definition of object '{}' (at {}): objects do not nest",
                                   desc_.objects[current_object_].name, desc_.objects[current_object_].loc.str()));
  for (const auto& o : desc_.objects)
    if (o.name == name.text)
      throw Error(name.loc, fmt::format("object '{}' redefined (first defined at {})", name.text, o.loc.str()));
  desc_.objects.push_back(ObjectEntity{name.text, d.loc});
  current_object_ = static_cast<int>(desc_.objects.size()) - 1;
  blocks_.push_back({true, d.loc, state_});
  object_depth_ = blocks_.size();
}

void SceneParser::object_end(const Token& d) {
  require_world(d);
  if (current_object_ < 0) throw Error(d.loc, "ObjectEnd without a matching ObjectBegin");
  if (blocks_.size() != object_depth_)
    throw Error(d.loc, fmt::format("ObjectEnd closes the {} at {}", blocks_.back().attribute ? "AttributeBegin" : "TransformBegin",
                                   blocks_.back().loc.str()));
  close_block(d, true);
  current_object_ = -1;
}

void SceneParser::object_instance(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "object name");
  if (current_object_ >= 0)
    throw Error(d.loc, fmt::format("ObjectInstance inside the definition of object '{}': instances do not nest",
                                   desc_.objects[current_object_].name));
  desc_.instances.push_back(InstanceEntity{name.text, name.loc, Mat4(state_.ctm)});
}

void SceneParser::transform_begin(const Token& d) {
  warn_once(d, "TransformBegin is deprecated in pbrt-v4; use AttributeBegin");
  blocks_.push_back({false, d.loc, state_});
}

void SceneParser::transform_end(const Token& d) {
  warn_once(d, "TransformEnd is deprecated in pbrt-v4; use AttributeEnd");
  close_block(d, false);
}

void SceneParser::close_block(const Token& d, bool attribute) {
  const char* begin = attribute ? "AttributeBegin" : "TransformBegin";
  if (blocks_.empty()) throw Error(d.loc, fmt::format("{} without a matching {}", d.text, begin));
  OpenBlock& b = blocks_.back();
  if (b.attribute != attribute)
    throw Error(d.loc, fmt::format("{} closes the {} at {}", d.text,
                                   b.attribute ? "AttributeBegin" : "TransformBegin", b.loc.str()));
  if (attribute) {
    state_ = b.saved;
  } else {
    state_.ctm = b.saved.ctm;  // a transform block restores nothing else
  }
  blocks_.pop_back();
}

void SceneParser::world_begin(const Token& d) {
  if (in_world_)
    throw Error(d.loc, fmt::format("WorldBegin given twice (first at {})", world_begin_loc_.str()));
  in_world_ = true;
  world_begin_loc_ = d.loc;
  desc_.world_begin = d.loc;
  state_.ctm = glm::dmat4(1.0);
  named_coordinate_systems_["world"] = state_.ctm;
}

void SceneParser::world_end(const Token& d) {
  warn_once(d, "WorldEnd is not part of pbrt-v4 and is ignored");
}

void SceneParser::warn_once(const Token& d, const std::string& message) {
  if (warned_.insert(d.text).second) warning(d.loc, message);
}

SceneDescription parse_scene_file(const std::string& path) {
  SceneDescription desc;
  desc.filename = path;
  SceneParser parser(desc);
  parser.parse_file(path, FileLoc{});
  parser.finish();
  return desc;
}

SceneDescription parse_scene_string(const std::string& text, const std::string& name) {
  SceneDescription desc;
  desc.filename = name;
  SceneParser parser(desc);
  parser.parse_text(text, name, "");
  parser.finish();
  return desc;
}

}  // namespace penumbra
