#pragma once
// What a rigid body under contact reports besides its reaction force (framework/reactions.hpp):
// the displacement of its centre of mass since it became rigid, its rotation (the integral of
// its angular velocity: the angle in 2D, the rotation vector about a fixed axis in 3D) and the
// moment its prescribed rotation components apply about its centre (rotation: fixed; zero when
// it turns freely). Columns of history.csv (rigid_<name>_displacement_x, ..._rotation,
// ..._moment) and summary.json, under the name of the condition's reaction; kept in
// checkpoints. framework/rigid_fields.hpp records each step's motion; under mpirun every rank
// records the same values.
#include <algorithm>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "framework/boundary.hpp"
#include "framework/rigid_motion.hpp"

namespace loam {

template <int D>
class RigidRecords {
 public:
  static constexpr int R = RigidDofs<D>::Q - D;  // rotation components: 0, 1, 3
  /// Per body: displacement (D), rotation (R), moment (R), its least and largest value (R
  /// each), the centre it started from (D), whether it has started (1).
  static constexpr int kDisplacement = 0, kRotation = D, kMoment = D + R, kMomentLow = D + 2 * R,
                       kMomentHigh = D + 3 * R, kStart = D + 4 * R, kStarted = 2 * D + 4 * R,
                       W = 2 * D + 4 * R + 1;

  /// Report condition b's motion under `name` (conditions of one name share the columns).
  void add(const Boundary<D>* b, const std::string& name) {
    const auto it = std::find(names_.begin(), names_.end(), name);
    slot_[b] = size_t(it - names_.begin());
    if (it != names_.end()) return;
    names_.push_back(name);
    std::vector<double> fresh(W, 0.0);
    std::fill_n(fresh.begin() + kMomentLow, R, std::numeric_limits<double>::infinity());
    std::fill_n(fresh.begin() + kMomentHigh, R, -std::numeric_limits<double>::infinity());
    values_.insert(values_.end(), fresh.begin(), fresh.end());
  }
  const std::vector<std::string>& names() const { return names_; }
  bool empty() const { return names_.empty(); }

  /// A step of b's body: its centre of mass moved from `before` to `after`, it turned at
  /// angular velocity omega (R values) over dt under the moment `moment` (R values) of its
  /// prescribed rotation.
  void record(const Boundary<D>* b, const double* before, const double* after, const double* omega,
              const double* moment, double dt) {
    const auto it = slot_.find(b);
    if (it == slot_.end()) return;
    double* v = values_.data() + it->second * W;
    if (!(v[kStarted] > 0)) std::copy(before, before + D, v + kStart), v[kStarted] = 1;
    for (int d = 0; d < D; ++d) v[kDisplacement + d] = after[d] - v[kStart + d];
    for (int k = 0; k < R; ++k) {
      v[kRotation + k] += omega[k] * dt;
      v[kMoment + k] = moment[k];
      v[kMomentLow + k] = std::min(v[kMomentLow + k], moment[k]);
      v[kMomentHigh + k] = std::max(v[kMomentHigh + k], moment[k]);
    }
  }
  /// Body `slot`'s values (the layout above).
  const double* values(size_t slot) const { return values_.data() + slot * W; }

  /// Checkpoints: every value.
  const std::vector<double>& state() const { return values_; }
  void restore(const std::vector<double>& s) {
    if (s.size() == values_.size()) values_ = s;
  }

 private:
  std::vector<std::string> names_;
  std::unordered_map<const Boundary<D>*, size_t> slot_;
  std::vector<double> values_;  // W per name
};

}  // namespace loam
