#pragma once
// Sensors: the form factor from a differential element (a point with a unit normal, facing
// the scene) to every patch, with occlusion. A sensor takes no part in the solve and is not
// drawn; its irradiance is sum_j F(dA -> j) B_j. Each entry takes the most exact path its
// geometry allows, as the patch-to-patch factors do: Lambert's formula for an unblocked
// polygon, the contour integral for an unblocked disk or cylinder patch that faces the point,
// the sphere-region contour for a sphere patch, and otherwise an adaptive 2-D cubature over the
// patch with every blocker tested.
#include <vector>

#include "formfactor/form_factor.h"
#include "geometry/scene_geometry.h"

namespace radiosa {

struct SensorFactors {
    std::vector<double> F;      // F(dA -> patch j), in patch order
    std::vector<double> error;  // each entry's error estimate
    long long closed_form = 0;  // entries by a contour formula (the rest numerically or zero)
};

// sum_j F(dA -> j) B_j per channel; with `error`, also sum_j (estimate of F(dA -> j)) B_j.
Rgb sensor_irradiance(const SensorFactors& s, const std::vector<Rgb>& B, Rgb* error = nullptr);

// `tolerance`: absolute, per entry. Throws nothing for valid input.
SensorFactors sensor_factors(const SceneGeometry& g, const Vec3& x, const Vec3& unit_normal, double tolerance,
                             bool visibility);

}  // namespace radiosa
