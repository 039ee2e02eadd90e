#pragma once
// F-bar against volumetric locking (de Souza Neto, Peric, Dutko & Owen 1996, "Design of simple
// low order finite elements for large strain analysis of nearly incompressible solids"), with
// the volume averaged through the grid's nodes as Zhao, Jiang & Choo (2023, "Circumventing
// volumetric locking in explicit material point methods: A simple, efficient, and general
// approach") do for explicit MPM. Nearly incompressible plastic flow (Tresca, Mohr-Coulomb with
// psi = 0, the critical state) asks every particle to keep its volume; with one volume
// constraint per particle against D velocities per node the grid cannot find a mode that does,
// and the collapse load comes out too high. F-bar relaxes the constraint to about one per node:
// each particle's increment dF = I + L dt keeps its deviatoric part and takes the volume change
// of its neighbourhood,
//   dF_bar = (dJ_bar / dJ)^(1/D) dF,   dJ = det dF,
//   dJ_bar(x_p) = sum_I N_I(x_p) dJ_I,  dJ_I = sum_q N_I(x_q) V_q dJ_q / sum_q N_I(x_q) V_q,
// with the linear tents N of the particle's cell whatever the shape function (a continuous
// bilinear/trilinear field, one value per node) and the volumes V^n. The material updates its
// stress with
//   L_bar = (dF_bar - I) / dt = alpha L + (alpha - 1) / dt I,  alpha = (dJ_bar / dJ)^(1/D),
// and the volume with det dF_bar = dJ_bar; the internal force keeps each particle's own stress:
// the mean stress averaged the same way (the B-bar form, Hughes 1980) is one-sided at a free
// surface and a held base, a spurious force on a body at rest under gravity. The average is per
// node, not per cell (Q1-P0): two particles of one cell that expand and contract alike have no
// volumetric stiffness in a cell mean, and under perfect plasticity barely any deviatoric one
// (docs/volumetric_locking.md gives the measurements behind both choices). Rigid motion keeps dJ =
// 1 everywhere, so it stays free of stress. Bodies on their own velocity fields (contact) are
// averaged each on their own; a rigid body's particles keep their own L. The nodal sums run in the
// scatter's colour-parallel blocks (the same bits at a given thread count, as the P2G) and are
// completed over the ranks under mpirun.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "boundary.hpp"
#include "grid.hpp"
#include "params.hpp"
#include "particle_set.hpp"
#include "particles.hpp"
#include "ranks.hpp"
#include "tensor.hpp"

namespace loam {

template <int D>
class Simulation;

/// How a scheme treats the volume change of nearly incompressible flow.
enum class Volumetric { kNone, kFbar };

/// A scheme's `volumetric` parameter (fbar, or none: each particle's own volume change).
inline Volumetric volumetric_of(const Params& p) {
  return p.text("volumetric") == "fbar" ? Volumetric::kFbar : Volumetric::kNone;
}

template <int D>
class Fbar {
 public:
  static constexpr int kNoGroup = -1;  // a particle that keeps its own L (a rigid body's)

  explicit Fbar(Volumetric v = Volumetric::kNone) : on_(v == Volumetric::kFbar) {}
  bool on() const { return on_; }

  /// At the step's first scatter (the positions its velocity gradients are taken at): each
  /// particle's cell and the weights V_p N_I(x_p) of the cell's corners, and the nodal weights
  /// W_I = sum_p V_p N_I(x_p) of each group. `group(set, i)`: the velocity field of particle i
  /// of set slot `set` among `groups`, or kNoGroup.
  template <class Group>
  void locate(Simulation<D>& sim, int groups, Group&& group) {
    groups_ = groups;
    stores_.resize(sim.sets.size());
    for (size_t set = 0; set < sim.sets.size(); ++set) locate_set(sim, set);
    weights_.assign(size_t(groups) * sim.grid.num_nodes, 0.0);
    scatter(sim, group, weights_, nullptr);
  }

