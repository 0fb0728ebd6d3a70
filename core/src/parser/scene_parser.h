// The state machine behind parse_scene_file: pbrt-v4's graphics state (current transform, material,
// area light, orientation), its attribute stack, named coordinate systems, and the files being
// read. Directive handlers are split by theme over parser.cpp, transform_directives.cpp and
// entity_directives.cpp.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "parser/scene_description.h"
#include "parser/tokenizer.h"

namespace penumbra {

/// What AttributeBegin saves and AttributeEnd restores.
struct GraphicsState {
  glm::dmat4 ctm{1.0};  // double so that inverting camera transforms loses nothing
  bool reverse_orientation = false;
  int material = -1;
  std::string material_name;
  FileLoc material_loc;
  int area_light = -1;
  std::string medium_inside, medium_outside;  // MediumInterface ("" = vacuum)
  FileLoc medium_loc;
  // Attribute "shape"|"light"|"material"|"medium"|"texture": defaults for the parameters of the
  // directives of that kind that follow (a directive's own parameters win).
  std::map<std::string, ParamSet> attributes;
};

class SceneParser {
 public:
  explicit SceneParser(SceneDescription& desc) : desc_(desc) {}

  /// Parses a file; `included_from` is the Include directive's location (empty for the top file).
  void parse_file(const std::filesystem::path& path, const FileLoc& included_from);
  /// Parses text standing for file `name`, whose relative paths resolve against `base_dir`.
  void parse_text(const std::string& text, const std::string& name, const std::string& base_dir);
  /// Reports what the scene left open (blocks without End).
  void finish();

 private:
  using Handler = void (SceneParser::*)(const Token&);
  void dispatch(const Token& directive);
  static bool looks_like_directive(const Token& first);
  static const std::map<std::string, Handler>& handlers();

  // Reading arguments.
  Token expect_string(const Token& directive, const char* what);
  std::vector<double> read_numbers(const Token& directive, size_t n);
  glm::dmat4 read_matrix(const Token& directive);
  SceneEntity make_entity(const Token& directive, const char* what);
  SceneEntity entity_at(const Token& directive, std::string type, ParamSet params);
  void require_options(const Token& directive);
  void require_world(const Token& directive);
  void warn_once(const Token& directive, const std::string& message);

  // Transforms (transform_directives.cpp).
  void identity(const Token& d);
  void translate(const Token& d);
  void scale(const Token& d);
  void rotate(const Token& d);
  void look_at(const Token& d);
  void transform(const Token& d);
  void concat_transform(const Token& d);
  void coordinate_system(const Token& d);
  void coord_sys_transform(const Token& d);

  // Blocks and files (parser.cpp).
  void attribute_begin(const Token& d);
  void attribute_end(const Token& d);
  void transform_begin(const Token& d);
  void transform_end(const Token& d);
  void close_block(const Token& d, bool attribute);
  void include(const Token& d);
  void world_begin(const Token& d);
  void world_end(const Token& d);

  // Scene objects and options (entity_directives.cpp).
  void camera(const Token& d);
  void film(const Token& d);
  void pixel_filter(const Token& d);
  void sampler(const Token& d);
  void integrator(const Token& d);
  void set_option_entity(const Token& d, SceneEntity& slot, const char* what);
  void material(const Token& d);
  void make_named_material(const Token& d);
  void named_material(const Token& d);
  void area_light_source(const Token& d);
  void light_source(const Token& d);
  void shape(const Token& d);
  void take_graphics_state(ShapeEntity& s) const;  // material, area light, media
  void make_named_medium(const Token& d);
  void object_begin(const Token& d);
  void object_end(const Token& d);
  void object_instance(const Token& d);
  void attribute(const Token& d);
  void medium_interface(const Token& d);
  void texture(const Token& d);
  void reverse_orientation(const Token& d);
  void accelerator(const Token& d);
  void color_space(const Token& d);
  void option(const Token& d);

  struct OpenBlock {
    bool attribute;  // AttributeBegin (true) or the deprecated TransformBegin
    FileLoc loc;
    GraphicsState saved;
  };

  SceneDescription& desc_;
  GraphicsState state_;
  std::vector<OpenBlock> blocks_;
  std::map<std::string, glm::dmat4> named_coordinate_systems_;
  bool in_world_ = false;
  int current_object_ = -1;              // the ObjectBegin being read, or -1
  size_t object_depth_ = 0;              // blocks_.size() just after that ObjectBegin
  FileLoc world_begin_loc_;
  std::set<std::string> warned_;
  std::vector<std::string> open_files_;  // canonical paths of the Include chain, for cycles
  Tokenizer* tok_ = nullptr;             // the file being read
  std::string base_dir_;                 // its folder
};

}  // namespace penumbra
