// What a scene file says, before any plugin is loaded: the parser turns pbrt-v4 syntax into this,
// the command line may override parts of it (--integrator, --sampler, --spp, --res), and the scene
// builder (core/src/scene/) then loads the plugins it names and builds the renderable Scene.
#pragma once

#include <penumbra/error.h>
#include <penumbra/math.h>
#include <penumbra/params.h>

#include <map>
#include <string>
#include <vector>

namespace penumbra {

/// A directive that names a type and carries parameters: `Integrator "path" "integer maxdepth" [5]`.
struct SceneEntity {
  std::string type;      // "path", "perspective", "diffuse", ...; empty when the scene left it out
  ParamSet params;
  FileLoc loc;           // location of the directive keyword
  std::string base_dir;  // folder of the file the directive is in (for relative file names)
  Mat4 to_world{1.f};    // current transform at the directive (render-space = world space)
  bool reverse_orientation = false;
};

struct ShapeEntity : SceneEntity {
  int material = -1;            // index into SceneDescription::materials, or -1 for a named one
  std::string material_name;    // NamedMaterial in effect (resolved by the builder)
  FileLoc material_loc;         // where that NamedMaterial directive is
  int area_light = -1;          // index into SceneDescription::area_lights, or -1
  // MediumInterface in effect: named media inside and outside ("" = vacuum), and where it was set.
  std::string medium_inside, medium_outside;
  FileLoc medium_loc;
  int object = -1;              // index into SceneDescription::objects when inside ObjectBegin
};

/// `ObjectBegin "name"` ... `ObjectEnd`: shapes placed by instances (pbrt-v4's object instancing).
struct ObjectEntity {
  std::string name;
  FileLoc loc;
};

/// `ObjectInstance "name"`: the object placed with the transform current at the directive.
struct InstanceEntity {
  std::string name;
  FileLoc loc;
  Mat4 to_world{1.f};
};

/// `MakeNamedMedium "name" "string type" "homogeneous" ...`: type is the medium's "string type".
struct MediumEntity : SceneEntity {
  std::string name;
};

/// `Texture "name" "float"|"spectrum" "class" ...`: type is the class (the plugin's name).
struct TextureEntity : SceneEntity {
  std::string name;
  bool spectrum = false;  // "spectrum" (else "float")
};

struct SceneDescription {
  std::string filename;  // the top-level scene file
  SceneEntity camera;    // to_world is the camera-to-world transform (inverse of the CTM at Camera)
  SceneEntity film;
  SceneEntity filter;
  SceneEntity sampler;
  SceneEntity integrator;
  std::vector<TextureEntity> textures;            // in file order
  std::vector<SceneEntity> materials;             // Material and MakeNamedMaterial, in file order
  std::map<std::string, int> named_materials;     // name -> index into materials
  std::vector<SceneEntity> lights;                // LightSource
  std::vector<SceneEntity> area_lights;           // AreaLightSource
  std::vector<ShapeEntity> shapes;
  std::vector<ObjectEntity> objects;              // ObjectBegin, in file order
  std::vector<InstanceEntity> instances;          // ObjectInstance
  std::vector<MediumEntity> media;                // MakeNamedMedium, in file order
  std::map<std::string, int> named_media;         // name -> index into media
  std::string camera_medium;                      // outside medium of the MediumInterface at Camera
  FileLoc camera_medium_loc;
  FileLoc world_begin;   // where WorldBegin is; no filename when the scene has none
};

/// Parses a pbrt-v4 scene file (following Include and Import). Throws Error with a location.
SceneDescription parse_scene_file(const std::string& path);
/// Parses scene text; `name` stands for the file name in messages and Include paths are relative to
/// the current directory.
SceneDescription parse_scene_string(const std::string& text, const std::string& name = "<string>");

}  // namespace penumbra
