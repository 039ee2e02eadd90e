#pragma once
// Shape-function plugin interface. A shape function fills a StencilBlock for up to kBlock
// consecutive particles: for each particle p and stencil entry k the node index, weight N and
// gradient dN/dx. Blocks are small enough to stay in L1, and the layout [k][p] lets the
// evaluation vectorise across particles; only the scatter/gather that follows is scalar.
#include <cstdint>
#include <type_traits>
#include <vector>

#include "grid.hpp"
#include "particles.hpp"

namespace loam {

template <int D>
class Simulation;
template <int D>
class ParticleSet;
class Diagnostics;

constexpr int kBlock = 64;

/// The per-cell pressure space stable with a shape function's velocity space (the two-phase
/// schemes' pressure_smoothing: cell; framework/cell_projection.hpp): one value per cell
/// (Q1-P0) or a linear function per cell (Q2-P1disc).
enum class CellPressure { kConstant, kLinear };

template <int D>
struct StencilBlock {
  static constexpr int dimension = D;
  int count = 0;              // particles in this block
  int npp = 0;                // stencil entries per particle
  std::vector<int32_t> node;  // [k*kBlock + p]
  std::vector<double> w;      // [k*kBlock + p]
  std::vector<double> grad;   // [(k*D + d)*kBlock + p]

  // The affine transfers' geometry (framework/affine_transfer.hpp). A pass that transfers an
  // affine velocity sets `affine` before evaluating: kOffsets asks for x_I - x_p of every entry,
  // kInertia also for D_p^-1. A tensor-product shape function fills them from its per-axis
  // values (framework/axis_stencil.hpp) and sets `has_affine`; for the others AffineTransfer
  // computes them from the node coordinates. The offsets are kept per axis, as the tensor
  // product forms them: entry k is axis node (k / M^d) % M along axis d, M = axis_nodes, and
  // its offset along d is that axis node's (the affine transfers use the product form).
  enum Affine { kNone = 0, kOffsets = 1, kInertia = 2 };
  Affine affine = kNone;
  bool has_affine = false;
  int axis_nodes = 0;               // M: nodes per axis of the tensor-product stencil
  std::vector<double> dx;           // [(d*M + j)*kBlock + p]: x_I - x_p of axis node j along d
  std::vector<double> inertia_inv;  // [d*kBlock + p]: 1 / D_p(d, d) (D_p diagonal)

  /// Stencil entry k's node along axis d: (k / M^d) % M, for M nodes per axis.
  static constexpr int axis_node(int k, int d, int M) {
    for (int e = 0; e < d; ++e) k /= M;
    return k % M;
  }
  /// Where the offsets of axis node j along axis d start in dx (then one per particle).
  static constexpr size_t axis_offset_index(int M, int d, int j) {
    return (size_t(d) * size_t(M) + size_t(j)) * kBlock;
  }
  /// x_I - x_p along axis d of stencil entry k of particle p (has_affine).
  double offset(int k, int d, int p) const {
    return dx[axis_offset_index(axis_nodes, d, axis_node(k, d, axis_nodes)) + size_t(p)];
  }

  void allocate(int nodes_per_particle) {
    npp = nodes_per_particle;
    node.assign(size_t(npp) * kBlock, 0);
    w.assign(size_t(npp) * kBlock, 0.0);
    grad.assign(size_t(npp) * D * kBlock, 0.0);
    dx.assign(size_t(npp) * D * kBlock, 0.0);  // D * M <= M^D * D
    inertia_inv.assign(size_t(D) * kBlock, 0.0);
  }
};

template <int D>
class ShapeFunction {
 public:
  static constexpr const char* kind = "shape_function";
  virtual ~ShapeFunction() = default;

