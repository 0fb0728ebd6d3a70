#include "scene/composite_materials.h"

#include <fmt/core.h>

#include "scene/mix_bsdf.h"

namespace penumbra {

namespace {

const ParamSpec kMixParams[] = {
    {"string[]", "materials", "", "the two named materials to mix"},
    {"float", "amount", "0.5", "probability of the second material, in [0, 1]"},
};
const ParamSpec kInterfaceParams[] = {{"unsupported", "displacement", "", "an interface has no surface"}};

class CompositeBuilder {
 public:
  CompositeBuilder(const SceneDescription& desc, std::vector<std::unique_ptr<Bsdf>>& bsdfs)
      : desc_(desc), bsdfs_(bsdfs), state_(desc.materials.size(), State::Todo) {}

  // The BSDF of material i (nullptr for "interface"), building mixes first when they are needed.
  const Bsdf* build(size_t i) {
    const SceneEntity& m = desc_.materials[i];
    if (m.type == "interface") {
      ParamSet p = m.params;
      p.validate(kInterfaceParams, "material 'interface'");
      return nullptr;
    }
    if (m.type != "mix" || state_[i] == State::Done) return bsdfs_[i].get();
    if (state_[i] == State::Building) throw Error(m.loc, "this mix material contains itself");
    state_[i] = State::Building;
    ParamSet p = m.params;
    p.validate(kMixParams, "material 'mix'");
    const Param* names = p.find("materials");
    if (!names || names->strings.size() != 2)
      throw Error(names ? names->loc : m.loc, "material 'mix' needs \"string materials\" with two named materials");
    const Bsdf* parts[2];
    for (int k = 0; k < 2; ++k) {
      auto it = desc_.named_materials.find(names->strings[k]);
      if (it == desc_.named_materials.end())
        throw Error(names->loc, fmt::format("named material '{}' is not defined", names->strings[k]));
      parts[k] = build(static_cast<size_t>(it->second));
      if (!parts[k])
        throw Error(names->loc, fmt::format("mixing with the 'interface' material '{}' is not supported",
                                            names->strings[k]));
    }
    float amount = p.get_float("amount");
    if (!(amount >= 0.f && amount <= 1.f)) throw Error(p.loc_of("amount"), "amount must be in [0, 1]");
    bsdfs_[i] = std::make_unique<MixBsdf>(*parts[0], *parts[1], amount);
    state_[i] = State::Done;
    return bsdfs_[i].get();
  }

 private:
  enum class State { Todo, Building, Done };
  const SceneDescription& desc_;
  std::vector<std::unique_ptr<Bsdf>>& bsdfs_;
  std::vector<State> state_;
};

}  // namespace

bool is_composite_material(const std::string& type) { return type == "mix" || type == "interface"; }

void build_composite_materials(const SceneDescription& desc, std::vector<std::unique_ptr<Bsdf>>& bsdfs) {
  CompositeBuilder builder(desc, bsdfs);
  for (size_t i = 0; i < desc.materials.size(); ++i)
    if (is_composite_material(desc.materials[i].type)) builder.build(i);
}

}  // namespace penumbra
