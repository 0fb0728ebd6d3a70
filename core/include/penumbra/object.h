// Common base of everything a plugin creates. Objects are owned by the runtime.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace penumbra {

class Object {
 public:
  virtual ~Object();
  /// Names of the acceleration or sampling structures this object built ("environment_distribution",
  /// "light_vertex_bvh"), reported in the render stats so tests can check that a scene builds only what
  /// it needs. Asked after preprocessing and again after rendering.
  virtual std::vector<std::string> structures_built() const { return {}; }
  /// Figures worth reporting in the render stats' "integrator_stats" (e.g. connections per eye vertex,
  /// build times), as (name, value) pairs. Asked after rendering.
  virtual std::vector<std::pair<std::string, double>> statistics() const { return {}; }
};

}  // namespace penumbra
