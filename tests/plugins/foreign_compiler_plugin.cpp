// A plugin that claims another compiler (PENUMBRA_COMPILER_ID is overridden at build time) with the
// runtime's SDK version: the loader must refuse it, naming the file and both compilers.
#include <penumbra/integrator.h>
#include <penumbra/plugin.h>

namespace {
const penumbra::ParamSpec kParams[] = {{"integer", "maxdepth", "5", "unused"}};
penumbra::Object* create(const penumbra::CreateContext&) { return nullptr; }
}  // namespace

PENUMBRA_PLUGIN(Integrator, "foreigncc", "built with another compiler", kParams, create)
