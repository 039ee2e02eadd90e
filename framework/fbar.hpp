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
//   dF_bar = (dJ_bar / dJ)^(1/D) dF,   dJ = det dF,   dJ_bar = P dJ,
// where P projects a particle field onto the continuous (bi/tri)linear nodal field of the
// linear tents N of each particle's cell (whatever the shape function), in the V-weighted L2
// sense: nodal values a = M^-1 b, M_IJ = sum_p V_p N_I(x_p) N_J(x_p) (the consistent mass),
// b_I = sum_p V_p N_I(x_p) f_p, and (P f)_p = sum_I N_I(x_p) a_I. The material updates its
// stress with
//   L_bar = (dF_bar - I) / dt = alpha L + (alpha - 1) / dt I,  alpha = (dJ_bar / dJ)^(1/D),
// and its volume with det dF_bar = dJ_bar. The internal force takes the mean normal stress
// projected the same way, f_I = sum_p V_p (sigma_p + (P m - m)_p I) grad N_I (m = sum_d
// sigma_dd / D): the B-bar form (Hughes 1980), whose power is the stress power sum_p V_p
// sigma_p : L_bar_p the materials store, because P is symmetric in the V-weighted product.
// Without that consistency dilatant flow gains energy: the dilating band of an infinite slope
// (psi = phi) heaved and failed at 0.84 of its strength. P reproduces every linear field, at a
// free surface and a held base too, so a body at rest under gravity feels the force it would
// without F-bar; a lumped nodal average (b_I / sum_J M_IJ) is one-sided there, and its spurious
// force made a frictional layer with psi = 0 creep at full strength (docs/volumetric_locking.md).
// The average is per node, not per cell (Q1-P0): two particles of one cell that expand and
// contract alike have no volumetric stiffness in a cell mean. Rigid motion keeps dJ = 1, so it
// stays free of stress. Bodies on their own velocity fields (contact) are projected each on
// their own; a rigid body's particles keep their own L. M is assembled each step in the
// scatter's colour-parallel blocks (the same bits on any number of threads, as the P2G) and
// solved by a fixed number of conjugate-gradient steps preconditioned with its row sums;
// products and sums are completed over the ranks under mpirun and joined across periodic
// faces. The projection is global: an error at a body's face (where nodal velocities are
// averages) reaches into it, decaying by about a third per cell.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
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
    row_offsets(sim.grid);
    weights_.assign(size_t(groups) * sim.grid.num_nodes + 2 * pad_, 0.0);
    scatter(sim, group, at(weights_), nullptr);
    index_nodes(sim);
    assemble_mass(sim, group);
  }

  /// Keep particle i's velocity gradient and volume change det(I + L dt) - 1 (set slot `set`);
  /// the stress update waits for project_volume_ratios().
  void keep(size_t set, size_t i, const double (&l)[D][D], double dt) {
    Store& s = stores_[set];
    double* dst = s.l.data() + i * size_t(D * D);
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) dst[a * D + b] = l[a][b];
    s.dj[i] = volume_change<D>(l, dt);
  }
  /// Size the kept gradients and volume changes of every set before a gradient pass.
  void resize(const Simulation<D>& sim) {
    for (size_t s = 0; s < sim.sets.size(); ++s) {
      stores_[s].l.resize(sim.sets[s].size() * size_t(D * D));
      stores_[s].dj.resize(sim.sets[s].size());
    }
  }

  /// The kept volume changes projected: dJ_bar - 1 of every particle.
  template <class Group>
  void project_volume_ratios(Simulation<D>& sim, Group&& group) {
    project(sim, group, &Store::dj, &Store::dj_bar);
  }

  /// The shift m_bar - m of each particle's mean normal stress over the D axes, m = sum_d
  /// sigma_dd / D, to its projection, which the internal force adds to sigma_dd (the header's
  /// B-bar form); shifts(set) after.
  template <class Group>
  void project_mean_stress(Simulation<D>& sim, Group&& group) {
    for (size_t set = 0; set < stores_.size(); ++set) {
      const Particles<D>& P = sim.sets[set].particles;
      std::array<const double*, D> sig{};
      for (int d = 0; d < D; ++d) sig[size_t(d)] = P.col(P.stress, voigt_index(d, d));
      std::vector<double>& m = stores_[set].mean;
      m.resize(P.size());
      const long np = long(P.size());
#pragma omp parallel for schedule(static) num_threads(sim.threads)
      for (long i = 0; i < np; ++i) {
        double sum = 0;
        for (int d = 0; d < D; ++d) sum += sig[size_t(d)][i];
        m[size_t(i)] = sum / D;
      }
    }
    project(sim, group, &Store::mean, &Store::shift);
    for (Store& s : stores_) {
      double* shift = s.shift.data();
      const double* m = s.mean.data();
      const long np = long(s.shift.size());
#pragma omp parallel for schedule(static) num_threads(sim.threads)
      for (long i = 0; i < np; ++i) shift[i] -= m[i];
    }
  }
  const double* shifts(size_t set) const {
    return stores_[set].shift.data();
  }

  /// Particle i's L_bar (the header's equation); its own L where a volume ratio (1 + change)
  /// is not positive (the step's stability check reports the inverted particle).
  void averaged_gradient(size_t set, size_t i, double dt, double (&l)[D][D]) const {
    const Store& s = stores_[set];
    const double* src = s.l.data() + i * size_t(D * D);
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) l[a][b] = src[a * D + b];
    const double dj = 1 + s.dj[i], dj_bar = 1 + s.dj_bar[i];
    if (!(dj > 0 && dj_bar > 0)) return;
    const double ratio = dj_bar / dj;
    const double alpha = D == 1 ? ratio : D == 2 ? std::sqrt(ratio) : std::cbrt(ratio);
    for (int a = 0; a < D; ++a) {
      for (int b = 0; b < D; ++b) l[a][b] *= alpha;
      l[a][a] += (alpha - 1) / dt;
    }
  }

 private:
  static constexpr int K = 1 << D;                        // a cell's corners
  static constexpr int S = D == 1 ? 3 : D == 2 ? 9 : 27;  // a node's row: the 3^D around it
  static constexpr int kProducts = 20;                    // the solve's conjugate-gradient steps
  /// kEntry[k][l]: the entry of corner l in the row of corner k (offset l - k per axis).
  static constexpr std::array<std::array<int, K>, K> entries() {
    std::array<std::array<int, K>, K> e{};
    for (int k = 0; k < K; ++k)
      for (int l = 0; l < K; ++l) {
        int o = 0, p3 = 1;
        for (int d = 0; d < D; ++d, p3 *= 3) o += (((l >> d) & 1) - ((k >> d) & 1) + 1) * p3;
        e[size_t(k)][size_t(l)] = o;
      }
    return e;
  }
  static constexpr std::array<std::array<int, K>, K> kEntry = entries();
  struct Store {
    // Per particle: L (D x D), the volume change det(I + L dt) - 1 and its projection, the
    // mean normal stress and its projection's shift.
    std::vector<double> l, dj, dj_bar, mean, shift;
    std::vector<size_t> corner;  // the cell's lower corner (stored node)
    std::vector<double> wv;      // V_p N_I(x_p) of the K corners
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
  void scatter(Simulation<D>& sim, Group& group, double* const out,
               std::vector<double> Store::*values) {
    const size_t nodes = sim.grid.num_nodes;
    const std::array<size_t, K> offset = corner_offsets(sim.grid);
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
    complete(sim, out);
  }
  /// A scatter's nodal sums completed over the ranks and joined across periodic faces.
  void complete(Simulation<D>& sim, double* nodal) {
    const size_t nodes = sim.grid.num_nodes;
    std::vector<NodalArray> arrays;
    for (int g = 0; g < groups_; ++g) arrays.push_back({nodal + size_t(g) * nodes, 1, 1});
    sim.complete_nodes(arrays);
    join_periodic(sim, nodal);
  }
  /// Along a periodic axis a face node and its partner on the other face are one node (the
  /// periodic condition joins their masses and momenta the same way): each pair's sums go to
  /// both.
  void join_periodic(const Simulation<D>& sim, double* nodal) {
    const size_t nodes = sim.grid.num_nodes;
    for (int g = 0; g < groups_; ++g)
      for (const auto& [lo, hi] : periodic_pairs(sim)) {
        double* n = nodal + size_t(g) * nodes;
        n[lo] = n[hi] = n[lo] + n[hi];
      }
  }

  /// The node pairs that periodic faces join (lower face, upper face); built on first use.
  const std::vector<std::pair<size_t, size_t>>& periodic_pairs(const Simulation<D>& sim) {
    if (periodic_pairs_built_) return periodic_pairs_;
    for (int a = 0; a < D; ++a)
      if (sim.held_faces.period[size_t(a)] > 0) {
        const auto lo = face_nodes(sim.grid, Face{a, false});
        const auto hi = face_nodes(sim.grid, Face{a, true});
        for (size_t k = 0; k < lo.size(); ++k) periodic_pairs_.push_back({lo[k], hi[k]});
      }
    periodic_pairs_built_ = true;
    return periodic_pairs_;
  }
  /// Per node, whether dot() counts it: this rank's own, and of a periodic pair the lower
  /// node only. Fixed for the run (the ranks' cut does not move); built on first use.
  const std::vector<uint8_t>& counted_nodes(const Simulation<D>& sim) {
    const size_t nodes = sim.grid.num_nodes;
    if (counts_.size() == nodes) return counts_;
    counts_.assign(nodes, 1);
    for (const auto& pr : periodic_pairs(sim)) counts_[pr.second] = 0;
    if (sim.ranks->distributed())
      for (size_t n = 0; n < nodes; ++n)
        if (!sim.ranks->owns_node(sim.grid, sim.grid.node_ijk(n))) counts_[n] = 0;
    return counts_;
  }

  /// (s.*out)[i] = (s.*in)[i] projected onto the continuous (bi/tri)linear nodal field of its
  /// group in the V-weighted L2 sense: the nodal values a solve M a = b with the consistent
  /// mass M_IJ = sum_p V_p N_I(x_p) N_J(x_p) and b_I = sum_p V_p N_I(x_p) in_p, and each
  /// particle takes sum_I N_I(x_p) a_I; in itself for kNoGroup. The projection is symmetric
  /// in the V-weighted product and reproduces every linear field, at free surfaces and held
  /// faces too (the lumped average b_I / W_I is one-sided there).
  template <class Group>
  void project(Simulation<D>& sim, Group& group, std::vector<double> Store::*in,
               std::vector<double> Store::*out) {
    std::fill(rhs_.begin(), rhs_.end(), 0.0);
    scatter(sim, group, at(rhs_), in);
    solve_consistent_mass(sim);
    gather(sim, group, at(nodal_), in, out);
  }

  /// nodal_ ~ M^-1 rhs_ by kProducts conjugate-gradient steps preconditioned with the lumped
  /// mass W (the row sums of M), from the lumped solution rhs_ / W. W^-1 M is row-stochastic,
  /// its spectrum in (0, 1] and about [1/2^D, 1] where cells are full; conjugate gradients also
  /// resolve the few small eigenvalues of nodes that a partly filled cell's particles hardly
  /// see. The count is fixed so that the result is continuous in its data: a stopping test on
  /// the residual flips its count with round-off, and a run on ranks would then leave the
  /// serial one by the solve's tolerance instead of round-off (docs/volumetric_locking.md).
  void solve_consistent_mass(Simulation<D>& sim) {
    const double* W = at(weights_);
    const double* b = at(rhs_);
    double *a = at(nodal_), *r = at(res_), *p = at(dir_), *z = at(pre_), *q = at(prod_);
    const size_t* act = active_.data();
    const long na = long(active_.size());
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long j = 0; j < na; ++j) a[act[j]] = b[act[j]] / W[act[j]];
    apply_mass(sim, a, q);
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long j = 0; j < na; ++j) {
      const size_t k = act[j];
      r[k] = b[k] - q[k];
      p[k] = r[k] / W[k];
    }
    double rz = dot(sim, r, p);
    for (int it = 0; it < kProducts; ++it) {
      apply_mass(sim, p, q);
      const double pq = dot(sim, p, q);
      if (!(rz > 0 && pq > 0)) break;  // solved exactly (a zero right-hand side)
      const double alpha = rz / pq;
#pragma omp parallel for schedule(static) num_threads(sim.threads)
      for (long j = 0; j < na; ++j) {
        const size_t k = act[j];
        a[k] += alpha * p[k];
        r[k] -= alpha * q[k];
        z[k] = r[k] / W[k];
      }
      const double rz_next = dot(sim, r, z);
      const double beta = rz_next / rz;
#pragma omp parallel for schedule(static) num_threads(sim.threads)
      for (long j = 0; j < na; ++j) p[act[j]] = z[act[j]] + beta * p[act[j]];
      rz = rz_next;
    }
  }
  /// The sum of x y over the counted nodes in fixed chunks (the same bits on any number of
  /// threads), summed over the ranks.
  double dot(const Simulation<D>& sim, const double* x, const double* y) {
    constexpr size_t kChunk = 1024;
    const size_t* c = counted_.data();
    const size_t n = counted_.size(), chunks = (n + kChunk - 1) / kChunk;
    chunk_sums_.assign(chunks, 0.0);
    double* part = chunk_sums_.data();
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long ch = 0; ch < long(chunks); ++ch) {
      double sum = 0;
      for (size_t j = size_t(ch) * kChunk; j < std::min(n, size_t(ch + 1) * kChunk); ++j)
        sum += x[c[j]] * y[c[j]];
      part[ch] = sum;
    }
    double sum = 0;
    for (size_t ch = 0; ch < chunks; ++ch) sum += part[ch];
    sum_over_ranks(*sim.ranks, sum);
    return sum;
  }
  /// The consistent mass of every group, as each node's row over the 3^D nodes around it:
  /// mass_[(g nodes + I) S + o] = sum_p V_p N_I N_{I+o} over this rank's particles (the rows of
  /// nodes shared with other ranks are partial; apply_mass completes the product).
  template <class Group>
  void assemble_mass(Simulation<D>& sim, Group& group) {
    const size_t nodes = sim.grid.num_nodes;
    mass_.assign(size_t(groups_) * nodes * S, 0.0);
    const std::array<size_t, K> offset = corner_offsets(sim.grid);
    double* const out = mass_.data();
    sim.scatter_blocks([&](ParticleSet<D>& set, size_t b, int count, int) {
      const size_t slot = sim.set_slot(set);
      const Store& s = stores_[slot];
      const double* V = set.particles.col(set.particles.volume);
      const double* wv = s.wv.data();
      const size_t* corner = s.corner.data();
      for (size_t i = b; i < b + size_t(count); ++i) {
        const int g = group(slot, i);
        if (g == kNoGroup) continue;
        const double* w = wv + i * K;
        const double inv = 1.0 / V[i];
        double* row0 = out + (size_t(g) * nodes + corner[i]) * S;
        for (int k = 0; k < K; ++k) {
          double* row = row0 + offset[size_t(k)] * S;
          const double wk = w[k] * inv;
          for (int l = 0; l < K; ++l) row[kEntry[size_t(k)][size_t(l)]] += wk * w[l];
        }
      }
    });
  }
  /// The stored-node offset of each entry of a node's row, and the padding that lets a row be
  /// read at any node of the box.
  void row_offsets(const Grid<D>& g) {
    pad_ = 0;
    for (int o = 0; o < S; ++o) {
      long off = 0;
      for (int d = 0, r = o; d < D; ++d, r /= 3) off += (r % 3 - 1) * g.node_stride[size_t(d)];
      entry_offset_[size_t(o)] = off;
      pad_ = std::max(pad_, size_t(std::labs(off)));
    }
  }
  /// The nodes the solve runs over (a mass in their group), those dot() counts (this rank's
  /// own, a periodic pair once), and the solve's vectors sized with pad_ zeros on both sides.
  void index_nodes(const Simulation<D>& sim) {
    const size_t nodes = sim.grid.num_nodes, n_all = size_t(groups_) * nodes;
    const std::vector<uint8_t>& counts = counted_nodes(sim);
    active_.clear();
    counted_.clear();
    const double* W = at(weights_);
    for (size_t k = 0; k < n_all; ++k) {
      if (!(W[k] > 0)) continue;
      active_.push_back(k);
      if (counts[k % nodes]) counted_.push_back(k);
    }
    for (auto* v : {&rhs_, &nodal_, &res_, &dir_, &pre_, &prod_}) v->assign(n_all + 2 * pad_, 0.0);
  }

  /// y = M x at the active nodes: each rank's rows, completed over the ranks and joined across
  /// periodic faces as a scatter's sums are.
  void apply_mass(Simulation<D>& sim, const double* x, double* y) {
    const double* M = mass_.data();
    const size_t* act = active_.data();
    const long na = long(active_.size());
    const std::array<long, S> off = entry_offset_;
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long j = 0; j < na; ++j) {
      const size_t k = act[j];
      const double* row = M + k * S;
      double sum = 0;
      for (int o = 0; o < S; ++o) sum += row[o] * x[long(k) + off[size_t(o)]];
      y[k] = sum;
    }
    complete(sim, y);
  }
  double* at(std::vector<double>& v) {
    return v.data() + pad_;
  }
  /// (s.*out)[i] = sum_I N_I(x_p) nodal_I of its group; (s.*in)[i] for kNoGroup (0 without in).
  template <class Group>
  void gather(Simulation<D>& sim, Group& group, const double* nodal, std::vector<double> Store::*in,
              std::vector<double> Store::*out) {
    const size_t nodes = sim.grid.num_nodes;
    const std::array<size_t, K> offset = corner_offsets(sim.grid);
    for (size_t set = 0; set < stores_.size(); ++set) {
      Store& s = stores_[set];
      const double* V = sim.sets[set].particles.col(sim.sets[set].particles.volume);
      (s.*out).resize(s.corner.size());
      const double* f = in ? (s.*in).data() : nullptr;
      double* o = (s.*out).data();
      const double* wv = s.wv.data();
      const size_t* corner = s.corner.data();
      const long np = long(s.corner.size());
#pragma omp parallel for schedule(static) num_threads(sim.threads)
      for (long i = 0; i < np; ++i) {
        const int g = group(set, size_t(i));
        if (g == kNoGroup) {
          o[i] = f ? f[i] : 0.0;
          continue;
        }
        const double* node = nodal + size_t(g) * nodes + corner[i];
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
  std::vector<Store> stores_;                                 // per set
  std::vector<double> weights_;                               // per group and node: W_I
  std::vector<double> rhs_, nodal_, res_, dir_, pre_, prod_;  // per group and node: the solve
  std::vector<double> mass_;                                  // per group and node: S entries
  std::array<long, S> entry_offset_{};                        // stored-node offset of entry o
  std::vector<size_t> active_, counted_;  // group-major node indices: the solve's, dot()'s
  std::vector<double> chunk_sums_;        // dot()
  size_t pad_ = 0;                        // zeros before and after the solve's nodal vectors
  std::vector<std::pair<size_t, size_t>> periodic_pairs_;  // periodic_pairs()
  bool periodic_pairs_built_ = false;
  std::vector<uint8_t> counts_;  // per node: counted_nodes()
};

}  // namespace loam
