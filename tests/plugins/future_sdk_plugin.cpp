// A plugin compiled with PENUMBRA_SDK_VERSION=999: the loader must refuse it with a clear message.
#include <penumbra/integrator.h>
#include <penumbra/plugin.h>

namespace {
const penumbra::ParamSpec kParams[] = {{"integer", "maxdepth", "5", "unused"}};
penumbra::Object* create(const penumbra::CreateContext&) { return nullptr; }
}  // namespace

PENUMBRA_PLUGIN(Integrator, "future", "built for another SDK version", kParams, create)
