#pragma once
// Plausible ranges of material parameters (ParamSpec::plausible): a legal value outside them is
// almost surely a unit slip, and `loam check` and `loam run` warn, located like an error. A
// value that is meant is listed under the run file's accept_warnings.
#include "framework/params.hpp"

namespace loam {

/// A friction or dilation angle in degrees: a nonzero value below 1 deg was meant in radians.
inline ParamSpec& plausible_angle(ParamSpec& p) {
  return p.plausible(1, 89, "an angle in radians typed as degrees?");
}

/// A stiffness in Pa: soils and rocks lie between 1 kPa (a slurry) and 1 TPa.
inline ParamSpec& plausible_modulus(ParamSpec& p) {
  return p.plausible(1e3, 1e12, "a value in kPa or MPa typed as Pa?");
}

/// A density in kg/m^3: between 100 (a foam, a light fluid) and 30 000 (above any mineral).
inline ParamSpec& plausible_density(ParamSpec& p) {
  return p.plausible(100, 30000, "a density in t/m^3 or g/cm^3 typed as kg/m^3?");
}

}  // namespace loam
