// Soil and water as two sets of material points on one grid, moving separately and free to
// occupy the same place: the double-point ("dual particle") formulation of Liang, Zhao &
// Martinelli, "MPM simulations of the interaction between water jet and soil bed" (seed 003),
// eqs. 1-12; Bandara & Soga 2015; Anura3D's double-point scheme, docs/verification.md F. Pure
// water, dry soil and saturated soil live in one model.
//
// Sets. `solid`: the grains (the skeleton); the material is the effective-stress model (the
// `stress` field is sigma', tension positive) and its density the grain density rho_s; the
// particle `mass` is the solid mass (1 - n0) rho_s V, V the point's mixture volume, and the
// `porosity` field its porosity, conserved with the solid mass: n <- 1 - (1 - n)/J.
// `liquid`: the water; the material is a fluid (Material::is_fluid: its stress follows from its
// density m/V and rate, e.g. newtonian_fluid), V is the point's INTRINSIC water volume, so
// m/V is the intrinsic water density rho_w; its `porosity` field is the porosity of its grid
// cell (below) and `pore_pressure` the water pressure -tr(sigma_w)/3 (compression positive).
//
// Per step (MUSL, lumped masses, drag implicit):
//   1. particle -> grid, each set with its own points:
//        solid: m_s, m_s v, F_s = sum[ -V sigma' grad N + m_s g N + f_ext N ],
//               drag Q_I = sum[ V Q_p N ] (Q per unit mixture volume from the drag plugin, at
//               the solid point's porosity), solid volume V_s,I = sum[ (1 - n) V N ];
//               and per grid cell the solid volume V_s,c = sum (1 - n) V;
//        liquid: m_w, m_w w, F_w = sum[ m_w g N + f_ext N ] and the weak form of div sigma_w
//               over the mixture, G_I = sum[ -(V/n_c) sigma_w grad N ], V/n_c the mixture
//               volume whose pores the point fills, n_c = 1 - V_s,c / V_c the porosity of its
//               cell (cell_porosity: the liquid points of a full cell integrate over the cell,
//               as Anura3D's liquid weights V_cell V_p / sum V_liquid do).
//   2. grid: the porosity field n_I = 1 - V_s,I / V_I (V_I = int N_I dOmega as the solid
//      bodies' lattice integrates it, ShapeFunction::axis_node_lattice_volume), clamped to
//      [0, 1]: from the solid
//      points only, so it rises to 1 where the grains spread or are absent. The liquid stress is
//      shared as seed 003 eqs. 8-9 do:
//        F_w += n_I G_I,   F_s += (1 - n_I) G_I,
//      i.e. the water gets n div sigma_w = div(n sigma_w) + p grad n and the skeleton
//      (1 - n) div sigma_w = div((1 - n) sigma_w) - p grad n: the porosity-gradient term p grad n
//      is split between the phases without differentiating n (the nodal n times the weak form of
//      div sigma_w, as the single-point scheme does for -n grad p). Loads, the face forces of
//      boundary conditions (on the mixture F_s + F_w and the water F_w) and local damping (on the
//      solid; on the water too with `liquid: true`) come in; then per node and component the
//      momentum equations of the two phases with the drag implicit (solve_drag_implicit,
//      framework/two_phase_blocks.hpp):
//        (m_w/dt + Q) w' - Q v' = m_w w/dt + F_w,   -Q w' + (m_s/dt + Q) v' = m_s v/dt + F_s.
//      Drag acts only where both phases are present (Q comes from solid points, and a node
//      without water mass takes no water velocity). A node with one phase integrates it alone.
//      Boundary conditions act on both phases (Simulation::constrain_update: a fixed or slip face
//      is impermeable for the liquid points too), then a phase whose partner was held is solved
//      again against it (follow_held_phase).
//   3. grid -> particle (MUSL): FLIP/PIC update of each set's velocity from its phase's nodal
//      velocity and acceleration, the new momenta re-mapped to the grid with the points still at
//      x^n (Sulsky 1995), velocity gradients from the re-mapped velocities on the same stencil,
//      then each point moves with its phase's updated grid velocity.
//   4. particle update: solid: V <- det(I + L_s dt) V, F, n <- 1 - (1 - n)/J and the
//      material's sigma' (Jaumann rate), one call per block. Liquid: the intrinsic density
//      from both mass balances (seed 003 eq. 12, with its sign: compression raises rho_w),
//        -(1/rho_w) D rho_w/Dt = div u_w + ((1 - n)/n) div u_s + (1/n) grad n . (u_w - u_s),
//      which is (1/n) [div((1 - n) u_s) + div(n u_w)]. Discretised with the nodal products,
//        V <- V (1 + dt (1/n) sum_I [(1 - n_I) v_I + n_I w_I] . grad N_I)
//      (v_I, w_I the re-mapped velocities): the adjoint of the shared liquid stress, so the
//      pressure work balances the stored energy (the interpolated form of eq. 12 drifted unstable
//      under gravity); n the liquid point's porosity of the step (liquid_porosity). In pure water
//      it is V (1 + dt tr L_w), the single-phase update to O(dt^2).
//      Partly filled pores: the rate is that of the pore volume, which the water fills only
//      when the pores are saturated. With air in them a compression goes to the air first: the
//      water takes the share r(S) of it,
//        V <- V (1 + dt r(S) (1/n) sum_I [...]) where the sum is negative,
//        r = clamp((S - S_c) / (S_o - S_c), 0, 1),
//      an expansion relieves the water in full, and where r < 1 the water takes no tension
//      (V <= m / rho_0 after the smoothing: capillary suction is not modelled). S is the degree
//      of saturation interpolated from the nodes, S_I = sum_w (m / rho_0) N_I / sum_s n V N_I
//      (the amount of water over the soil's pore volume, at most 1; smooth as points move, where
//      a count per cell jumps by a point's volume), S_c (air_continuous_below, 0.8) and S_o
//      (air_occluded_above, 0.9) roughly the range over which the pore air passes from a
//      continuous phase open to the atmosphere to occluded bubbles (Fredlund & Rahardjo 1993,
//      Soil Mechanics for Unsaturated Soils, ch. 2): a soil with air in half its pores carries a
//      load on its skeleton, and water rising into dry sand takes no suction. The water's
//      pressure still acts over the part of the cell it fills (V/n), i.e. on the mixture as
//      S p (Bishop's chi = S).
//      The fluid material then gives sigma_w from m/V and L_w (pressure, viscosity, cavitation).
// Fluidisation (max_porosity: n_max, seed 003 section 2 and Anura3D): a solid point in contact
// whose porosity reaches n_max is fluidised (`contact` 0): it carries no effective stress (the
// material's update is overwritten with 0) and its porosity is the smoothed grid field at the
// point, at least n_max (its volume follows, V = V_s / (1 - n), the solid volume kept); it
// regains contact (sigma' restarting from 0) when that field is below n_max while it is
// compressed (tr L_s < 0). No hysteresis. The nodal field counts the empty half cell beyond a
// free surface of the soil (n_I = 0.7 there for n = 0.4), so grains settling at a free surface
// inside the grid regain contact late or not at all: a known limit.
// Time step: the CFL limit of the materials, and of the fastest wave of the drag-free two-phase
// equations at every solid point (fast_wave_speed2 with the liquid materials' stiffest K_w);
// no drag limit: the implicit drag leaves the time step independent of the permeability
// (Anura3D's explicit drag needs dt < 2 rho k / mu).
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "framework/affine_transfer.hpp"
#include "framework/cell_projection.hpp"
#include "framework/drag.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/step_blocks.hpp"
#include "framework/tensor.hpp"
#include "framework/two_phase_blocks.hpp"

