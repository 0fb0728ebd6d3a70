// Which lobes a BxDF's sampling may choose from (pbrt-v4's BxDFReflTransFlags): the layered BxDF
// asks an interface for "transmission only" or "reflection only", and then sample_f() returns the
// density conditional on that choice.
#pragma once

#include <cstdint>

namespace penumbra::bxdf {

enum class Lobes : uint32_t { Reflection = 1u, Transmission = 2u, All = 3u };

inline bool allows(Lobes allowed, Lobes lobe) {
  return (static_cast<uint32_t>(allowed) & static_cast<uint32_t>(lobe)) != 0;
}

}  // namespace penumbra::bxdf
