#pragma once
// The parameters of linear isotropic elasticity shared by several material plugins.
#include "framework/params.hpp"
#include "plausible.hpp"

namespace loam {

/// A schema starting with E (Pa), nu and density (kg/m^3). Soil models take nu in [0, 0.5)
/// (a negative Poisson's ratio is not a soil); general solids allow (-1, 0.5).
inline Schema isotropic_elastic_schema(bool soil) {
  Schema s;
  plausible_modulus(s.real("E", "Pa", "Young's modulus").required().positive());
  ParamSpec& nu = s.real("nu", "-", "Poisson's ratio").required().below(0.5);
  if (soil)
    nu.min(0);
  else
    nu.above(-1);
  plausible_density(s.real("density", "kg/m^3", "mass density").required().positive());
  return s;
}

}  // namespace loam
