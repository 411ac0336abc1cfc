// Why a surface's BSDF is zero between two directions on opposite sides of the surface, in words:
// the wording of `bdptref trace`'s diagnosis of a zero-BSDF connection (src/verify/trace.cpp).
// It repeats the checks of the BSDF's transmission branch (roughValue and evalRoughDielectric in
// src/scene/bsdf_rough_dielectric.cpp) in their order to name the first that fails; no value is
// ever taken from here.
#pragma once

#include "bdptref/bsdf.h"
#include "bdptref/material.h"

#include <string>

namespace bdptref {

// The cause, naming the material as `material` says ("material 2 'frosted'"). wo: the vertex's
// direction towards where the path came from; wi: towards the other end of the connection, on the
// other geometric side (dot(ng, wo) * dot(ng, wi) < 0). Both unit.
std::string zeroTransmissionCause(const MaterialParams& params, const std::string& material, const Vec3& ns, const Vec3& ng,
                                  const Vec3& wo, const Vec3& wi, TransportMode mode);

}  // namespace bdptref
