// Strength reduction (docs/strength_reduction.md): the factor of safety of the model in the static
// state the last stage ended in. A trial divides the strength of the chosen bodies by F
// (Material::reduced: c / F, tan(phi) / F) and runs from that state until it is static again
// (stable) or a particle has moved failure_displacement from it (failed). The motion decides,
// not the time it takes: near the factor a model can creep for seconds at a steady rate and
// then stop, or go on, and no trend of the motion tells which beforehand. max_time only bounds
// a trial's cost; a trial still moving then is undecided, counted as failed, and the search
// says so when such a trial bounds the bracket. The largest stable F is found by bisection on
// [F_low, F_high] to `tolerance` (Dawson, Roth & Drescher 1999; Griffiths & Lane 1999, for
// finite elements). Every trial starts from the same in-memory copy of the static state, so
// trials are independent of their order.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "interrupt.hpp"
#include "run.hpp"

namespace loam {
namespace detail {

namespace {

/// The material body b has after the last stage: the last stage's change of it, else its own.
template <int D>
const Material<D>& final_material(const Simulation<D>& sim, int b) {
  for (auto st = sim.stages.rbegin(); st != sim.stages.rend(); ++st)
    for (const auto& c : st->materials)
      if (c.body == b) return *c.material;
  return *sim.materials[size_t(b)];
}

/// The undecided trial that bounds the search's bracket, if any: the smallest failed factor of a
/// converged search, or F_low of a search below its bracket. Its verdict would change with
/// max_time (docs/strength_reduction.md, "What a trial does").
const nlohmann::json* undecided_bound(const nlohmann::json& trials, const std::string& status,
                                      double lo, double hi) {
  const double bound = status == "converged" ? hi : status == "below_bracket" ? lo : NAN;
  for (const auto& t : trials)
    if (t["factor"].get<double>() == bound && t["status"] == "undecided") return &t;
  return nullptr;
}

}  // namespace

template <int D>
void Run<D>::check_strength_reduction(Diagnostics& diag) {
  if (!cfg_.params.given("strength_reduction")) return;
  const Params& r = cfg_.params.section("strength_reduction");
  const Simulation<D>& sim = *sim_;
  const auto& bl = cfg_.params.list("bodies");
  const auto& names = r.strings("bodies");
  srf_bodies_.clear();
  std::string left_out;
  for (size_t b = 0; names.empty() && b < bl.size(); ++b) {
    if (final_material(sim, int(b)).reduced(1.0))
      srf_bodies_.push_back(int(b));
    else
      left_out += (left_out.empty() ? "'" : ", '") + sim.bodies[b].name + "'";
  }
  if (!left_out.empty() && !srf_bodies_.empty() && sim.ranks->root())
    spdlog::warn(
        "strength reduction leaves out {}: no strength to reduce (an elastic or fluid "
        "model after the last stage)",
        left_out);
  if (names.empty() && srf_bodies_.empty())
    diag.error(r.where(), r.path(),
               "no body's material has a strength to reduce (elastic and fluid models have "
               "none): the factor of safety is undefined");
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string path = r.path("bodies") + "." + std::to_string(i);
    const int b = sim.body_index(names[i]);
    if (b < 0) {
      sim.unknown_body(diag, r.where("bodies", i), path, names[i]);
    } else if (!final_material(sim, b).reduced(1.0)) {
      diag.error(r.where("bodies", i), path,
                 "body '" + names[i] +
                     "' has a material without a strength to reduce after the last stage (an "
                     "elastic or fluid model)");
    } else {
      srf_bodies_.push_back(b);
    }
  }
  if (!sim.sources.empty() || !sim.sinks.empty())
    diag.error(r.where(), r.path(),
               "strength reduction with sources or sinks is not supported: every trial restarts "
               "from the particles of the static state");
}

template <int D>
double Run<D>::largest_displacement() const {
  // Along a periodic axis the nearest image: a particle that wrapped moved by less than half
  // the grid's length.
  const auto& period = sim_->held_faces.period;
  double u2 = 0;
  for (const auto& set : sim_->sets) {
    const Particles<D>& P = set.particles;
    for (size_t i = 0; i < P.size(); ++i) {
      double a = 0;
      for (int d = 0; d < D; ++d) {
        double u = P.col(P.position, d)[i] - P.col(initial_position_, d)[i];
        if (period[size_t(d)] > 0) u -= period[size_t(d)] * std::round(u / period[size_t(d)]);
        a += u * u;
      }
      u2 = std::max(u2, a);
    }
  }
  return sim_->ranks->max(std::sqrt(u2));  // over the ranks: every rank calls it
}

template <int D>
double Run<D>::default_static_window() const {
  const Simulation<D>& sim = *sim_;
  double longest = 0;
  for (int d = 0; d < D; ++d)
    longest = std::max(longest, sim.grid.upper_corner()[size_t(d)] - sim.grid.origin[size_t(d)]);
  // Under mpirun the fastest wave over the ranks (a rank may hold no particle yet).
  return longest / std::max(sim.ranks->max(sim.wave_speed()), 1e-300);
}

/// One trial from the static state (in sim.last_good on entry): its record, status "static",
/// "moved" (failure_displacement reached), "undecided" (still moving when max_time passed),
/// "unstable" or "interrupted".
template <int D>
nlohmann::json Run<D>::srf_trial(const typename Simulation<D>::GoodState& start, double F) {
  Simulation<D>& sim = *sim_;
  const Params& r = cfg_.params.section("strength_reduction");
  sim.last_good = start;
  sim.swap_last_good();
  sim.failure.clear();
  for (size_t i = 0; i < srf_bodies_.size(); ++i)
    sim.materials[size_t(srf_bodies_[i])] = srf_strong_[i]->reduced(F);
  for (auto& set : sim.sets) sim.restart_displacement(set.particles, 0, set.particles.size());
  const double t0 = sim.time, t_end = t0 + r.real("max_time");
  const long step0 = sim.step;
  const double window =
      r.real("static_window") > 0 ? r.real("static_window") : default_static_window();
  const double fail_u = r.real("failure_displacement");
  const auto wall0 = std::chrono::steady_clock::now();
  std::string status = "undecided";
  double since = -1;
  sim.track_motion = true;
  while (sim.time < t_end * (1 - 1e-12)) {
    const double dt = std::min(sim.stable_dt(), t_end - sim.time);
    if (!sim.advance(dt)) {
      status = "unstable";
      break;
    }
    int signal = InterruptGuard::requested();
    if (sim.ranks->distributed()) signal = sim.ranks->max(signal);  // every rank stops together
    if (signal != 0) {
      status = "interrupted";
      break;
    }
    if (sim.checked_step != sim.step) continue;
    if (largest_displacement() > fail_u) {
      status = "moved";
      break;
    }
    if (at_rest(sim.time, sim.motion_speed, r.real("static_speed"), window, since)) {
      status = "static";
      break;
    }
  }
  srf_steps_ += sim.step - step0;
  nlohmann::json rec{
      {"factor", F},
      {"status", status},
      {"time", sim.time - t0},
      {"steps", sim.step - step0},
      {"motion_speed", sim.motion_speed},
      {"max_displacement", largest_displacement()},
      {"wall_seconds",
       std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count()}};
  if (status == "unstable") rec["failure"] = sim.failure;
  if (!opt_.quiet && sim.ranks->root())
    spdlog::info(
        "strength reduction F = {:.5g}: {} after {:.4g} s ({} steps), largest "
        "displacement {:.3g} m",
        F, status, sim.time - t0, sim.step - step0, rec["max_displacement"].get<double>());
  return rec;
}

template <int D>
nlohmann::json Run<D>::strength_reduction() {
  Simulation<D>& sim = *sim_;
  const Params& r = cfg_.params.section("strength_reduction");
  const double tol = r.real("tolerance");
  double lo = r.vec("factors")[0], hi = r.vec("factors")[1];
  const auto wall0 = std::chrono::steady_clock::now();
  sim.save_last_good();
  const typename Simulation<D>::GoodState start = sim.last_good;  // the static state
  const std::vector<double> reactions = sim.reactions.state();    // the trials' are not the run's
  const std::vector<double> ledger = sim.ledger.state();
  srf_strong_.clear();
  for (int b : srf_bodies_) srf_strong_.push_back(std::move(sim.materials[size_t(b)]));
  nlohmann::json trials = nlohmann::json::array();
  double failed_lowest = std::numeric_limits<double>::infinity();
  // A trial; a failed one below every failed so far keeps its end state (the mechanism).
  auto run = [&](double F) {
    trials.push_back(srf_trial(start, F));
    const std::string s = trials.back()["status"];
    const bool failed = s != "static" && s != "interrupted";
    if (failed && F < failed_lowest) {
      failed_lowest = F;
      sim.save_last_good();
      srf_mechanism_ = std::move(sim.last_good);
    }
    return s;
  };
  std::string status = "converged", s;
  if ((s = run(lo)) != "static") {
    status = s == "interrupted" ? s : "below_bracket";
  } else if ((s = run(hi)) == "static" || s == "interrupted") {
    status = s == "interrupted" ? s : "above_bracket";
  } else {
    while (hi - lo > tol * (1 + 1e-9)) {
      const double mid = 0.5 * (lo + hi);
      if ((s = run(mid)) == "interrupted") {
        status = s;
        break;
      }
      (s == "static" ? lo : hi) = mid;
    }
  }
  // Back to the static state with the full strength: the rest of summary.json describes it.
  sim.last_good = start;
  sim.swap_last_good();
  sim.reactions.restore(reactions);
  sim.ledger.restore(ledger);
  for (size_t i = 0; i < srf_bodies_.size(); ++i)
    sim.materials[size_t(srf_bodies_[i])] = std::move(srf_strong_[i]);
  for (auto& set : sim.sets) sim.restart_displacement(set.particles, 0, set.particles.size());
  nlohmann::json out{
      {"status", status},
      {"tolerance", tol},
      {"trials", trials},
      {"steps", srf_steps_},
      {"wall_seconds",
       std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count()}};
  std::vector<std::string> bodies;
  for (int b : srf_bodies_) bodies.push_back(sim.bodies[size_t(b)].name);
  out["bodies"] = bodies;
  if (status == "converged") {
    out["factor_of_safety"] = 0.5 * (lo + hi);
    out["factor_of_safety_bracket"] = {lo, hi};
  } else if (status == "below_bracket") {
    out["factor_of_safety_bracket"] = {0.0, lo};
  } else if (status == "above_bracket") {
    out["factor_of_safety_bracket"] = {hi, nullptr};
  }
  if (!opt_.quiet && sim.ranks->root() && status == "converged")
    spdlog::info("factor of safety {:.4g} (bracket [{:.5g}, {:.5g}], {} trials)", 0.5 * (lo + hi),
                 lo, hi, trials.size());
  if (const nlohmann::json* t = undecided_bound(trials, status, lo, hi)) {
    out["status"] = "undecided";
    out["undecided_factor"] = (*t)["factor"];
    if (sim.ranks->root())
      spdlog::warn(
          "strength reduction: the trial F = {:.5g} bounds the bracket but was still moving when "
          "max_time = {:g} s passed (largest displacement {:.3g} m, failure_displacement {:g} "
          "m); it is counted as failed, so the factor of safety may be higher: raise max_time",
          (*t)["factor"].get<double>(), r.real("max_time"), (*t)["max_displacement"].get<double>(),
          r.real("failure_displacement"));
  }
  return out;
}

#define LOAM_INSTANTIATE_SRF(D)                                                                \
  template void Run<D>::check_strength_reduction(Diagnostics&);                                \
  template double Run<D>::largest_displacement() const;                                        \
  template double Run<D>::default_static_window() const;                                       \
  template nlohmann::json Run<D>::srf_trial(const typename Simulation<D>::GoodState&, double); \
  template nlohmann::json Run<D>::strength_reduction();
LOAM_INSTANTIATE_SRF(1)
LOAM_INSTANTIATE_SRF(2)
LOAM_INSTANTIATE_SRF(3)

}  // namespace detail
}  // namespace loam
