#pragma once
// The free spinning disks of the transfer tests (tests/test_apic.cpp, test_apic_two_phase.cpp,
// test_tpic.cpp): radius 0.5 m about (1, 1) in a 2 m grid of 0.1 m cells, no gravity, no
// boundaries, 2 x 2 points per cell, linear elastic grains (E = 1 MPa, nu = 0.3).
#include <string>

namespace loam_test {

/// One body of density `density` under the scheme `scheme` (the inside of its mapping).
inline std::string disk_yaml(const std::string& shape, const std::string& scheme,
                             const std::string& density = "1000") {
  return "grid: {extent: [2, 2], cell_size: 0.1}\ngravity: [0, 0]\nshape_function: " + shape +
         "\nscheme: {" + scheme +
         "}\nbodies:\n  - name: disk\n    generator: {type: sphere, center: [1, 1], radius: 0.5}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: " +
         density + "}\ntime: {end: 100, cfl: 0.5}\n";
}

/// The double-point scheme's saturated disk: solid points (rho_s = 2650) and liquid points
/// (water, K_w = 20 MPa) at the same places, porosity 0.4, Darcy k = 1e-3 m/s; `extra` is
/// appended inside the scheme's mapping (e.g. ", transfer: apic").
inline std::string double_point_disk_yaml(const std::string& shape, const std::string& extra) {
  return "grid: {extent: [2, 2], cell_size: 0.1}\ngravity: [0, 0]\nshape_function: " + shape +
         "\nscheme: {type: two_phase_double_point, porosity: 0.4, drag: {type: darcy, "
         "hydraulic_conductivity: 1.0e-3}" +
         extra +
         "}\nbodies:\n"
         "  - {name: grains, set: solid, generator: {type: sphere, center: [1, 1], radius: 0.5}, "
         "material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}}\n"
         "  - {name: water, set: liquid, generator: {type: sphere, center: [1, 1], radius: 0.5}, "
         "material: {type: newtonian_fluid, bulk_modulus: 2.0e7, viscosity: 1.0e-3, density: "
         "1000}}\n"
         "time: {end: 100, cfl: 0.5}\n";
}

}  // namespace loam_test
