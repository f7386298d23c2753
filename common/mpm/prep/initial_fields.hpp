#pragma once
/// A body's initial spin, velocity field and stress field (docs/scene.md, initial fields),
/// applied to the particles mpm-prep made.
#include "mpm/core/columns.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// For the particles of every body with initial fields: v += angular_velocity x (x - c) +
/// velocity_field(x); with a stress_field, sigma (a column "sigma" added to the model, zero
/// for the other bodies) = stress_field(x), the density the one at which the material's EOS
/// gives the field's pressure at zero internal energy, and the mass that density times the
/// particle's volume (the body as drawn is the stressed one). Throws InputError naming the
/// body's key when a formula gives a value that is not finite, or a pressure no density
/// between rho0 / 2 and 20 rho0 gives.
void apply_initial_fields(const Scene& scene, ColumnStore& cols);

}  // namespace mpm
