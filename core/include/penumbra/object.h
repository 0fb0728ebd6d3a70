// Common base of everything a plugin creates. Objects are owned by the runtime.
#pragma once

namespace penumbra {

class Object {
 public:
  virtual ~Object();
};

}  // namespace penumbra
