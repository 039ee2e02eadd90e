#pragma once
// The energies of a run (history.csv, summary.json), summed over every phase a scheme carries.
#include <vector>

namespace loam {

struct Energies {
  double kinetic = 0;  // sum 1/2 m |v|^2 over every phase (J; per unit thickness in 2D)
  /// Stored energy: the materials' elastic strain energy plus what a scheme stores itself (the
  /// pore water's compression p^2 n V / (2 K_w) in two-phase schemes); NaN if a material has none.
  double strain = 0;
  double gravity = 0;            // -sum m g . x over every phase
  std::vector<double> momentum;  // sum m v over every phase
};

}  // namespace loam
