#pragma once
// Output writer plugin interface: one frame per output time, into the run's output directory.
#include <string>
#include <vector>

namespace loam {

template <int D>
class Simulation;

template <int D>
class Writer {
 public:
  static constexpr const char* kind = "writer";
  virtual ~Writer() = default;
  /// `fields` are particle field handles to write besides position.
  virtual void open(const std::string& directory, Simulation<D>&,
                    const std::vector<int>& fields) = 0;
  /// Write one frame; `label` is "" for a regular frame or e.g. "failed" for the last state.
  virtual void write(Simulation<D>&, const std::string& label) = 0;
  virtual void close() {}
};

}  // namespace loam
