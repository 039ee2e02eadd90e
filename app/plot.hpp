#pragma once
// `loam plot RUN`: one figure of any run (tools/loam_plot.py, with the interpreter loam uses for
// its other figures): the particles of a frame coloured by a field, the history and the verify
// series.
#include <string>

namespace loam {

struct PlotOptions {
  std::string run_dir;
  std::string field;  // empty: the first of plastic_strain_eq, pore_pressure, displacement, ...
  int frame = -1;     // -1: the last
  std::string set;    // empty: every particle set
  std::string out;    // empty: RUN/plot.png
};

/// Draws the figure; returns 0, 2 for bad input (its message lists what the run has), 1 when
/// Python or its modules are missing.
int run_plot(const PlotOptions& opt);

}  // namespace loam