  /// Keep particle i's velocity gradient and volume ratio det(I + L dt) (set slot `set`); the
  /// stress update waits for project_volume_ratios().
  void keep(size_t set, size_t i, const double (&l)[D][D], double dt) {
    Store& s = stores_[set];
    double* dst = s.l.data() + i * size_t(D * D);
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) dst[a * D + b] = l[a][b];
    s.dj[i] = det_increment<D>(l, dt);
  }
  /// Size the kept gradients and volume ratios of every set before a gradient pass.
  void resize(const Simulation<D>& sim) {
    for (size_t s = 0; s < sim.sets.size(); ++s) {
      stores_[s].l.resize(sim.sets[s].size() * size_t(D * D));
      stores_[s].dj.resize(sim.sets[s].size());
    }
  }

  /// The kept volume ratios projected: dJ_bar of every particle.
  template <class Group>
  void project_volume_ratios(Simulation<D>& sim, Group&& group) {
    project(sim, group, &Store::dj, &Store::dj_bar);
  }

  /// Particle i's L_bar (the header's equation); its own L where a volume ratio is not
  /// positive (the step's stability check reports the inverted particle).
  void averaged_gradient(size_t set, size_t i, double dt, double (&l)[D][D]) const {
    const Store& s = stores_[set];
    const double* src = s.l.data() + i * size_t(D * D);
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) l[a][b] = src[a * D + b];
    const double dj = s.dj[i], dj_bar = s.dj_bar[i];
    if (!(dj > 0 && dj_bar > 0)) return;
    const double ratio = dj_bar / dj;
    const double alpha = D == 1 ? ratio : D == 2 ? std::sqrt(ratio) : std::cbrt(ratio);
    for (int a = 0; a < D; ++a) {
      for (int b = 0; b < D; ++b) l[a][b] *= alpha;
      l[a][a] += (alpha - 1) / dt;
    }
  }

 private:
  static constexpr int K = 1 << D;  // a cell's corners
  struct Store {
    std::vector<double> l, dj, dj_bar;  // D x D, 1, 1 per particle
    std::vector<size_t> corner;         // the cell's lower corner (stored node)
    std::vector<double> wv;             // V_p N_I(x_p) of the K corners
  };

  void locate_set(const Simulation<D>& sim, size_t set) {
    const Particles<D>& P = sim.sets[set].particles;
    Store& s = stores_[set];
    s.corner.resize(P.size());
    s.wv.resize(P.size() * K);
    const Grid<D>& g = sim.grid;
    std::array<const double*, D> x{};
    for (int d = 0; d < D; ++d) x[size_t(d)] = P.col(P.position, d);
    const double* V = P.col(P.volume);
    size_t* corner = s.corner.data();
    double* wv = s.wv.data();
    const long np = long(P.size());
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long i = 0; i < np; ++i) {
      std::array<int, D> lower{};
      double xi[D];
      for (int d = 0; d < D; ++d) {
        lower[size_t(d)] = g.cell_of(x[size_t(d)][i], d);
        xi[d] = std::clamp(
            (x[size_t(d)][i] - g.origin[size_t(d)]) * g.inv_cell[size_t(d)] - lower[size_t(d)], 0.0,
            1.0);
      }
      corner[i] = g.node_index(lower);
      for (int k = 0; k < K; ++k) {
        double w = V[i];
        for (int d = 0; d < D; ++d) w *= (k >> d) & 1 ? xi[d] : 1 - xi[d];
        wv[size_t(i) * K + size_t(k)] = w;
      }
    }
  }

  /// nodal[g * nodes + I] += sum over group g's particles p of V_p N_I(x_p) (s.*values)[p] (1
  /// without values), by the colour-parallel scatter (race-free: a cell's corners are in the
  /// stencil the partition was made for), completed over the ranks.
  template <class Group>
  void scatter(Simulation<D>& sim, Group& group, std::vector<double>& nodal,
               std::vector<double> Store::*values) {
    const size_t nodes = sim.grid.num_nodes;
    const std::array<size_t, K> offset = corner_offsets(sim.grid);
    double* const out = nodal.data();
    sim.scatter_blocks([&](ParticleSet<D>& set, size_t b, int count, int) {
      const size_t slot = sim.set_slot(set);
      const Store& s = stores_[slot];
      const double* f = values ? (s.*values).data() : nullptr;
      const double* wv = s.wv.data();
      const size_t* corner = s.corner.data();
      for (size_t i = b; i < b + size_t(count); ++i) {
        const int g = group(slot, i);
        if (g == kNoGroup) continue;
        const double fi = f ? f[i] : 1.0;
        double* node = out + size_t(g) * nodes + corner[i];
        for (int k = 0; k < K; ++k) node[offset[size_t(k)]] += wv[i * K + size_t(k)] * fi;
      }
    });
    std::vector<NodalArray> arrays;
    for (int g = 0; g < groups_; ++g) arrays.push_back({out + size_t(g) * nodes, 1, 1});
    sim.complete_nodes(arrays);
    join_periodic(sim, out);
  }
  /// Along a periodic axis a face node and its partner on the other face are one node (the
  /// periodic condition joins their masses and momenta the same way): each pair's sums go to
  /// both.
  void join_periodic(const Simulation<D>& sim, double* nodal) {
    if (periodic_pairs_.empty())
      for (int a = 0; a < D; ++a)
        if (sim.held_faces.period[size_t(a)] > 0) {
          const auto lo = face_nodes(sim.grid, Face{a, false});
          const auto hi = face_nodes(sim.grid, Face{a, true});
          for (size_t k = 0; k < lo.size(); ++k) periodic_pairs_.push_back({lo[k], hi[k]});
        }
    const size_t nodes = sim.grid.num_nodes;
    for (int g = 0; g < groups_; ++g)
      for (const auto& [lo, hi] : periodic_pairs_) {
        double* n = nodal + size_t(g) * nodes;
        n[lo] = n[hi] = n[lo] + n[hi];
      }
  }

  /// (s.*out)[i] = (s.*in)[i] projected onto the continuous (bi/tri)linear nodal field of its
  /// group: sum_p V_p N_I(x_p) in_p / W_I at the nodes, sum_I N_I(x_p) of that at the
  /// particle; in itself for kNoGroup.
  template <class Group>
  void project(Simulation<D>& sim, Group& group, std::vector<double> Store::*in,
               std::vector<double> Store::*out) {
    const size_t nodes = sim.grid.num_nodes;
    values_.assign(size_t(groups_) * nodes, 0.0);
    scatter(sim, group, values_, in);
    const long n_all = long(values_.size());
    double* mean = values_.data();
    const double* W = weights_.data();
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long n = 0; n < n_all; ++n) mean[n] = W[n] > 0 ? mean[n] / W[n] : 0.0;
    const std::array<size_t, K> offset = corner_offsets(sim.grid);
    for (size_t set = 0; set < stores_.size(); ++set) {
      Store& s = stores_[set];
      const double* V = sim.sets[set].particles.col(sim.sets[set].particles.volume);
      (s.*out).resize(s.corner.size());
      const double* f = (s.*in).data();
      double* o = (s.*out).data();
      const double* wv = s.wv.data();
      const size_t* corner = s.corner.data();
      const long np = long(s.corner.size());
#pragma omp parallel for schedule(static) num_threads(sim.threads)
      for (long i = 0; i < np; ++i) {
        const int g = group(set, size_t(i));
        if (g == kNoGroup) {
          o[i] = f[i];
          continue;
        }
        const double* node = mean + size_t(g) * nodes + corner[i];
        double sum = 0;
        for (int k = 0; k < K; ++k) sum += wv[size_t(i) * K + size_t(k)] * node[offset[size_t(k)]];
        o[i] = sum / V[i];  // sum_k wv_k = V_p
      }
    }
  }
  /// Stored-node offsets of a cell's 2^D corners from its lower one.
  static std::array<size_t, K> corner_offsets(const Grid<D>& g) {
    std::array<size_t, K> offset{};
    for (int k = 0; k < K; ++k)
      for (int d = 0; d < D; ++d)
        if ((k >> d) & 1) offset[size_t(k)] += size_t(g.node_stride[size_t(d)]);
    return offset;
  }

  bool on_ = false;
  int groups_ = 1;
  std::vector<Store> stores_;    // per set
  std::vector<double> weights_;  // per group and node: W_I
  std::vector<double> values_;   // per group and node: sum V N value, then its mean
  std::vector<std::pair<size_t, size_t>> periodic_pairs_;  // join_periodic
};

}  // namespace loam
