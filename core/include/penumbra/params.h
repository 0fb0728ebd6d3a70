// Typed parameter lists: `"float fov" [ 45 ]` in a scene file becomes one Param in a ParamSet.
// Every object created from a scene (plugins and the core's camera, film, filter and shapes)
// declares its parameters once in a ParamSpec table. The table feeds `penumbra plugins`, supplies
// defaults, and validates the scene: an unknown name, a wrong type or a wrong number of values is an
// error located at the parameter ("unknown parameter 'maxdeph' for integrator 'path'; did you mean
// 'maxdepth'?").
#pragma once

#include <penumbra/color.h>
#include <penumbra/error.h>
#include <penumbra/math.h>

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace penumbra {

/// One declared parameter: pbrt type name ("integer", "float", "bool", "string", "rgb", "point2",
/// "point3", "vector3", "normal"), name, default value as scene-file text ("5", "0.5 0.5 0.5",
/// "true", "box"; empty when there is none) and a one-line description.
/// A type ending in "[]" ("point3[]") takes any number of values (meshes); others take one value.
/// Type "float|spectrum" takes one float or a spectrum ("spectrum", "rgb" or "blackbody": pbrt-v4's
/// dielectric "eta"); get_float() then returns the spectrum's luminance-weighted mean (the Y of its
/// RGB), since one value is all an RGB renderer can refract with.
/// Type "unsupported" declares a pbrt parameter Penumbra knows but does not implement: giving it is
/// an error that says so (the doc text explains why or what to use instead).
struct ParamSpec {
  const char* type;
  const char* name;
  const char* default_value;
  const char* doc;
};

/// One parameter as written in a scene file, with its location.
struct Param {
  std::string type;   // as written: "float", "rgb", "spectrum", "blackbody", "point3", ...
  std::string name;
  FileLoc loc;
  std::vector<double> numbers;       // integer, float, rgb, point, vector, normal values; the RGB
                                     // of a spectrum or blackbody (converted when the scene is read)
  std::vector<std::string> strings;  // string values
  std::vector<bool> bools;           // bool values
  bool from_attribute = false;       // a default from pbrt-v4's `Attribute` directive: dropped, not an
                                     // error, when the object has no parameter of that name
  size_t count() const { return numbers.size() + strings.size() + bools.size(); }
};

class ParamSet {
 public:
  /// Adds a parameter; a second parameter with the same name is an error at its location.
  void add(Param p);
  /// Replaces or adds a value without a location (command-line overrides).
  void set_int(const std::string& name, int v);
  void set_string(const std::string& name, const std::string& v);
  void set_bool(const std::string& name, bool v);

  const Param* find(const std::string& name) const;
  bool has(const std::string& name) const { return find(name) != nullptr; }
  const std::vector<Param>& params() const { return params_; }

  /// Checks every parameter against `spec` (name, type, value count) and keeps the spec for
  /// defaults. `what` names the object in messages, e.g. "integrator 'path'". Throws Error.
  void validate(std::span<const ParamSpec> spec, const std::string& what);

  // Single values: the given value, else the spec default, else `fallback`.
  int get_int(const std::string& name, int fallback = 0) const;
  float get_float(const std::string& name, float fallback = 0.f) const;
  bool get_bool(const std::string& name, bool fallback = false) const;
  std::string get_string(const std::string& name, const std::string& fallback = "") const;
  Rgb get_rgb(const std::string& name, Rgb fallback = Rgb(0.f)) const;
  Vec3 get_point3(const std::string& name, Vec3 fallback = Vec3(0.f)) const;

  // Arrays (empty when absent).
  std::vector<int> get_ints(const std::string& name) const;
  std::vector<float> get_floats(const std::string& name) const;
  std::vector<Vec2> get_point2s(const std::string& name) const;
  std::vector<Vec3> get_point3s(const std::string& name) const;  // also vectors and normals

  /// Location of a parameter (or an empty location) for error messages.
  FileLoc loc_of(const std::string& name) const;

 private:
  const Param* find_or_default(const std::string& name) const;
  std::vector<Param> params_;
  std::vector<Param> defaults_;  // parsed from the spec by validate()
};

/// Levenshtein distance, used for "did you mean" suggestions.
size_t edit_distance(const std::string& a, const std::string& b);

}  // namespace penumbra
