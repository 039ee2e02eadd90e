// Reference: seepage under a single impermeable sheet pile and the onset of piping ("Numerical
// Modelling of the Internal Erosion Process in Granular Soils using the Material Point Method",
// seed 000; docs/verification.md I). Harr (1962, Groundwater and Seepage, ch. 3, conformal
// mapping): a pile driven to depth d into a homogeneous layer of infinite depth, the water levels
// differing by ΔH across it, has the head field
//   h(x, y) = h_down + (ΔH / π) Re[arccos(t / d)],   t = ±√(z² + d²),  z = (x - x_pile) + i (y -
//   y_s)
// (the sign of t that of x - x_pile: + downstream), so the exit gradient at the downstream
// surface a distance x from the pile is ΔH / (π √(x² + d²)), at the pile i_exit = ΔH / (π d).
// With the critical gradient i_c = (G_s - 1)(1 - n) = γ'/γ_w the soil next to the pile
// fluidises at ΔH_c = π d i_c (the exit-gradient criterion); Terzaghi's prism d deep and d/2 wide
// heaves when the mean excess head on its base reaches i_c d, ΔH_c = i_c d / h̄, with h̄/ΔH the
// mean of Harr's head on the base (0.354 ΔH: ΔH_c = 2.83 i_c d).
//
// What it measures, every `every` seconds:
// - the head difference ΔH = h_up - h_down: the mean head p/γ_w + y of the pressure set's points
//   within `head_band` above the soil surface, on each side, at least d/2 from the pile;
// - the exit gradient in the exit window (x_pile ≤ x ≤ x_pile + width, y_s - depth ≤ y ≤ y_s)
//   from the seepage: i = n (w_y - v_y) / k, Darcy's law for the flux relative to the skeleton,
//   i.e. the drag on the grains over γ_w, the force that lifts them (cell means of the liquid
//   and solid points' vertical velocity and the solid porosity, averaged over the window's cells
//   weighted by their liquid points), against Harr's -dh/dy averaged at the same cell centroids;
// - the exit gradient from the pressures (series exit_gradient_pressure): -dh/dy, the
//   least-squares slope of the cell-mean head over the window, Harr's fitted the same way. The
//   liquid points' own pressures scatter by far more than their cell means (with linear hats a
//   cell's nodal forces see only its sum of V p; docs/verification.md I), so this one is noisy;
// - the fluidised points of the bed (a `contact` field of 0) downstream of the pile, and the heave:
//   the rise of the highest grain of the bed within d/2 downstream of the pile;
// - the pipe along the pile: pipe_fraction, the share of the embedded depth d (in rows one cell
//   high, from the tip to the surface; heaved grains above it count in the top row) holding a
//   fluidised grain within the exit window's width of the downstream face. 1 is a fluidised
//   channel from the tip to the exit.
// Metrics: exit_gradient_error (the slope through the origin of the seepage exit gradient
// against Harr's over the intact samples, ΔH ≥ ΔH_c/4 and before the critical head, minus 1),
// critical_head (ΔH at the first sample whose seepage exit gradient reaches i_c: the quick
// condition next to the pile, zero effective stress at the exit, Harr's and Terzaghi's
// criterion; NaN if never), critical_head_fluidised (ΔH at the first sample with a grain
// fluidised at n_max downstream; NaN if none), critical_head_harr (π d i_c),
// critical_head_prism, critical_head_error (critical_head against Harr), heave,
// fluidised_points and pipe_fraction at the end, critical_gradient.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "plugins/references/sheet_pile.hpp"

