// Stages of a run (docs/stages.md): building them from `stages:` with every check of their
// changes before the run starts, and what happens at a stage's start. The loop that runs them,
// ends them after their time or once static and writes their records is in runner.cpp.
#include <spdlog/spdlog.h>

#include <cmath>

#include "registry.hpp"
#include "simulation.hpp"

namespace loam {

namespace {

/// 1 for the particles of body b (an erase mask).
template <int D>
std::vector<uint8_t> of_body(const Particles<D>& P, int b) {
  std::vector<uint8_t> mask(P.size());
  for (size_t i = 0; i < P.size(); ++i) mask[i] = P.body[i] == b;
  return mask;
}

}  // namespace

template <int D>
void Simulation<D>::create_stages(Diagnostics& diag) {
  Registry& reg = Registry::instance();
  const auto& list = config.list("stages");
  if (list.empty()) {  // a plain run: one stage of time.end, changing nothing
    stages.emplace_back();
    stages.back().name = "run";
    stages.back().duration = end_time;
    return;
  }
  const auto& bl = config.list("bodies");
  // Whether each body is in the run, stage by stage: 0 not yet (active: false), 1 in the run,
  // 2 deactivated. A body is activated once, from 0, and deactivated only while in the run.
  std::vector<char> state;
  for (const auto& b : bl) state.push_back(b.flag("active") ? 1 : 0);
  end_time = 0;
  for (const Params& sp : list) {
    stages.emplace_back();
    Stage<D>& st = stages.back();
    st.params = sp;
    st.name = sp.text("name");
    st.until_static = sp.has("until");
    st.duration = st.until_static ? sp.real("max_time") : sp.real("duration");
    st.stop_if_not_static = sp.text("if_not_static") == "stop";
    st.static_speed = sp.real("static_speed");
    st.static_window = sp.real("static_window");
    end_time += st.duration;
    for (size_t j = 0; j + 1 < stages.size(); ++j)
      if (stages[j].name == st.name)
        diag.error(sp.where("name"), sp.path("name"), "duplicate stage name '" + st.name + "'");
    st.sets_loads = sp.given("loads");
    for (const auto& l : sp.list("loads")) st.loads.push_back(reg.create<Load, D>(l));
    st.sets_boundaries = sp.given("boundaries");
    for (const auto& b : sp.list("boundaries")) st.boundaries.push_back(reg.create<Boundary, D>(b));
    st.sets_damping = sp.has("damping");
    if (st.sets_damping) st.damping = reg.create<Damping, D>(sp.section("damping"));
    const auto& changes = sp.list("materials");
    for (size_t c = 0; c < changes.size(); ++c) {
      const Params& mc = changes[c];
      const int b = body_index(mc.text("body"));
      if (b < 0) {
        unknown_body(diag, mc.where("body"), mc.path("body"), mc.text("body"));
        continue;
      }
      for (size_t k = 0; k < c; ++k)
        if (changes[k].text("body") == mc.text("body"))
          diag.error(mc.where("body"), mc.path("body"),
                     "the material of body '" + mc.text("body") +
                         "' is changed twice in this "
                         "stage");
      typename Stage<D>::MaterialChange change;
      change.body = b;
      change.material = reg.create<Material, D>(mc.section("material"));
      change.new_type = mc.section("material").type() != bl[size_t(b)].section("material").type();
      if (change.material->is_fluid() != materials[size_t(b)]->is_fluid())
        diag.error(mc.where("material"), mc.path("material"),
                   std::string("body '") + mc.text("body") + "' is a " +
                       (materials[size_t(b)]->is_fluid() ? "fluid" : "solid") +
                       ": its material cannot become a " +
                       (change.material->is_fluid() ? "fluid" : "solid") + " in a stage");
      st.materials.push_back(std::move(change));
    }
    for (const char* key : {"activate", "deactivate"}) {
      const bool on = key[0] == 'a';
      const auto& names = sp.strings(key);
      for (size_t i = 0; i < names.size(); ++i) {
        const std::string path = sp.path(key) + "." + std::to_string(i);
        const int b = body_index(names[i]);
        if (b < 0) {
          unknown_body(diag, sp.where(key, i), path, names[i]);
          continue;
        }
        const char now = state[size_t(b)];
        if (on && now != 0)
          diag.error(sp.where(key, i), path,
                     "body '" + names[i] + "' " +
                         (now == 1 ? (bl[size_t(b)].flag("active")
                                          ? "is in the run from the start (no `active: false`)"
                                          : "was activated by an earlier stage")
                                   : "was deactivated by an earlier stage") +
                         ": a body is activated once, from `active: false`");
        else if (!on && now != 1)
          diag.error(sp.where(key, i), path,
                     "body '" + names[i] + "' is not in the run at this stage (" +
                         (now == 0 ? "it has `active: false` and no earlier stage activates it"
                                   : "deactivated by an earlier stage") +
                         ")");
        state[size_t(b)] = on ? 1 : 2;
        (on ? st.activate : st.deactivate).push_back(b);
      }
    }
    for (const auto& r : sp.strings("reset")) {
      st.reset_displacement = st.reset_displacement || r == "displacement";
      st.reset_velocity = st.reset_velocity || r == "velocity";
      st.reset_plastic_strain = st.reset_plastic_strain || r == "plastic_strain";
    }
    st.sets_output = sp.given("output");
    if (st.sets_output) {
      const Params& o = sp.section("output");
      st.every_steps = o.has("every_steps") ? long(o.integer("every_steps")) : 0;
      st.every_time = o.has("every_time") ? o.real("every_time") : 0.0;
      if (!st.every_steps && st.every_time <= 0)
        diag.error(sp.where("output"), sp.path("output"), "give every_steps or every_time");
    }
  }
}

template <int D>
void Simulation<D>::setup_stage_plugins(const char* what, Diagnostics& diag) {
  const std::string w = what;
  for (auto& st : stages) {
    if (w == "materials")
      for (auto& c : st.materials) c.material->setup(*this, c.body, diag);
    if (w == "boundaries")
      for (auto& b : st.boundaries) b->setup(*this, diag);
    if (w == "loads")
      for (auto& l : st.loads) l->setup(*this, diag);
  }
}

template <int D>
void Simulation<D>::keep_inactive_bodies_aside() {
  const auto& bl = config.list("bodies");
  inactive_.resize(bl.size());
  active_.assign(bl.size(), 1);
  bool any = false;
  for (size_t b = 0; b < bl.size(); ++b) {
    if (bl[b].flag("active")) continue;
    active_[b] = 0;
    any = true;
    ParticleSet<D>& set = sets[size_t(body_set(int(b)))];
    Particles<D>& P = set.particles;
    const std::vector<uint8_t> mine = of_body(P, int(b));
    std::vector<uint8_t> others(mine.size());
    for (size_t i = 0; i < mine.size(); ++i) others[i] = !mine[i];
    inactive_[b] = P;
    inactive_[b].erase(others);
    P.erase(mine);
    set.invalidate_index();
  }
  if (any) sort();
}

template <int D>
void Simulation<D>::swap_stage_plugins(int k) {
  Stage<D>& st = stages[size_t(k)];
  if (st.sets_loads) std::swap(loads, st.loads);
  if (st.sets_boundaries) {
    std::swap(boundaries, st.boundaries);
    held_faces = HeldFaces<D>(grid, boundaries);
    held_faces_water = HeldFaces<D>(grid, boundaries, 1);
  }
  if (st.sets_damping) std::swap(damping, st.damping);
  for (auto& c : st.materials) std::swap(materials[size_t(c.body)], c.material);
}

template <int D>
void Simulation<D>::begin_stage(int k) {
  stage = k;
  Stage<D>& st = stages[size_t(k)];
  if (st.sets_loads) loads_start = time;
  swap_stage_plugins(k);
  std::vector<char> resized(sets.size(), 0);
  for (int b : st.deactivate) {
    ParticleSet<D>& set = sets[size_t(body_set(b))];
    Particles<D>& P = set.particles;
    const std::vector<uint8_t> mine = of_body(P, b);
    size_t n = 0;
    for (size_t i = 0; i < P.size(); ++i)
      if (mine[i]) mass_removed += P.col(P.mass)[i], ++n;
    carry_energy(P, 0, P.size(), -1.0, mine.data());
    P.erase(mine);
    removed += n;
    active_[size_t(b)] = 0;
    resized[size_t(body_set(b))] = 1;
  }
  for (int b : st.activate) {
    ParticleSet<D>& set = sets[size_t(body_set(b))];
    Particles<D>& P = set.particles;
    const size_t begin = P.size();
    P.append(inactive_[size_t(b)]);
    inactive_[size_t(b)] = Particles<D>();
    for (size_t i = begin; i < P.size(); ++i) mass_created += P.col(P.mass)[i];
    carry_energy(P, begin, P.size(), 1.0);
    created += P.size() - begin;
    restart_displacement(P, begin, P.size());  // its displacement counts from when it joins
    active_[size_t(b)] = 1;
    resized[size_t(body_set(b))] = 1;
  }
  for (size_t s = 0; s < sets.size(); ++s)
    if (resized[s]) sets[s].invalidate_index(), sort(sets[s]);
  for (auto& c : st.materials) {  // a new model starts its state from the current stress
    if (!c.new_type) continue;
    auto& set = sets[size_t(body_set(c.body))];
    const auto& r = set.partition.material_ranges[size_t(c.body)];
    if (r.end > r.begin) materials[size_t(c.body)]->initialize(set.particles, r.begin, r.end);
  }
  // A velocity reset takes the motion's kinetic energy out of the run (the energy balance's
  // E_carried; energies() is over the ranks, counted once).
  const bool take = st.reset_velocity && ledger.enabled;
  const double kinetic_before = take ? energies().kinetic : 0.0;
  std::vector<std::string> velocities{"velocity"};
  for (const auto& f : scheme->velocity_fields()) velocities.push_back(f);
  for (auto& set : sets) {
    Particles<D>& P = set.particles;
    auto zero = [&](const std::string& name) {
      const int h = P.find(name);
      if (!P.has(h)) return;
      for (int c = 0; c < P.info(h).components; ++c)
        std::fill(P.col(h, c), P.col(h, c) + P.size(), 0.0);
    };
    if (st.reset_velocity)
      for (const auto& f : velocities) zero(f);
    if (st.reset_plastic_strain) zero(plastic_strain_eq_field().name);
    if (st.reset_displacement) restart_displacement(P, 0, P.size());
  }
  if (st.reset_velocity) {
    max_speed = 0;
    const double taken = take ? kinetic_before - energies().kinetic : 0.0;
    if (ranks->root()) ledger.totals.carried_kinetic -= taken;
  }
  if (!st.params.path().empty() && ranks->root())
    spdlog::info("stage {} '{}' begins at t = {:.6g} s", k + 1, st.name, time);
}

#define LOAM_INSTANTIATE_STAGES(D)                                             \
  template void Simulation<D>::create_stages(Diagnostics&);                    \
  template void Simulation<D>::setup_stage_plugins(const char*, Diagnostics&); \
  template void Simulation<D>::keep_inactive_bodies_aside();                   \
  template void Simulation<D>::swap_stage_plugins(int);                        \
  template void Simulation<D>::begin_stage(int);
LOAM_INSTANTIATE_STAGES(1)
LOAM_INSTANTIATE_STAGES(2)
LOAM_INSTANTIATE_STAGES(3)

}  // namespace loam