  /// Stencil entries per particle (entries may carry zero weight), for this step: it may change
  /// in begin_step (CPDI merges its corners' stencils while the domains are small).
  virtual int nodes_per_particle() const = 0;
  /// The most stencil entries per particle over the run: what a scheme allocates.
  virtual int max_nodes_per_particle() const { return nodes_per_particle(); }
  /// Node rows along the slowest axis that a particle in cell row r can touch:
  /// [r - rows_below(), r + rows_above()]. Used to colour slabs for race-free scatter.
  virtual int rows_below() const = 0;
  virtual int rows_above() const = 0;
  /// Whether it runs on a grid split over MPI ranks (docs/parallel.md): it reads and writes only
  /// the particles of this rank and the stored box of nodes, each node as the whole grid's
  /// value. Default false: a run under mpirun refuses it with a located error.
  virtual bool runs_on_ranks() const { return false; }
  /// Request particle fields (e.g. particle domain sizes) and check the set-up.
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// Initialise its fields of particles [begin, end) of a set: every particle at set-up, and
  /// particles a source adds later (Simulation::add_particles).
  virtual void initialize_particles(Simulation<D>&, ParticleSet<D>&, size_t /*begin*/,
                                    size_t /*end*/) {}
  /// Called before every step (e.g. to update particle domains and the reach reported by
  /// rows_below/rows_above). A shape function that cannot continue (a particle domain too
  /// distorted, ...) sets Simulation::failure; the run then stops with exit code 3.
  virtual void begin_step(Simulation<D>&) {}
  /// Whether the stencil of a particle reaches the whole particle domain (GIMP, CPDI, B-splines;
  /// not the linear hats, which see only the particle's cell). Loads applied on the particle's
  /// surface rather than at its centre need it, or they could land on nodes without mass.
  virtual bool stencil_covers_domain() const { return true; }
  /// int N_i dx / h along one axis with nodes 0 .. last (last >= 1 cells): the nodal volume of
  /// node i in cell units, a factor of V_I = int N_I dOmega (e.g. for a porosity field from
  /// particle volumes). Default: the linear hat's, 1/2 at the two end nodes and 1 inside; GIMP
  /// and CPDI, whose weights are the hat averaged over a particle domain inside the grid, share
  /// it.
  virtual double axis_node_volume(int i, int last) const { return i == 0 || i == last ? 0.5 : 1.0; }
  /// sum_k N_i(x_k) / ppc over the lattice x_k = (k + 1/2) h / ppc, k in [0, last ppc): the
  /// nodal volume of node i in cell units as particles generated on the grid-aligned lattice
  /// (framework/body_lattice.hpp) integrate it. A field that compares a particle sum with a
  /// nodal volume (the double-point porosity 1 - V_s,I / V_I) needs this one, or it sees a full
  /// node as partly empty. Default axis_node_volume: the lattice integrates the linear tents
  /// exactly (linear on each sub-cell), and GIMP's and CPDI's weights, domain averages of the
  /// tents over domains that tile the grid.
  virtual double axis_node_lattice_volume(int i, int last, int /*points_per_cell*/) const {
    return axis_node_volume(i, last);
  }
  /// The per-cell pressure space that its nodal forces can balance (framework/cell_projection.hpp):
  /// constant where a cell's nodal forces depend only on its particles' mean pressure (the
  /// linear tents; GIMP and CPDI integrate the tents' gradients), linear where the gradients
  /// vary inside a cell (quadratic B-splines).
  virtual CellPressure cell_pressure() const { return CellPressure::kConstant; }
  /// Fill `out` for particles [begin, begin + count), count <= kBlock. Stencil entries for nodes
  /// outside the grid must carry a valid node index with zero weight and gradient.
  virtual void evaluate(const Grid<D>& grid, const Particles<D>& particles, size_t begin, int count,
                        StencilBlock<D>& out) const = 0;
};

}  // namespace loam

namespace loam {

constexpr int ipow(int b, int e) {
  return e == 0 ? 1 : b * ipow(b, e - 1);
}

/// Call f(std::integral_constant<int, NPP>) with the stencil size as a compile-time constant for
/// the common sizes (2^D, 3^D, 4^D), so inner loops unroll; NPP = 0 means "use the runtime count".
template <int D, class F>
void with_stencil_size(int npp, F&& f) {
  if (npp == ipow(2, D))
    f(std::integral_constant<int, ipow(2, D)>{});
  else if (npp == ipow(3, D))
    f(std::integral_constant<int, ipow(3, D)>{});
  else if (npp == ipow(4, D))
    f(std::integral_constant<int, ipow(4, D)>{});
  else
    f(std::integral_constant<int, 0>{});
}

}  // namespace loam