namespace loam {

template <int D>
class TwoPhaseDoublePoint : public Scheme<D> {
 public:
  static constexpr const char* name = "two_phase_double_point";
  static constexpr const char* summary =
      "soil and water as separate solid and liquid points on one grid (double-point, as Liang, "
      "Zhao & Martinelli's water jet): "
      "pure water, dry and saturated soil in one model; implicit nodal drag; fluidisation at "
      "max_porosity. Particle sets (bodies[].set): solid (the grains: an effective-stress "
      "material, mass (1 - n) rho_s V; fields porosity, contact) and liquid (water: a fluid "
      "material, intrinsic volume and density; fields porosity, pore_pressure)";
  static Schema schema() {
    Schema s;
    s.plugin("drag", "drag", "drag law between the liquid and the solid points (darcy, ergun)")
        .required();
    s.real("porosity", "-", "initial porosity n0 of the solid bodies (0 < n0 < 1)")
        .required()
        .above(0)
        .below(1);
    s.choice("pressure_smoothing", {"cell", "none"},
             "cell: after every step the water density is projected per grid cell onto the "
             "pressure space stable with the shape function: the cell's mean (one pressure per "
             "cell: linear, gimp, cpdi) or its volume-weighted linear fit (bspline2, whose "
             "gradients vary inside a cell); removes the point-to-point pressure checkerboard; "
             "none: every liquid point keeps its own")
        .def("cell");
    s.real("max_porosity", "-",
           "fluidisation threshold n_max (Liang, Zhao & Martinelli: 0.5): a solid point whose "
           "porosity reaches "
           "it carries no effective stress and takes the grid's porosity (at least n_max) "
           "until the grains are compressed below it again; default: no fluidisation")
        .above(0)
        .below(1);
    s.real("free_surface_filling", "-",
           "a cell whose pores the water fills less than this fraction is at the free surface: "
           "its liquid points get the free_surface flag (0: no detection)")
        .def("0.9")
        .min(0)
        .max(1);
    s.real("air_continuous_below", "-",
           "partly filled pores: below this degree of saturation S the pore air is continuous "
           "and escapes, and the water takes none of a compression of the pores (it builds no "
           "pressure when the soil is compressed); between it and air_occluded_above the "
           "water's share rises linearly; an expansion relieves the water in full, and with "
           "air in the pores it takes no tension (docs/verification.md F)")
        .def("0.8")
        .min(0)
        .max(1);
    s.real("air_occluded_above", "-",
           "above this degree of saturation the air is in occluded bubbles and the water takes "
           "the whole compression (the saturated response); 0 for both: pores are treated as "
           "full wherever water is")
        .def("0.9")
        .min(0)
        .max(1);
    s.choice("free_surface_pressure", {"free", "zero"},
             "free: the flagged points keep the pressure of their density; zero: they are set to "
             "zero pressure (V = m / rho_0), as Anura3D does. zero needs the cells below the "
             "surface full of liquid points: water that has spread out inside the soil (points "
             "s/n apart) fills its cells less and would lose its pressure there")
        .def("free");
    add_transfer_params(s, "; gimp, bspline2 or cpdi");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.real("air_continuous_below") > p.real("air_occluded_above"))
        d.error(p.where("air_continuous_below"), p.path("air_continuous_below"),
                "air_continuous_below " + format_number(p.real("air_continuous_below")) +
                    " exceeds air_occluded_above " + format_number(p.real("air_occluded_above")) +
                    ": the water's share of the pore volume change must rise with saturation");
      if (p.has("max_porosity") && p.real("max_porosity") <= p.real("porosity"))
        d.error(p.where("max_porosity"), p.path("max_porosity"),
                "max_porosity " + format_number(p.real("max_porosity")) +
                    " must exceed the initial porosity " + format_number(p.real("porosity")) +
                    ": the soil would start fluidised");
    });
    return s;
  }
  explicit TwoPhaseDoublePoint(const Params& p)
      : drag_(Registry::instance().create<Drag, D>(p.section("drag"))),
        n0_(p.real("porosity")),
        flip_(p.real("flip")),
        transfer_(p.text("transfer")),
        affine_on_(AffineTransfer<D>::is_affine(transfer_)),
        transfer_where_(p.where("transfer")),
        transfer_path_(p.path("transfer")),
        smooth_(p.text("pressure_smoothing") == "cell"),
        n_max_(p.has("max_porosity") ? p.real("max_porosity") : 2.0),
        free_filling_(p.real("free_surface_filling")),
        air_continuous_(p.real("air_continuous_below")),
        air_occluded_(p.real("air_occluded_above")),
        zero_surface_pressure_(p.text("free_surface_pressure") == "zero") {}

  int phases() const override { return 2; }
  /// APIC's affine matrix is part of each point's velocity field (a velocity reset zeroes it).
  std::vector<std::string> velocity_fields() const override {
    return affine_on_ ? std::vector<std::string>{"affine_moment"} : std::vector<std::string>{};
  }
  std::vector<SetDeclaration> particle_sets() const override {
    return {{"solid", "soil grains: the skeleton, effective stress, solid mass (1 - n) rho_s V"},
            {"liquid", "water: a fluid material, intrinsic water volume and density"}};
  }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    check_materials(sim, diag);
    n_ = sim.request_field({"porosity",
                            1,
                            "-",
                            "porosity: the solid point's own (solid set), that of the liquid "
                            "point's grid cell (liquid set)",
                            {}});
    p_ = sim.request_field(
        {"pore_pressure", 1, "Pa", "water pressure -tr(sigma_w)/3, compression positive", {}},
        kLiquid);
    contact_ = sim.request_field(
        {"contact", 1, "-", "1: the grains are in contact (effective stress), 0: fluidised", {}},
        kSolid);
    free_surface_ = sim.request_field(
        {"free_surface", 1, "-", "1: in a cell the water fills less than free_surface_filling", {}},
        kLiquid);
    saturation_ = sim.request_field(
        {"saturation",
         1,
         "-",
         "degree of saturation S of the soil's pores around the point (1 where no soil is)",
         {}},
        kLiquid);
    drag_->setup(sim, diag);
    node_.assign(sim.grid.num_nodes * S, 0.0);
    solved_.assign(sim.grid.num_nodes * 2 * D, 0.0);
    remap_.assign(sim.grid.num_nodes * 2 * D, 0.0);
    node_volume(sim);
    inv_cell_volume_ = 1;
    for (int d = 0; d < D; ++d) inv_cell_volume_ *= sim.grid.inv_cell[size_t(d)];
    cell_solid_.assign(sim.grid.num_cells, 0.0);
    for (const auto& m : sim.materials) inv_density_.push_back(1 / m->density());
    scratch_ = make_block_scratch<Scratch>(sim.threads, sim.shape->max_nodes_per_particle(),
                                           [](Scratch& s) {
                                             s.Q.assign(size_t(kBlock), 0.0);
                                             s.L_power.assign(size_t(D * D * kBlock), 0.0);
                                           });
    initialize_particles(sim, sim.sets[kSolid], 0, sim.sets[kSolid].size());
    if (affine_on_) setup_apic(sim, diag);
    if (diag.ok()) fill_pores(sim);
  }

  /// transfer: apic or tpic: every point keeps B_p (C_p) of its phase's velocity (solid points
  /// of v, liquid points of w). Linear tents need USF's gradient (framework/affine_transfer.hpp);
  /// this scheme is MUSL only: refused.
  void setup_apic(Simulation<D>& sim, Diagnostics& diag) {
    affine_.setup(sim.grid, *sim.shape, transfer_ == "tpic");
    B_ = sim.request_field(
        affine_.field_info("affine_moment", "point's own phase velocity (solid v, liquid w)"));
    refuse_affine_shape(affine_, *sim.shape, transfer_, transfer_where_, transfer_path_, diag);
  }

  /// Solid points: porosity n0, solid mass (1 - n0) rho_s V, in contact. Liquid points (at
  /// set-up, fill_pores, and a source's during the run): the fraction n of their volume and
  /// mass, n the porosity of the solid point whose domain holds the liquid point and 1 where
  /// none does (solid_porosity_at), so water generated over the soil fills only its pores, and
  /// a soil surface inside a cell divides the cell's water by point: the point in the soil keeps
  /// n rho_w V, the point above it rho_w V.
  void initialize_particles(Simulation<D>& sim, ParticleSet<D>& set, size_t b, size_t e) override {
    auto& P = set.particles;
    if (&set == &sim.sets[kSolid]) {
      for (size_t i = b; i < e; ++i) {
        P.col(n_)[i] = n0_;
        P.col(P.mass)[i] *= 1 - n0_;
        P.col(contact_)[i] = 1;
      }
      return;
    }
    const SolidIndex solid = index_solid_points(sim);
    for (size_t i = b; i < e; ++i) {
      double x[D];
      for (int d = 0; d < D; ++d) x[d] = P.col(P.position, d)[i];
      const double n = solid_porosity_at(sim, solid, x);
      P.col(n_)[i] = n;
      P.col(P.volume)[i] *= n;
      P.col(P.mass)[i] *= n;
    }
  }

  /// The liquid points' pore_pressure from their initial stress and their degree of
  /// saturation, for the first frame.
  void initial_state(Simulation<D>& sim) override {
    water_pressure(sim.sets[kLiquid].particles, 0, sim.sets[kLiquid].size());
    initial_saturation(sim);
  }

  /// The nodal water and pore volumes of the set-up (the step's scatter of them alone), S_I,
  /// and S interpolated at the liquid points.
  void initial_saturation(Simulation<D>& sim) {
    zero_nodes(node_, sim.threads);
    sim.scatter_blocks([&](ParticleSet<D>& set, size_t b, int count, int thread) {
      const Particles<D>& P = set.particles;
      StencilBlock<D>& st = scratch_[size_t(thread)]->stencil;
      sim.shape->evaluate(sim.grid, P, b, count, st);
      const bool solid = &set == &sim.sets[kSolid];
      for (int p = 0; p < count; ++p) {
        const size_t i = b + size_t(p);
        const double v = solid ? P.col(n_)[i] * P.col(P.volume)[i]
                               : P.col(P.mass)[i] * inv_density_[P.material[i]];
        for (int k = 0; k < st.npp; ++k) {
          const size_t kp = size_t(k) * kBlock + size_t(p);
          node_[size_t(st.node[kp]) * S + (solid ? kPore : kSat)] += st.w[kp] * v;
        }
      }
    });
    sim.complete_nodes({{node_.data(), S, S}});
    for_each_record(sim,
                    [&](double* r, size_t) { r[kSat] = degree_of_saturation(r[kSat], r[kPore]); });
    auto& liquid = sim.sets[kLiquid];
    liquid.gather_blocks([&](size_t b, int count, int thread) {
      Particles<D>& P = liquid.particles;
      StencilBlock<D>& st = scratch_[size_t(thread)]->stencil;
      sim.shape->evaluate(sim.grid, P, b, count, st);
      for (int p = 0; p < count; ++p) {
        double s = 0;
        for (int k = 0; k < st.npp; ++k) {
          const size_t kp = size_t(k) * kBlock + size_t(p);
          s += st.w[kp] * node_[size_t(st.node[kp]) * S + kSat];
        }
        P.col(saturation_)[b + size_t(p)] = s;
      }
    });
  }

  double stable_dt(const Simulation<D>& sim) const override {
    // The fast wave of the drag-free phases with each liquid material's own water (K_w =
    // rho_w c^2 from its wave speed); dry: the materials' CFL alone.
    // Under mpirun each liquid material's wave speed is the largest over the ranks: a rank's
    // solid points feel the water of the whole model, also where this rank holds none of it.
    double c2 = 0;
    for (size_t m = 0; m < sim.materials.size(); ++m) {
      const double c = sim.material_wave_speed(sim.sets[kLiquid], m);
      if (!(c > 0)) continue;
      const double rho = sim.materials[m]->density();
      c2 = std::max(c2, max_fast_wave_speed2(sim, sim.sets[kSolid], n_, rho * c * c, rho));
    }
    if (!(c2 > 0)) return std::numeric_limits<double>::infinity();
    return sim.cfl * sim.grid.min_cell() / (std::sqrt(c2) + sim.max_speed);
  }

  /// Both sets' nodal record and the re-map completed over the ranks after their scatters, the
  /// cells' solid volumes after the scatter (the free-surface test reads them in the cell a
  /// liquid point moved to, which may be in the ghost layer) and the liquid cell sums after the
  /// move. The sums a liquid point reads in its own cell at the step's start (solid volume,
  /// liquid volume) are whole on the rank owning the cell: every particle is there.
  bool runs_on_ranks() const override { return true; }

  std::vector<GridFieldView> grid_fields() const override {
    return {{"mass", 1, node_.data(), S, kMs},
            {"water_mass", 1, node_.data(), S, kMw},
            {"velocity", D, node_.data(), S, kV},
            {"water_velocity", D, node_.data(), S, kW},
            {"porosity", 1, node_.data(), S, kN}};
  }

  void step(Simulation<D>& sim, double dt) override {
    F_ = sim.deformation_gradient;  // may be requested after our set-up
    for (int s = 0; s < 2; ++s) move_[s].resize(sim.sets[size_t(s)].size() * D);
    lw_.resize(sim.sets[kLiquid].size() * D * D);
    if (sim.ledger.enabled) volume_rate_.resize(sim.sets[kLiquid].size());
    with_stencil_size<D>(sim.shape->nodes_per_particle(),
                         [&](auto npp) { step_phases<decltype(npp)::value>(sim, dt); });
  }

 private:
  static constexpr int kSolid = 0, kLiquid = 1;
  // Node record: solid and water mass, solid and water momentum -> velocity, solid and water
  // force -> acceleration, the weak form of div sigma_w (G), drag Q, solid volume -> porosity,
  // water volume -> degree of saturation, the solid points' pore volume.
  static constexpr int kMs = 0, kMw = 1, kV = 2, kW = 2 + D, kF = 2 + 2 * D, kFw = 2 + 3 * D,
                       kG = 2 + 4 * D, kQ = 2 + 5 * D, kN = 3 + 5 * D, kSat = 4 + 5 * D,
                       kPore = 5 + 5 * D, S = 6 + 5 * D;
  static constexpr TwoPhaseRecord kRecord{kMs, kMw, kQ, kV, kW, kF, kFw, kN, S};
  static constexpr int NS = Particles<D>::NS;
  // Smallest porosity a liquid point divides by (its mixture volume V/n): a liquid point inside
  // a grain-filled region (n_I -> 0 where solid points overlap) keeps a finite weight.
  static constexpr double kMinPorosity = 1e-3;
  std::unique_ptr<Drag<D>> drag_;
  double n0_, flip_;
  std::string transfer_;     // flip, apic or tpic
  bool affine_on_;           // an affine transfer (apic or tpic)
  Location transfer_where_;  // for set-up errors about `transfer`
  std::string transfer_path_;
  int B_ = -1;                // APIC: each point's B_p of its own phase's velocity, or -1
  AffineTransfer<D> affine_;  // APIC's per-entry algebra (framework/affine_transfer.hpp)
  using AffineStencil = typename AffineTransfer<D>::Stencil;
  int n_ = -1, p_ = -1, F_ = -1;
  std::vector<double> node_;
  std::vector<double> vol_;          // per node: V_I = int N_I dOmega
  std::vector<double> solved_;       // per node: v', w' of the coupled solve (2 D values)
  std::vector<double> remap_;        // per node: re-mapped solid then water velocity (2 D values)
  std::vector<double> move_[2];      // per set and particle: dt v_grid from the re-map pass
  std::vector<double> cell_solid_;   // per grid cell: solid volume sum (1 - n) V of the step
  std::vector<double> cell_liquid_;  // per grid cell: liquid volume sum V at the step's start
  std::vector<size_t> liquid_cell_;  // per liquid point: its cell at the step's start
  double inv_cell_volume_ = 1;
  std::vector<double> lw_;           // per liquid point: L_w (D * D values) until its stress update
  std::vector<double> volume_rate_;  // per liquid point, with the energy ledger: the step's
                                     // applied rate (V' - V)/(V dt)
  CellProjection<D> cells_;  // per grid cell: liquid volume and mass, the density's projection
  bool smooth_ = true;
  double n_max_;  // fluidisation threshold (2: never)
  int contact_ = -1, free_surface_ = -1;
  double free_filling_;  // free-surface threshold of a cell's pore filling (0: none)
  double air_continuous_, air_occluded_;  // the water's share of the pore volume change
  int saturation_ = -1;
  std::vector<double> inv_density_;  // per material: 1 / rho_0
  bool zero_surface_pressure_;
  std::vector<double> mixture_force_;  // per node (D values), while boundary forces are added
  struct Scratch : BlockScratch<D> {
    std::vector<double> Q;        // drag coefficients of the block
    std::vector<double> L_power;  // the liquid's velocity gradient for the energy ledger
    long bad_porosity = -1;       // a solid point whose porosity left (0, 1) this step
    long bad_volume = -1;         // a liquid point compressed to zero volume this step
  };
  std::vector<std::unique_ptr<Scratch>> scratch_;

  /// A liquid body needs a fluid material (its stress from its density), a solid body an
  /// effective-stress model: located errors at the body's material.
  void check_materials(Simulation<D>& sim, Diagnostics& diag) const {
    const auto& bl = sim.config.list("bodies");
    for (size_t b = 0; b < bl.size() && b < sim.materials.size(); ++b) {
      if (bl[b].has("set") && sim.set_index(bl[b].text("set")) < 0) continue;  // reported
      const bool liquid = sim.body_set(int(b)) == kLiquid;
      const bool fluid = sim.materials[b]->is_fluid();
      if (liquid && !fluid)
        diag.error(bl[b].where("material"), bl[b].path("material"),
                   "a body in the liquid set needs a fluid material (e.g. newtonian_fluid): the "
                   "water's pressure follows from its density; '" +
                       bl[b].section("material").type() + "' is a soil model");
      if (!liquid && fluid)
        diag.error(bl[b].where("material"), bl[b].path("material"),
                   "'" + bl[b].section("material").type() +
                       "' is a fluid: put water in the liquid set (set: liquid); the solid set "
                       "holds the soil grains");
    }
  }

  /// V_I = prod_d h_d a_d(i_d), a_d the per-axis nodal volume that the solid bodies' lattice
  /// integrates (ShapeFunction::axis_node_lattice_volume), so that a node the soil fills has
  /// porosity n at set-up with every shape function (the boundary-modified B-splines' exact
  /// integrals are 2 % off the points' sums at a wall: a porosity of 0.41 or 0.39 there drove
  /// the water along the walls). Solid bodies with different points per cell, or none: the
  /// exact integral int N_I dOmega.
  void node_volume(const Simulation<D>& sim) {
    const Grid<D>& g = sim.grid;
    const std::array<int, D> ppc = solid_points_per_cell(sim);
    std::array<std::vector<double>, D> axis;  // h_d a_d(i) per axis
    for (int d = 0; d < D; ++d)
      for (int i = 0, last = g.cells[d], k = ppc[size_t(d)]; i <= last; ++i)
        axis[size_t(d)].push_back(g.cell[size_t(d)] *
                                  (k > 0 ? sim.shape->axis_node_lattice_volume(i, last, k)
                                         : sim.shape->axis_node_volume(i, last)));
    vol_.assign(g.num_nodes, 1.0);
    for (size_t n = 0; n < g.num_nodes; ++n) {
      const auto ijk = g.node_ijk(n);
      for (int d = 0; d < D; ++d) vol_[n] *= axis[size_t(d)][size_t(ijk[size_t(d)])];
    }
  }

  /// The points per cell along each axis that every solid body shares, 0 where they differ or
  /// no solid body is given.
  static std::array<int, D> solid_points_per_cell(const Simulation<D>& sim) {
    std::array<int, D> ppc{};
    bool first = true;
    for (const Body& body : sim.bodies) {
      if (body.set != kSolid) continue;
      for (int d = 0; d < D; ++d) {
        const int k = int(std::lround(sim.grid.cell[size_t(d)] / body.spacing[size_t(d)]));
        ppc[size_t(d)] = first || ppc[size_t(d)] == k ? k : 0;
      }
      first = false;
    }
    return ppc;
  }

  /// The liquid bodies are generated like any body, a point per spacing filling its whole
  /// volume; where they overlap the soil only the pores hold water. At set-up each liquid point
  /// keeps the fraction n of its volume and mass that the pores around it leave
  /// (initialize_particles): V <- n V, m <- n m (intrinsic water volume at the material's
  /// density). A regular fill thus puts exactly the pore volume of the soil in water; pure water
  /// keeps its points as they are (n = 1).
  void fill_pores(Simulation<D>& sim) {
    initialize_particles(sim, sim.sets[kLiquid], 0, sim.sets[kLiquid].size());
  }

  /// The solid points sorted by grid cell: the points of cell c are order[start[c] ..
  /// start[c + 1]).
  struct SolidIndex {
    std::vector<size_t> start, order;
  };
  SolidIndex index_solid_points(const Simulation<D>& sim) const {
    const Particles<D>& S = sim.sets[kSolid].particles;
    SolidIndex idx;
    idx.start.assign(sim.grid.num_cells + 1, 0);
    std::vector<size_t> cell(S.size());
    for (size_t j = 0; j < S.size(); ++j)
      ++idx.start[(cell[j] = particle_cell(sim.grid, S, j)) + 1];
    for (size_t c = 0; c < sim.grid.num_cells; ++c) idx.start[c + 1] += idx.start[c];
    idx.order.resize(S.size());
    std::vector<size_t> next(idx.start.begin(), idx.start.end() - 1);
    for (size_t j = 0; j < S.size(); ++j) idx.order[next[cell[j]]++] = j;
    return idx;
  }

  /// The porosity of the solid point whose domain holds x, 1 if none does. A solid point's
  /// domain is its lattice box, the body's spacing s_d scaled by (V / prod s_d)^(1/D) as its
  /// volume changes; the boxes of x's cell and its neighbours are searched (a lattice that is
  /// not aligned with the cells has boxes across cell faces).
  double solid_porosity_at(const Simulation<D>& sim, const SolidIndex& idx, const double* x) const {
    const Particles<D>& S = sim.sets[kSolid].particles;
    const Grid<D>& g = sim.grid;
    int lo[D], hi[D], c[D];
    for (int d = 0; d < D; ++d) {
      const int k = g.cell_of(x[d], d);
      lo[d] = std::max(k - 1, 0), hi[d] = std::min(k + 1, g.cells[d] - 1), c[d] = lo[d];
    }
    while (true) {
      size_t cell = 0;
      for (int d = 0; d < D; ++d) cell += size_t(c[d]) * size_t(g.cell_stride[d]);
      for (size_t k = idx.start[cell]; k < idx.start[cell + 1]; ++k)
        if (holds(sim, S, idx.order[k], x)) return S.col(n_)[idx.order[k]];
      int d = 0;
      while (d < D && ++c[d] > hi[d]) c[d] = lo[d], ++d;
      if (d == D) return 1.0;
    }
  }

  /// Whether solid point j's domain box holds x. The boxes of a lattice share their faces, and a
  /// point of another lattice (the water generated with other particles_per_cell) can lie on
  /// one: a relative tolerance of 1e-9 keeps round-off from leaving it in no box (in two, the
  /// first found decides; neighbouring solid points have the same porosity at set-up).
  bool holds(const Simulation<D>& sim, const Particles<D>& S, size_t j, const double* x) const {
    const auto& s = sim.bodies[S.body[j]].spacing;
    double lattice = 1;
    for (int d = 0; d < D; ++d) lattice *= s[size_t(d)];
    const double ratio = S.col(S.volume)[j] / lattice;  // 1 at set-up
    const double stretch = ratio == 1 ? 1.0 : std::pow(ratio, 1.0 / D);
    for (int d = 0; d < D; ++d) {
      const double half = 0.5 * s[size_t(d)] * stretch, r = x[d] - S.col(S.position, d)[j];
      if (!(std::fabs(r) <= half * (1 + 1e-9))) return false;
    }
    return true;
  }

  /// Porosity of grid cell c from the solid volume in it, n_c = 1 - V_s,c / V_c in
  /// [kMinPorosity, 1]: the water fraction of a cell whose pores are full. A liquid point's
  /// mixture volume is V / n_c, so the liquid points of a full cell integrate over the cell's
  /// volume (Anura3D's weight V_cell V_p / sum V_liquid), and those of a cell the water only
  /// partly fills (a free surface) over the part they fill.
  double cell_porosity(size_t c) const {
    return std::clamp(1.0 - cell_solid_[c] * inv_cell_volume_, kMinPorosity, 1.0);
  }
  /// The porosity a liquid point of cell c divides its volume by in the step: the cell's
  /// porosity from its solid volume, but never below the cell's water fraction sum V / V_c,
  /// so the liquid points of a cell never integrate over more than the cell. Where solid points
  /// crowd (a jet's impact, a flying cluster of grains), V_s,c over-counts the grains and n_c
  /// falls towards kMinPorosity: a weight V / n_c up to 1000 V then drove the water jet of seed
  /// 003 unstable at 22 and 27 m/s. For water filling the pores both are n (Anura3D's weights
  /// V_cell V_p / sum V_liquid are the second).
  double liquid_porosity(size_t c) const {
    return std::max(cell_porosity(c), std::min(1.0, cell_liquid_[c] * inv_cell_volume_));
  }
  /// Per cell the liquid points' volume sum V at the start of the step, and each liquid point's
  /// cell (liquid_cell_, indexed by point), summed in point order (framework/cell_sums.hpp):
  /// bitwise the same at any thread count.
  void liquid_cell_volumes(Simulation<D>& sim) {
    const Particles<D>& P = sim.sets[kLiquid].particles;
    const double* V = P.col(P.volume);
    sum_per_cell<1>(sim.grid, P, sim.threads, liquid_cell_, cell_liquid_,
                    [&](size_t i, double* v) { v[0] = V[i]; });
  }

  template <int NPP>
  void step_phases(Simulation<D>& sim, double dt) {
    sim.timed("grid", [&] {
      zero_nodes(node_, sim.threads);
      zero_nodes(cell_solid_, sim.threads);
    });
    sim.timed("p2g", [&] { liquid_cell_volumes(sim); });
    sim.timed("p2g", [&] {
      sim.scatter_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
        with_form<NPP>(sim, s, b, c, t, [&](auto form) {
          constexpr AffineForm F = decltype(form)::value;
          if (&s == &sim.sets[kSolid])
            scatter_solid<NPP, F>(sim, s, b, c, t);
          else
            scatter_liquid<NPP, F>(sim, s, b, c, t);
        });
      });
    });
    sim.complete_nodes({{node_.data(), S, S}});
    sim.complete_cells(cell_solid_, 1);
    sim.timed("grid", [&] { integrate(sim, dt); });
    reset_max_speed(scratch_);
    sim.timed("grid", [&] { zero_nodes(remap_, sim.threads); });
    sim.timed("g2p_velocity_remap", [&] {
      sim.scatter_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
        with_form<NPP>(sim, s, b, c, t, [&](auto form) {
          remap<NPP, decltype(form)::value>(sim, s, &s == &sim.sets[kSolid] ? kSolid : kLiquid, dt,
                                            b, c, t);
        });
      });
    });
    sim.complete_nodes({{remap_.data(), 2 * D, 2 * D}});
    sim.timed("grid", [&] {
      remapped_two_phase_velocities(sim, node_.data(), kRecord, remap_, MasslessWater::kNone);
    });
    sim.timed("g2p_gradient_stress", [&] {
      sim.gather_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
        if (&s == &sim.sets[kSolid])
          update_solid<NPP>(sim, s, dt, b, c, t);
        else
          update_liquid<NPP>(sim, s, dt, b, c, t);
      });
    });
    auto& liquid = sim.sets[kLiquid];
    sim.timed("pore_pressure", [&] { liquid_cells(sim); });
    sim.timed("g2p_gradient_stress", [&] {
      liquid.gather_blocks(
          [&](size_t b, int c, int t) { liquid_stress(sim, liquid, dt, b, c, t); });
    });
    sim.max_speed = max_speed(scratch_);
    report_bad_porosity(sim);
  }

  /// A solid point whose porosity left (0, 1) in the step ends the run (Simulation::failure).
  void report_bad_porosity(Simulation<D>& sim) {
    for (auto& s : scratch_)
      if (s->bad_porosity >= 0) {
        const auto& P = sim.sets[kSolid].particles;
        const size_t i = size_t(s->bad_porosity);
        sim.failure = "solid particle " + std::to_string(P.id[i]) +
                      ": porosity left (0, 1) (n = " + format_number(P.col(n_)[i]) +
                      "); the skeleton was compressed to zero pore volume or torn apart";
        s->bad_porosity = -1;
      }
    for (auto& s : scratch_)
      if (s->bad_volume >= 0) {
        const auto& P = sim.sets[kLiquid].particles;
        sim.failure = "liquid particle " + std::to_string(P.id[size_t(s->bad_volume)]) +
                      ": compressed to zero volume in one step (storage rate x dt <= -1); a "
                      "smaller time.cfl or a softer water (bulk_modulus)";
        s->bad_volume = -1;
      }
  }

  // ------------------------------------------------------------------ particle to grid
  /// Solid points: mass, momentum, force (effective stress, weight, loads), drag, solid volume.
  /// APIC: point i's stencil geometry at its position and its affine momenta per unit weight
  /// of every stencil entry, m v_p + m B_p D_p^-1 (x_I - x_p) (mass m, momentum mv).
  template <int NPP, AffineForm FORM>
  using Momenta = typename AffineTransfer<D>::template Momenta<NPP, FORM>;
  template <int NPP, AffineForm FORM>
  void affine_momenta(const Particles<D>& P, const typename AffineTransfer<D>::Columns& B,
                      const StencilBlock<D>& st, int p, size_t i, int npp, double m,
                      const double (&mv)[D], AffineStencil& as, Momenta<NPP, FORM>& am) const {
    double mC[D][D];
    affine_.stencil(P, st, p, i, npp, as);
    affine_.matrix(B, i, m, as, mC);
    AffineTransfer<D>::template momenta<NPP>(as, npp, mv, mC, am);
  }

  /// Block b's stencil evaluated (with the affine geometry when APIC or TPIC is on) and
  /// kernel(form) called with its AffineForm: each pass's loop is compiled per form.
  template <int NPP, class Kernel>
  void with_form(Simulation<D>& sim, ParticleSet<D>& s, size_t b, int count, int thread,
                 Kernel&& kernel) {
    affine_.template evaluate_with_form<NPP>(sim, s.particles, b, count,
                                             scratch_[size_t(thread)]->stencil, affine_on_, kernel);
  }

  template <int NPP, AffineForm FORM>
  void scatter_solid(Simulation<D>& sim, ParticleSet<D>& set, size_t b, int count, int thread) {
    constexpr bool AFFINE = FORM != AffineForm::kOff;
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    const StencilBlock<D>& st = sc.stencil;
    const int npp = NPP ? NPP : st.npp;
    const double* ms = P.col(P.mass) + b;
    const double* V = P.col(P.volume) + b;
    const double* n = P.col(n_) + b;
    drag_coefficients(P, st, b, count, npp, sc.Q.data());
    double* g = node_.data();
    AffineStencil as;
    Momenta<NPP, FORM> am;  // APIC: the momenta per unit weight
    typename AffineTransfer<D>::Columns B;
    if constexpr (AFFINE) B = AffineTransfer<D>::columns(P, B_);
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      double mv[D], body[D], sv[D][D];
      for (int d = 0; d < D; ++d) {
        mv[d] = ms[p] * P.col(P.velocity, d)[i];
        const double fe = sim.external_force >= 0 ? P.col(sim.external_force, d)[i] : 0.0;
        body[d] = ms[p] * sim.gravity[size_t(d)] + fe;
        for (int j = 0; j < D; ++j) sv[d][j] = V[p] * P.col(P.stress, voigt_index(d, j))[i];
      }
      if constexpr (AFFINE) affine_momenta<NPP>(P, B, st, p, i, npp, ms[p], mv, as, am);
      const double vq = V[p] * sc.Q[size_t(p)], vs = (1 - n[p]) * V[p], vp = n[p] * V[p];
      cell_solid_[particle_cell(sim.grid, P, i)] += vs;  // in the stencil: race-free
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            const size_t kp = size_t(k) * kBlock + size_t(p);
            const double w = st.w[kp];
            double* r = g + size_t(st.node[kp]) * S;
            r[kMs] += w * ms[p];
            r[kQ] += w * vq;
            r[kN] += w * vs;
            r[kPore] += w * vp;
            for (int d = 0; d < D; ++d) {
              r[kV + d] += w * (AFFINE ? am.at(k, d) : mv[d]);  // APIC: the affine momentum
              double f = w * body[d];
              for (int j = 0; j < D; ++j)
                f -= sv[d][j] * st.grad[(size_t(k) * D + size_t(j)) * kBlock + size_t(p)];
              r[kF + d] += f;
            }
          });
    }
  }

  /// Drag coefficients of a block of solid points at their porosity; for a speed-dependent law
  /// (ergun) at their speed relative to the water, the re-mapped water velocity of the last
  /// step interpolated at the point (still in remap_: it is zeroed after the grid update).
  void drag_coefficients(const Particles<D>& P, const StencilBlock<D>& st, size_t b, int count,
                         int npp, double* Q) const {
    if (!drag_->speed_dependent())
      return drag_->coefficient(size_t(count), P.col(n_) + b, nullptr, Q);
    double speed[kBlock];
    for (int p = 0; p < count; ++p) {
      double w[D] = {};
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const double* r = remap_.data() + size_t(st.node[kp]) * 2 * D + D;
        for (int d = 0; d < D; ++d) w[d] += st.w[kp] * r[d];
      }
      double s2 = 0;
      for (int d = 0; d < D; ++d) {
        const double rel = w[d] - P.col(P.velocity, d)[b + size_t(p)];
        s2 += rel * rel;
      }
      speed[p] = std::sqrt(s2);
    }
    drag_->coefficient(size_t(count), P.col(n_) + b, speed, Q);
  }

  /// Liquid points: mass, momentum, weight and loads, and the weak form of div sigma_w over
  /// the mixture volume V/n.
  template <int NPP, AffineForm FORM>
  void scatter_liquid(Simulation<D>& sim, ParticleSet<D>& set, size_t b, int count, int thread) {
    constexpr bool AFFINE = FORM != AffineForm::kOff;
    Particles<D>& P = set.particles;
    const StencilBlock<D>& st = scratch_[size_t(thread)]->stencil;
    const int npp = NPP ? NPP : st.npp;
    const double* mw = P.col(P.mass) + b;
    const double* V = P.col(P.volume) + b;
    double* n = P.col(n_) + b;
    double* g = node_.data();
    AffineStencil as;
    Momenta<NPP, FORM> am;  // APIC: the momenta per unit weight
    typename AffineTransfer<D>::Columns B;
    if constexpr (AFFINE) B = AffineTransfer<D>::columns(P, B_);
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      n[p] = liquid_porosity(liquid_cell_[i]);  // the solid set is scattered first
      const double Vmix = V[p] / n[p];
      const double free_volume = mw[p] * inv_density_[P.material[i]];  // at p = 0
      double mv[D], body[D], sv[D][D];
      for (int d = 0; d < D; ++d) {
        mv[d] = mw[p] * P.col(P.velocity, d)[i];
        const double fe = sim.external_force >= 0 ? P.col(sim.external_force, d)[i] : 0.0;
        body[d] = mw[p] * sim.gravity[size_t(d)] + fe;
        for (int j = 0; j < D; ++j) sv[d][j] = Vmix * P.col(P.stress, voigt_index(d, j))[i];
      }
      if constexpr (AFFINE) affine_momenta<NPP>(P, B, st, p, i, npp, mw[p], mv, as, am);
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            const size_t kp = size_t(k) * kBlock + size_t(p);
            const double w = st.w[kp];
            double* r = g + size_t(st.node[kp]) * S;
            r[kMw] += w * mw[p];
            r[kSat] += w * free_volume;
            for (int d = 0; d < D; ++d) {
              r[kW + d] += w * (AFFINE ? am.at(k, d) : mv[d]);  // APIC: the affine momentum
              r[kFw + d] += w * body[d];
              double f = 0;
              for (int j = 0; j < D; ++j)
                f -= sv[d][j] * st.grad[(size_t(k) * D + size_t(j)) * kBlock + size_t(p)];
              r[kG + d] += f;
            }
          });
    }
  }

  // ------------------------------------------------------------------ grid
  /// Nodal porosity and the shared liquid stress, loads, boundary forces, damping, the coupled
  /// solve with the drag implicit, the boundary conditions and the re-solve of a phase whose
  /// partner a condition held.
  void integrate(Simulation<D>& sim, double dt) {
    porosity_and_liquid_stress(sim);
    sim.apply_grid_loads(NodalVector{node_.data(), S, kF});
    boundary_forces(sim);
    damp_phases(sim);
    solve_two_phase_nodes<D, PhaseNodes::kSeparate>(sim, node_.data(), kRecord, solved_.data(), dt);
    constrain_two_phase_update<D>(sim, node_.data(), kRecord, solved_.data(), dt);
  }

  /// n_I = 1 - V_s,I / V_I in [0, 1]; F_w += n_I G_I, F_s += (1 - n_I) G_I (see the header);
  /// the degree of saturation S_I.
  void porosity_and_liquid_stress(Simulation<D>& sim) {
    for_each_record(sim, [&](double* r, size_t i) {
      const double n = std::clamp(1.0 - r[kN] / vol_[i], 0.0, 1.0);
      r[kN] = n;
      r[kSat] = degree_of_saturation(r[kSat], r[kPore]);
      for (int d = 0; d < D; ++d) {
        r[kFw + d] += n * r[kG + d];
        r[kF + d] += (1 - n) * r[kG + d];
      }
    });
  }

  /// Face forces of the boundary conditions act on the mixture (F_s + F_w) and the water F_w
  /// (GridForces); the solid keeps the difference.
  void boundary_forces(Simulation<D>& sim) {
    if (sim.boundaries.empty()) return;
    mixture_force_.resize(sim.grid.num_nodes * D);
    for_each_record(sim, [&](const double* r, size_t i) {
      for (int d = 0; d < D; ++d) mixture_force_[i * D + size_t(d)] = r[kF + d] + r[kFw + d];
    });
    GridForces f;
    f.mixture = NodalVector{mixture_force_.data(), D, 0};
    f.water = NodalVector{node_.data(), S, kFw};
    f.porosity = NodalVector{node_.data(), S, kN};
    f.count = 2;
    sim.apply_boundary_forces(f);
    for_each_record(sim, [&](double* r, size_t i) {
      for (int d = 0; d < D; ++d) r[kF + d] = mixture_force_[i * D + size_t(d)] - r[kFw + d];
    });
  }

  /// Local damping (damping:) acts on the solid's momentum balance; the water is damped by the
  /// drag and its viscosity (damping its force would slow steady seepage), and by the damping
  /// too where it says so (a settle stage: water at rest at a free surface that B-splines
  /// integrate inexactly reaches the discrete equilibrium, docs/verification.md F).
  void damp_phases(Simulation<D>& sim) {
    if (!sim.damping) return;
    sim.apply_damping(NodeForces{node_.data() + kMs, NodalVector{node_.data(), S, kV},
                                 NodalVector{node_.data(), S, kF}, sim.grid.num_nodes, S});
    if (sim.damping->phases() == DampedPhases::solid_and_liquid)
      sim.apply_damping(NodeForces{node_.data() + kMw, NodalVector{node_.data(), S, kW},
                                   NodalVector{node_.data(), S, kFw}, sim.grid.num_nodes, S},
                        nullptr, MomentumBalance::kLiquid);
  }

  /// f(record, node) for every grid node, in parallel (static schedule).
  template <class F>
  void for_each_record(const Simulation<D>& sim, F&& f) {
    double* g = node_.data();
    for_each_node(sim.grid.num_nodes, sim.threads, [&](size_t i) { f(g + i * S, i); });
  }

  // ------------------------------------------------------------------ grid to particle
  /// MUSL first pass for the points of one phase: FLIP/PIC update of their velocity from the
  /// phase's nodal velocity and acceleration, the move dt v_grid kept for the gradient pass,
  /// and the scatter of the new momentum (the points stay at x^n).
  template <int NPP, AffineForm FORM>
  void remap(Simulation<D>& sim, ParticleSet<D>& set, int phase, double dt, size_t b, int count,
             int thread) {
    constexpr bool AFFINE = FORM != AffineForm::kOff;
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    const StencilBlock<D>& st = sc.stencil;
    const int npp = NPP ? NPP : st.npp;
    const int kv = phase == kSolid ? kV : kW, ka = phase == kSolid ? kF : kFw;
    const double* g = node_.data();
    const double* m = P.col(P.mass) + b;
    double* move = move_[phase].data() + b * D;
    const double flip = flip_;
    double max_v2 = sc.max_v2, loss = 0;
    AffineStencil as;
    Momenta<NPP, FORM> am;  // APIC: the momenta per unit weight
    typename AffineTransfer<D>::Columns B;
    if constexpr (AFFINE) B = AffineTransfer<D>::columns(P, B_);
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      double vg[D] = {}, ag[D] = {};
      // APIC: B_p = sum_I N_Ip v_I (x_I - x_p)^T at x^n (framework/affine_transfer.hpp).
      typename AffineTransfer<D>::template MomentSum<NPP, FORM> sum;
      if constexpr (AFFINE) {
        sum.clear();
        affine_.stencil(P, st, p, i, npp, as);
      }
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            const size_t kp = size_t(k) * kBlock + size_t(p);
            const double w = st.w[kp];
            const double* r = g + size_t(st.node[kp]) * S;
            for (int d = 0; d < D; ++d) {
              vg[d] += w * r[kv + d];
              if constexpr (!AFFINE) ag[d] += w * r[ka + d];
            }
            if constexpr (AFFINE) affine_.add_moment(sum, st, k, p, w, r + kv, as);
          });
      double v2 = 0, vp[D];
      for (int d = 0; d < D; ++d) {
        double& v = P.col(P.velocity, d)[i];
        const double v_old = v;
        v = vp[d] = AFFINE ? vg[d] : flip_pic(flip, v, dt, ag[d], vg[d]);
        if (!AFFINE && flip < 1) loss += m[p] * transfer_loss(v_old, dt, ag[d], vp[d]);
        move[size_t(p) * D + size_t(d)] = dt * vg[d];
        v2 += vp[d] * vp[d];
      }
      max_v2 = std::max(max_v2, v2);
      if constexpr (AFFINE) {  // the re-map carries the affine momentum too
        double Bp[D][D], mv[D], mC[D][D];
        affine_.moment(sum, as, Bp);
        B.store(i, Bp);
        for (int d = 0; d < D; ++d) mv[d] = m[p] * vp[d];
        affine_.matrix(m[p], Bp, as, mC);
        AffineTransfer<D>::template momenta<NPP>(as, npp, mv, mC, am);
        for_each_entry<FORM>(
            npp, [&](int k) __attribute__((always_inline)) {
              const size_t kp = size_t(k) * kBlock + size_t(p);
              double* r = remap_.data() + size_t(st.node[kp]) * 2 * D + size_t(phase * D);
              for (int d = 0; d < D; ++d) r[d] += st.w[kp] * am.at(k, d);
            });
      } else {
        for (int k = 0; k < npp; ++k) {
          const size_t kp = size_t(k) * kBlock + size_t(p);
          const double wm = st.w[kp] * m[p];
          double* r = remap_.data() + size_t(st.node[kp]) * 2 * D + size_t(phase * D);
          for (int d = 0; d < D; ++d) r[d] += wm * vp[d];
        }
      }
    }
    sc.max_v2 = max_v2;
    if (flip < 1) sim.ledger.add_transfer_loss(sim.set_slot(set), b, 0.5 * loss);
  }

  /// Solid points: L_s from the re-mapped solid velocities, volume, F and porosity, the move,
  /// the effective stress.
  template <int NPP>
  void update_solid(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count,
                    int thread) {
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    StencilBlock<D>& st = sc.stencil;
    sim.shape->evaluate(sim.grid, P, b, count, st);
    const int npp = NPP ? NPP : st.npp;
    double* L = sc.L.data();
    const auto F = deformation_gradient_block(P, F_, b);
    const double* move = move_[kSolid].data() + b * D;
    const double* g = node_.data();
    double* contact = P.col(contact_) + b;
    bool fluidised = false;
    // The smoothed (nodal) porosity field at point p: only fluidised points read it.
    auto grid_porosity = [&](int p) {
      double n = 0;
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        n += st.w[kp] * g[size_t(st.node[kp]) * S + kN];
      }
      return n;
    };
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      double l[D][D] = {};
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        add_velocity_gradient<D>(l, remap_.data() + size_t(st.node[kp]) * 2 * D, st, size_t(k), p);
      }
      move_point(sim.held_faces, P, i, move + size_t(p) * D);
      store_velocity_gradient<D>(l, L, p);
      double& V = P.col(P.volume)[i];
      double& n = P.col(n_)[i];
      const double Vs = (1 - n) * V;  // solid volume, conserved
      const double J = update_volume_and_deformation<D>(l, dt, V, F, p);
      // Fluidised: no effective stress, the grid's porosity (at least n_max), solid volume kept.
      auto fluidise = [&](double n_grid) {
        n = std::max(n_grid, n_max_);
        V = Vs / (1 - n);
        fluidised = true;
      };
      if (contact[p] > 0) {
        n = 1 - (1 - n) / J;
        if (n >= n_max_) {
          contact[p] = 0;
          fluidise(grid_porosity(p));
        }
      } else if (const double n_grid = grid_porosity(p); n_grid < n_max_ && volume_rate(l) < 0) {
        contact[p] = 1;  // compressed below n_max: the grains touch again, sigma' from 0
        // Not denser than the initial packing: where points crowd the nodal field dips towards
        // 0, and a grain at near-zero porosity is crushed to a negative one by the next step.
        n = std::max(n_grid, n0_);
        V = Vs / (1 - n);
      } else {
        fluidise(n_grid);
      }
      if (!(n > 0 && n < 1)) sc.bad_porosity = long(i);
    }
    sim.update_block_stress(set, b, count, dt, L);
    if (fluidised) zero_effective_stress(P, b, count);
  }

  /// S_I = (sum_liquid (m / rho_0) N_I) / (sum_solid n V N_I): the water's volume at zero
  /// pressure (its amount, whatever its pressure) over the soil's pore volume at the node, at most
  /// 1 (free water over the soil fills its pores); 1 where no soil is (pure water's free surface is
  /// its own density's business).
  static double degree_of_saturation(double water, double pores) {
    return pores > 0 ? std::min(1.0, water / pores) : 1.0;
  }
  /// The fraction of a compression of the pores the water takes at degree of saturation S: 0
  /// while the pore air is continuous and escapes (S <= air_continuous_below), 1 once it is
  /// occluded (S >= air_occluded_above), linear between.
  double water_share(double saturation) const {
    if (saturation >= air_occluded_) return 1.0;
    if (saturation <= air_continuous_) return 0.0;
    return (saturation - air_continuous_) / (air_occluded_ - air_continuous_);
  }

  static double volume_rate(const double (&l)[D][D]) {
    double tr = 0;
    for (int d = 0; d < D; ++d) tr += l[d][d];
    return tr;
  }

  /// Fluidised solid points of a block carry no effective stress (seed 003 section 2).
  void zero_effective_stress(Particles<D>& P, size_t b, int count) const {
    const double* contact = P.col(contact_) + b;
    for (int c = 0; c < NS; ++c) {
      double* s = P.col(P.stress, c) + b;
      for (int p = 0; p < count; ++p)
        if (contact[p] == 0) s[p] = 0.0;
    }
  }

  /// Liquid points: L_w from the re-mapped water velocities, the storage rate from both phases'
  /// re-mapped velocities and the nodal porosity (seed 003 eq. 12, see the header), the
  /// intrinsic volume, the move. L_w is kept for the stress update after the smoothing.
  template <int NPP>
  void update_liquid(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count,
                     int thread) {
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    StencilBlock<D>& st = sc.stencil;
    sim.shape->evaluate(sim.grid, P, b, count, st);
    const int npp = NPP ? NPP : st.npp;
    const auto F = deformation_gradient_block(P, F_, b);
    const double* move = move_[kLiquid].data() + b * D;
    const double* g = node_.data();
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      // L_w, and the storage rate sum_I [ (1 - n_I) v_I + n_I w_I ] . grad N_I: the discrete
      // div((1 - n) u_s) + div(n u_w) with the nodal products, the adjoint of the shared
      // liquid stress (n_I G_I to the water, (1 - n_I) G_I to the solid).
      double lw[D][D] = {}, rate = 0, saturation = 0;
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const size_t node = size_t(st.node[kp]);
        const double* vr = remap_.data() + node * 2 * D;
        const double n_I = g[node * S + kN];
        saturation += st.w[kp] * g[node * S + kSat];
        add_velocity_gradient<D>(lw, vr + D, st, size_t(k), p);
        for (int d = 0; d < D; ++d)
          rate += ((1 - n_I) * vr[d] + n_I * vr[D + d]) *
                  st.grad[(size_t(k) * D + size_t(d)) * kBlock + size_t(p)];
      }
      move_point(sim.held_faces_water, P, i, move + size_t(p) * D);
      for (int a = 0; a < D; ++a)
        for (int c = 0; c < D; ++c) lw_[i * D * D + size_t(a * D + c)] = lw[a][c];
      if (F[0]) update_deformation_gradient<D>(F, lw, dt, p);
      P.col(saturation_)[i] = saturation;
      // n: the step's, from the scatter; the water's share of a compression of the pores
      const double share = water_share(saturation);
      const double factor = 1 + dt * (share == 1 || rate > 0 ? rate : share * rate) / P.col(n_)[i];
      if (!volume_rate_.empty()) volume_rate_[i] = (factor - 1) / dt;  // the energy ledger's
      P.col(P.volume)[i] *= factor;
      if (!(factor > 0)) sc.bad_volume = long(i);
    }
  }

  /// After the move, per grid cell: the liquid points' volume and mass sums, then
  /// - pressure_smoothing: cell: the water density m / V is projected per cell onto the shape
  ///   function's pressure space (framework/cell_projection.hpp), V <- m / rho_projected: the
  ///   cell's mean density sum m / sum V (linear, gimp, cpdi; mass and the cell's water volume
  ///   are kept), so the fluid's pressure is one per cell, or the volume-weighted linear fit of
  ///   the density (bspline2: a constant per cell is not in equilibrium with the weight where a
  ///   free surface cuts the B-splines, and the water accelerated without bound). Without it two
  ///   points of a cell can carry opposite pressures that exert no nodal force, and the storage
  ///   equation feeds them: the Terzaghi column's top cell reached +-7e5 Pa under a 1e4 Pa load.
  ///   The single-point scheme does the same with its pore pressure (the Q1-P0 element; Anura3D
  ///   smooths the liquid pressure per element too).
  /// - free surface: a cell whose pores the water fills less than free_surface_filling (its
  ///   volume sum V over n_c V_c, n_c the cell's porosity from the solid points) is at the free
  ///   surface; its liquid points get the flag and, with free_surface_pressure: zero, zero
  ///   pressure (V <- m / rho_0, rho_0 their material's reference density), as Anura3D does.
  ///   Not the default: in the coarse permeameter the pore water spreads out to s/n inside the
  ///   sample, its cells fill less than 0.9, and zero pressure there put Ergun's flux off by
  ///   6.8 % (docs/verification.md F). The weakly compressible water needs no help at a free
  ///   surface: its pressure follows its own density there too.
  /// - partly filled pores (the water's share of a compression r(S) < 1): the water takes no
  ///   tension (V <= m / rho_0): capillary suction is not modelled.
  void liquid_cells(Simulation<D>& sim) {
    Particles<D>& P = sim.sets[kLiquid].particles;
    const double* m = P.col(P.mass);
    double* V = P.col(P.volume);
    const CellPressure degree = smooth_ ? sim.shape->cell_pressure() : CellPressure::kConstant;
    cells_.fit(sim, P, degree, [&](size_t i, double& w, double& wf) {
      w = V[i];
      wf = m[i];
    });
    const long np = long(P.size());
    double* flag = P.col(free_surface_);
    const double* saturation = P.col(saturation_);
    const double filling = free_filling_;
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long i = 0; i < np; ++i) {
      const size_t c = cells_.cell(size_t(i));
      const bool surface = cells_.weight(c) < filling * cell_porosity(c) / inv_cell_volume_;
      flag[i] = surface ? 1.0 : 0.0;
      const double share = water_share(saturation[i]);
      auto free_volume = [&] { return m[i] / sim.materials[P.material[size_t(i)]]->density(); };
      if (surface && zero_surface_pressure_)
        V[i] = free_volume();
      else if (smooth_ && degree == CellPressure::kConstant)
        V[i] = m[i] * cells_.weight(c) / cells_.weighted_value(c);
      else if (smooth_)
        V[i] = m[i] / cells_.at(sim.grid, P, size_t(i));
      if (share < 1) V[i] = std::min(V[i], free_volume());  // no suction in partly filled pores
    }
  }

  /// The fluid's stress from its density and L_w, and the pressure field, per block.
  void liquid_stress(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count,
                     int thread) {
    Particles<D>& P = set.particles;
    double* L = scratch_[size_t(thread)]->L.data();
    for (int p = 0; p < count; ++p)
      for (int a = 0; a < D * D; ++a)
        L[size_t(a) * kBlock + size_t(p)] = lw_[(b + size_t(p)) * D * D + size_t(a)];
    const double* Lp = sim.ledger.enabled ? stress_power_gradient(L, b, count, thread) : nullptr;
    sim.update_block_stress(set, b, count, dt, L, Lp);
    water_pressure(P, b, b + size_t(count));
  }

  /// The gradient whose stress power the ledger counts for liquid points [b, b + count): the
  /// volume followed the storage equation, not tr L_w, so the trace is the applied rate (the
  /// pressure's work on both phases, p V rate); the deviatoric part is L_w's.
  const double* stress_power_gradient(const double* L, size_t b, int count, int thread) {
    double* Lp = scratch_[size_t(thread)]->L_power.data();
    for (int p = 0; p < count; ++p) {
      double tr = 0;
      for (int d = 0; d < D; ++d) tr += L[size_t(d * D + d) * kBlock + size_t(p)];
      const double shift = (volume_rate_[b + size_t(p)] - tr) / D;
      for (int a = 0; a < D * D; ++a)
        Lp[size_t(a) * kBlock + size_t(p)] =
            L[size_t(a) * kBlock + size_t(p)] + (a % (D + 1) == 0 ? shift : 0.0);
    }
    return Lp;
  }

  /// The pore_pressure field of liquid points [b, e): -tr(sigma_w)/3.
  void water_pressure(Particles<D>& P, size_t b, size_t e) const {
    for (size_t i = b; i < e; ++i) {
      double tr = 0;
      for (int c = 0; c < 3; ++c) tr += P.col(P.stress, c)[i];
      P.col(p_)[i] = -tr / 3;
    }
  }

  /// Move a point by dt v_grid, never across a face held for its phase (the water passes a
  /// face held for the solid only, or released by a drained condition).
  static void move_point(const HeldFaces<D>& walls, Particles<D>& P, size_t i, const double* dx) {
    for (int d = 0; d < D; ++d)
      P.col(P.position, d)[i] = walls.moved(d, P.col(P.position, d)[i], dx[d]);
  }
};

LOAM_REGISTER(Scheme, TwoPhaseDoublePoint)

}  // namespace loam