namespace loam {

template <int D>
class SheetPileSeepage : public Reference<D> {
 public:
  static constexpr const char* name = "sheet_pile_seepage";
  static constexpr const char* summary =
      "seepage under a sheet pile: exit gradient and critical head against Harr (1962), the "
      "piping scene of docs/verification.md I";
  static Schema schema() {
    Schema s;
    s.text("body", "the soil (default: the first body)");
    s.real("pile", "m", "position of the pile along the first axis (downstream is +x)").required();
    s.real("depth", "m", "embedment d of the pile below the soil surface").positive().required();
    s.real("surface", "m",
           "level of the soil surface (default: the top of the soil body's domain)");
    s.text("pressure_set",
           "the set whose points carry the pore pressure (default: the scheme's last set: "
           "`liquid` in the double-point scheme)");
    s.real("water_density", "kg/m^3", "density of the water (γ_w = ρ_w g)").def("1000").positive();
    s.real("critical_gradient", "-",
           "i_c (default: (ρ_s/ρ_w - 1)(1 - n0) from the soil's density and scheme.porosity)")
        .positive();
    s.real_list("exit_window", "m",
                "width and depth of the exit window next to the pile, downstream (default: d/4 "
                "and d/2; at least two cell rows deep)");
    s.real("head_band", "m",
           "height of the band above the soil surface where the side heads are measured "
           "(default: d/4)")
        .positive();
    s.real("hydraulic_conductivity", "m/s",
           "Darcy k of the soil for the seepage exit gradient i = n (w - v) / k (default: "
           "scheme.drag.hydraulic_conductivity of a darcy drag)")
        .positive();
    s.real("every", "s", "sampling interval").def("0.05").positive();
    return s;
  }
  explicit SheetPileSeepage(const Params& p)
      : params_(p), x_pile_(p.real("pile")), d_(p.real("depth")), clock_{p.real("every")} {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (D < 2) {
      diag.error(params_.where(), params_.path(), "sheet_pile_seepage needs a 2D or 3D run");
      return;
    }
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    const Body& b = sim.bodies[size_t(body_)];
    surface_ = params_.has("surface") ? params_.real("surface") : b.upper[D - 1];
    set_ = params_.has("pressure_set") ? sim.set_param(params_, "pressure_set", diag)
                                       : int(sim.sets.size()) - 1;
    if (set_ < 0) return;
    pressure_ = sim.sets[size_t(set_)].particles.find("pore_pressure");
    if (pressure_ < 0) {
      diag.error(params_.where(), params_.path(),
                 "the points of set '" + sim.sets[size_t(set_)].name +
                     "' carry no pore pressure: give pressure_set");
      return;
    }
    contact_ = sim.particles_of_body(body_).find("contact");
    gamma_w_ = params_.real("water_density") * std::fabs(sim.gravity[D - 1]);
    if (!(gamma_w_ > 0)) {
      diag.error(params_.where(), params_.path(), "needs gravity along the last axis");
      return;
    }
    if (params_.has("critical_gradient")) {
      i_c_ = params_.real("critical_gradient");
    } else {
      const Params& scheme = sim.config.section("scheme");
      if (!scheme.has("porosity")) {
        diag.error(params_.where(), params_.path(),
                   "the scheme has no porosity: give critical_gradient");
        return;
      }
      const double rho_s = b.params.section("material").real("density");
      i_c_ = (rho_s / params_.real("water_density") - 1) * (1 - scheme.real("porosity"));
    }
    const Params& scheme = sim.config.section("scheme");
    if (params_.has("hydraulic_conductivity")) {
      k_ = params_.real("hydraulic_conductivity");
    } else if (scheme.has("drag") && scheme.section("drag").type() == "darcy") {
      k_ = scheme.section("drag").real("hydraulic_conductivity");
    } else {
      diag.error(params_.where(), params_.path(),
                 "the scheme has no darcy drag: give hydraulic_conductivity");
      return;
    }
    porosity_ = sim.particles_of_body(body_).find("porosity");
    n0_ = scheme.has("porosity") ? scheme.real("porosity") : std::nan("");
    width_ = band_ = d_ / 4, depth_ = d_ / 2;
    if (params_.has("exit_window")) {
      const auto& w = params_.vec("exit_window");
      if (w.size() != 2 || !(w[0] > 0) || !(w[1] > 0)) {
        diag.error(params_.where("exit_window"), params_.path("exit_window"),
                   "give two positive lengths: [width, depth]");
        return;
      }
      width_ = w[0], depth_ = w[1];
    }
    if (depth_ < 2 * sim.grid.cell[D - 1] * (1 - 1e-9))
      diag.error(params_.where(), params_.path(),
                 "the exit window (" + format_number(depth_) +
                     " m deep) must span two cell rows (" +
                     format_number(2 * sim.grid.cell[D - 1]) +
                     " m): give a deeper exit_window or a finer grid");
    if (params_.has("head_band")) band_ = params_.real("head_band");
    heave_base_ = strip_top(sim);
    if (!std::isfinite(heave_base_))
      diag.error(params_.where("pile"), params_.path("pile"),
                 "no grain of the soil lies within d/2 downstream of the pile");
  }

