// Point force (N; N per unit thickness in 2D) at a fixed position, distributed to the nodes of
// the cell containing it with linear weights, scaled by its time function (or ramped linearly
// over ramp_time).
#include "framework/load_time.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class PointLoad : public Load<D> {
 public:
  static constexpr const char* name = "point";
  static constexpr const char* summary =
      "point force at a fixed position, spread to its cell's nodes";
  static Schema schema() {
    Schema s;
    s.vector("position", "m", "where the force acts").required();
    s.vector("force", "N", "force vector").required();
    add_load_time_keys(s);
    return s;
  }
  explicit PointLoad(const Params& p) : params_(p), time_(p) {
    for (int d = 0; d < D; ++d) {
      x_[size_t(d)] = p.vec("position")[size_t(d)];
      f_[size_t(d)] = p.vec("force")[size_t(d)];
    }
  }
  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!sim.grid.inside(x_)) {
      diag.error(params_.where("position"), params_.path("position"),
                 "the point is outside the grid");
      return;
    }
    const auto& g = sim.grid;
    for (int k = 0; k < (1 << D); ++k) {
      std::array<int, D> ijk{};
      double w = 1;
      for (int d = 0; d < D; ++d) {
        int c = g.cell_of(x_[size_t(d)], d);
        double r = (x_[size_t(d)] - g.origin[size_t(d)]) * g.inv_cell[size_t(d)] - c;
        bool up = (k >> d) & 1;
        ijk[size_t(d)] = c + (up ? 1 : 0);
        w *= up ? r : 1 - r;
      }
      if (!g.stores(ijk)) continue;  // under mpirun: another rank's box (docs/parallel.md)
      nodes_.push_back(g.node_index(ijk));
      weights_.push_back(w);
    }
  }
  /// Added to every stored copy of its nodes, after the nodal sums are complete, as gravity.
  bool runs_on_ranks() const override { return true; }
  bool uses_grid_forces() const override { return true; }
  void apply_to_grid(Simulation<D>&, const NodalVector& force, double t) override {
    const double s = time_(t);
    for (size_t k = 0; k < nodes_.size(); ++k)
      for (int d = 0; d < D; ++d) force.at(nodes_[k], d) += s * weights_[k] * f_[size_t(d)];
  }

 private:
  Params params_;
  LoadTime<D> time_;
  std::array<double, D> x_{}, f_{};
  std::vector<size_t> nodes_;
  std::vector<double> weights_;
};

LOAM_REGISTER(Load, PointLoad)

}  // namespace loam