  void sample(Simulation<D>& sim) override {
    if (!clock_.due(sim.time)) return;
    const Particles<D>& P = sim.sets[size_t(set_)].particles;
    const double* y = P.col(P.position, D - 1);
    const double* x = P.col(P.position, 0);
    const double* p = P.col(pressure_);
    // Side heads in the water over the soil.
    double up = 0, down = 0;
    size_t n_up = 0, n_down = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      if (y[i] < surface_ || y[i] > surface_ + band_) continue;
      const double h = p[i] / gamma_w_ + y[i];
      if (x[i] < x_pile_ - d_ / 2) up += h, ++n_up;
      if (x[i] > x_pile_ + d_ / 2) down += h, ++n_down;
    }
    sum_over_ranks(*sim.ranks, up, n_up, down, n_down);  // identity serially
    const double h_up = n_up ? up / double(n_up) : std::nan("");
    const double h_down = n_down ? down / double(n_down) : std::nan("");
    const double dH = h_up - h_down;
    // Exit gradient: least-squares slope of the head against y over the window's cells (cell
    // means of pressure and position: a scheme may hold one pressure per cell), measured and
    // Harr's at the same cell centroids.
    std::map<std::array<long, D>, std::array<double, 4>> cells;  // sum x, y, p; count
    std::array<long, D> c{};
    for (size_t i = 0; i < P.size(); ++i) {
      if (!window_cell(sim, P, i, c)) continue;
      auto& a = cells[c];
      a[0] += x[i], a[1] += y[i], a[2] += p[i], a[3] += 1;
    }
    merge_over_ranks(*sim.ranks, cells);
    double sy = 0, sh = 0, shh = 0, syy = 0, syh = 0, syhh = 0, n = 0;
    for (const auto& [c, a] : cells) {
      const double w = a[3], xc = a[0] / w, yc = a[1] / w;
      const double h = a[2] / w / gamma_w_ + yc;
      const double hh = dH * harr_head_fraction(xc - x_pile_, yc - surface_, d_);
      sy += w * yc, sh += w * h, shh += w * hh, syy += w * yc * yc, syh += w * yc * h;
      syhh += w * yc * hh, n += w;
    }
    const double var = syy - sy * sy / n;
    const bool fit = cells.size() >= 2 && var > 1e-12 * depth_ * depth_ * n;
    const double i_exit = fit ? -(syh - sy * sh / n) / var : std::nan("");
    const double i_harr = fit ? -(syhh - sy * shh / n) / var : std::nan("");
    const Particles<D>& S = sim.particles_of_body(body_);
    const auto [i_seep, i_seep_harr] = seepage_exit_gradient(sim, P, S, dH);
    // Fluidised grains downstream and the heave next to the pile.
    long fluidised = 0;
    const double row = sim.grid.cell[D - 1];
    std::vector<char> pipe_rows(size_t(std::max(1L, std::lround(d_ / row))), 0);
    if (S.has(contact_))
      for (size_t i = 0; i < S.size(); ++i) {
        const double x = S.col(S.position, 0)[i], y = S.col(S.position, D - 1)[i];
        if (S.body[i] != body_ || S.col(contact_)[i] != 0 || x <= x_pile_) continue;
        ++fluidised;
        if (x > x_pile_ + width_ || y < surface_ - d_) continue;
        const long r = std::min(long(pipe_rows.size()) - 1, long((y - (surface_ - d_)) / row));
        pipe_rows[size_t(r)] = 1;
      }
    if (sim.ranks->distributed()) {  // over the ranks: the count summed, the rows or-ed
      sum_over_ranks(*sim.ranks, fluidised);
      std::vector<double> rows(pipe_rows.begin(), pipe_rows.end());
      sim.ranks->max(rows.data(), int(rows.size()));
      for (size_t r = 0; r < rows.size(); ++r) pipe_rows[r] = rows[r] > 0 ? 1 : 0;
    }
    const double pipe =
        double(std::count(pipe_rows.begin(), pipe_rows.end(), 1)) / double(pipe_rows.size());
    time_.push_back(sim.time);
    head_.push_back(dH);
    up_.push_back(h_up);
    down_.push_back(h_down);
    exit_.push_back(i_seep);
    harr_.push_back(i_seep_harr);
    exit_p_.push_back(i_exit);
    harr_p_.push_back(i_harr);
    fluidised_.push_back(double(fluidised));
    pipe_.push_back(pipe);
    heave_.push_back(strip_top(sim) - heave_base_);
    if (i_seep >= i_c_ && !std::isfinite(critical_)) critical_ = dH;
    if (fluidised > 0 && !std::isfinite(fluidised_head_)) fluidised_head_ = dH;
  }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    if (time_.empty() || time_.back() < sim.time) {
      clock_.restart();  // the end of the run is always sampled
      sample(sim);
    }
    const double harr = M_PI * d_ * i_c_;
    // Intact samples (before the quick condition) with a head difference large enough to
    // measure against.
    double num = 0, den = 0;
    for (size_t k = 0; k < time_.size(); ++k) {
      if (fluidised_[k] > 0 || exit_[k] >= i_c_) break;  // the intact stage ended
      if (!(head_[k] >= harr / 4) || !std::isfinite(exit_[k])) continue;
      num += exit_[k] * harr_[k], den += harr_[k] * harr_[k];
    }
    return {{"exit_gradient_error", den > 0 ? num / den - 1 : std::nan("")},
            {"critical_head", critical_},
            {"critical_head_fluidised", fluidised_head_},
            {"critical_head_harr", harr},
            {"critical_head_prism", i_c_ * d_ / prism_mean_head()},
            {"critical_head_error", critical_ / harr - 1},
            {"critical_gradient", i_c_},
            {"head_difference", head_.back()},
            {"exit_gradient", exit_.back()},
            {"heave", heave_.back()},
            {"fluidised_points", fluidised_.back()},
            {"pipe_fraction", pipe_.back()}};
  }

  std::vector<Comparison> comparisons(const std::map<std::string, double>&) const override {
    return {{"critical_head", "critical_head_harr", "Harr 1962"}};
  }

  std::vector<std::pair<std::string, std::vector<double>>> series() const override {
    return {{"time", time_},
            {"head_difference", head_},
            {"head_upstream", up_},
            {"head_downstream", down_},
            {"exit_gradient", exit_},
            {"exit_gradient_harr", harr_},
            {"exit_gradient_pressure", exit_p_},
            {"exit_gradient_pressure_harr", harr_p_},
            {"fluidised_points", fluidised_},
            {"pipe_fraction", pipe_},
            {"heave", heave_}};
  }

  /// Its sums, counts and per-cell sums are over the ranks (cell sums merged by cell).
  bool runs_on_ranks() const override { return true; }

  bool save_state(std::vector<double>& s) const override {
    s = {clock_.next, critical_, fluidised_head_, double(time_.size())};
    for (const auto* v : {&time_, &head_, &up_, &down_, &exit_, &harr_, &exit_p_, &harr_p_,
                          &fluidised_, &heave_, &pipe_})
      s.insert(s.end(), v->begin(), v->end());
    return true;
  }
  void restore_state(const std::vector<double>& s) override {
    clock_.next = s.at(0), critical_ = s.at(1), fluidised_head_ = s.at(2);
    const long n = long(s.at(3));
    long k = 4;
    for (auto* v : {&time_, &head_, &up_, &down_, &exit_, &harr_, &exit_p_, &harr_p_, &fluidised_,
                    &heave_, &pipe_}) {
      v->assign(s.begin() + k, s.begin() + k + n);
      k += n;
    }
  }

 private:
  /// Whether point i of Q lies in the exit window (x_pile <= x <= x_pile + width,
  /// y_s - depth <= y <= y_s), and then its grid cell c (the key both exit gradients group by).
  bool window_cell(const Simulation<D>& sim, const Particles<D>& Q, size_t i,
                   std::array<long, D>& c) const {
    const double x = Q.col(Q.position, 0)[i], y = Q.col(Q.position, D - 1)[i];
    if (x < x_pile_ || x > x_pile_ + width_ || y > surface_ || y < surface_ - depth_) return false;
    for (int d = 0; d < D; ++d)
      c[size_t(d)] = long(std::floor((Q.col(Q.position, d)[i] - sim.grid.origin[size_t(d)]) *
                                     sim.grid.inv_cell[size_t(d)]));
    return true;
  }

  /// The exit gradient from the seepage, i = n (w_y - v_y) / k, per cell of the exit window
  /// (liquid points P: w_y; the soil's points S: v_y and n), averaged over the cells weighted by
  /// their liquid points; and Harr's -dh/dy for the head difference dH (central difference)
  /// averaged the same way at the cells' liquid centroids.
  std::pair<double, double> seepage_exit_gradient(const Simulation<D>& sim, const Particles<D>& P,
                                                  const Particles<D>& S, double dH) const {
    // Per cell: liquid x, y, w_y, count; solid v_y, n, count.
    std::map<std::array<long, D>, std::array<double, 7>> cells;
    auto visit = [&](const Particles<D>& Q, size_t i, auto&& add) {
      std::array<long, D> c{};
      if (window_cell(sim, Q, i, c))
        add(cells[c], Q.col(Q.position, 0)[i], Q.col(Q.position, D - 1)[i]);
    };
    for (size_t i = 0; i < P.size(); ++i)
      visit(P, i, [&](auto& a, double x, double y) {
        a[0] += x, a[1] += y, a[2] += P.col(P.velocity, D - 1)[i], a[3] += 1;
      });
    for (size_t i = 0; i < S.size(); ++i)
      if (S.body[i] == body_)
        visit(S, i, [&](auto& a, double, double) {
          a[4] += S.col(S.velocity, D - 1)[i];
          a[5] += S.has(porosity_) ? S.col(porosity_)[i] : n0_;
          a[6] += 1;
        });
    merge_over_ranks(*sim.ranks, cells);
    double sum = 0, sum_harr = 0, weight = 0;
    const double dy = 1e-4 * d_;
    for (const auto& [c, a] : cells) {
      if (a[3] == 0 || a[6] == 0) continue;
      const double xc = a[0] / a[3] - x_pile_, yc = a[1] / a[3] - surface_;
      const double i = a[5] / a[6] * (a[2] / a[3] - a[4] / a[6]) / k_;
      const double i_harr =
          -(harr_head_fraction(xc, yc + dy, d_) - harr_head_fraction(xc, yc - dy, d_)) / (2 * dy);
      sum += a[3] * i, sum_harr += a[3] * i_harr, weight += a[3];
    }
    if (!(weight > 0)) return {std::nan(""), std::nan("")};
    return {sum / weight, dH * sum_harr / weight};
  }

  /// Terzaghi's prism: the mean of Harr's excess head fraction on its base (depth d, from the
  /// pile to d/2 downstream), by Simpson's rule on 200 intervals.
  double prism_mean_head() const {
    const int m = 200;
    double s = 0;
    for (int k = 0; k <= m; ++k) {
      const double w = (k == 0 || k == m) ? 1 : (k % 2 ? 4 : 2);
      s += w * harr_head_fraction(0.5 * d_ * k / m + 1e-12 * d_, -d_, d_);
    }
    return s / (3.0 * m);
  }
  /// The highest grain of the bed within d/2 downstream of the pile (-inf if none).
  double strip_top(const Simulation<D>& sim) const {
    const Particles<D>& P = sim.particles_of_body(body_);
    double top = -std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < P.size(); ++i) {
      const double x = P.col(P.position, 0)[i];
      if (P.body[i] != body_ || x < x_pile_ || x > x_pile_ + d_ / 2) continue;
      top = std::max(top, P.col(P.position, D - 1)[i]);
    }
    return sim.ranks->max(top);  // over the ranks
  }

  /// Per-cell sums of the ranks added cell by cell (in rank order) into every rank's map: each
  /// entry goes as its D cell indices and N sums. Serially nothing is done.
  template <size_t N>
  static void merge_over_ranks(const Ranks<D>& ranks,
                               std::map<std::array<long, D>, std::array<double, N>>& cells) {
    if (!ranks.distributed()) return;
    std::vector<double> mine;
    for (const auto& [c, a] : cells) {
      for (long k : c) mine.push_back(double(k));
      mine.insert(mine.end(), a.begin(), a.end());
    }
    const std::vector<double> all = ranks.all_gather(mine);
    cells.clear();
    for (size_t k = 0; k + D + N <= all.size(); k += D + N) {
      std::array<long, D> c{};
      for (int d = 0; d < D; ++d) c[size_t(d)] = long(all[k + size_t(d)]);
      auto& a = cells[c];
      for (size_t j = 0; j < N; ++j) a[j] += all[k + D + j];
    }
  }

  Params params_;
  double x_pile_, d_;
  SampleClock clock_;
  double surface_ = 0, gamma_w_ = 0, i_c_ = 0;
  double width_ = 0, depth_ = 0, band_ = 0, heave_base_ = 0;
  double critical_ = std::nan("");        // ΔH at the quick condition (i >= i_c)
  double fluidised_head_ = std::nan("");  // ΔH at the first fluidised grain
  int body_ = -1, set_ = -1, pressure_ = -1, contact_ = -1;
  std::vector<double> time_, head_, up_, down_, exit_, harr_, fluidised_, heave_;
  std::vector<double> pipe_;             // pipe_fraction per sample
  std::vector<double> exit_p_, harr_p_;  // the exit gradient from the pressures, and Harr's
  double k_ = 0;                         // Darcy hydraulic conductivity (m/s)
  int porosity_ = -1;                    // the soil points' porosity field
  double n0_ = 0;                        // scheme.porosity, if the soil has no porosity field
};

LOAM_REGISTER(Reference, SheetPileSeepage)

}  // namespace loam
