#pragma once
// Struct-of-arrays particle storage. Every field is a set of contiguous double columns, one per
// component; a field exists only if some active plugin requested it ("model only what a scene
// needs"). Hot loops take raw column pointers once per pass.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace loam {

/// Stress components stored per dimension, Voigt order xx, yy, zz, xy, yz, xz.
/// 1D keeps the lateral normal stresses (a confined column has sigma_h != 0), 2D is plane strain.
constexpr int stress_components(int D) {
  return 3 + D * (D - 1) / 2;
}

/// Voigt index of tensor component (i, j) for i, j < 3.
constexpr int voigt_index(int i, int j) {
  if (i == j) return i;
  int a = i < j ? i : j, b = i < j ? j : i;
  return a == 0 ? (b == 1 ? 3 : 5) : 4;
}

struct FieldInfo {
  std::string name;
  int components = 1;
  std::string unit;
  std::string doc;
  std::vector<std::string> component_names;  // for output ("x", "y", "xx", ...)
  /// Per component, the value of a particle that did not exist when the field was created (a
  /// particle added by a source); empty: zero.
  std::vector<double> initial = {};
};

template <int D>
class Particles {
 public:
  static constexpr int NS = stress_components(D);
  // Handles of the fields every scheme uses; requested in the constructor.
  int position, velocity, mass, volume, stress;

  Particles() {
    position = request({"position", D, "m", "current position", axis_names()});
    velocity = request({"velocity", D, "m/s", "velocity", axis_names()});
    mass = request({"mass", 1, "kg", "mass (per unit thickness in 2D, per unit area in 1D)", {}});
    volume = request({"volume", 1, "m^D", "current volume", {}});
    stress = request({"stress", NS, "Pa", "Cauchy stress, tension positive", stress_names()});
  }

  size_t size() const { return n_; }

  /// Returns the handle of a field, creating it (zero-filled) if needed. Requests with the same
  /// name must agree on the component count. With allocate = false the field is only registered
  /// (its handle reserved, no storage) until a request allocates it.
  int request(const FieldInfo& info, bool allocate = true) {
    for (size_t f = 0; f < fields_.size(); ++f)
      if (fields_[f].info.name == info.name) {
        if (fields_[f].info.components != info.components)
          throw std::logic_error("field '" + info.name + "' requested with different sizes");
        if (allocate && !fields_[f].allocated) {
          fields_[f].allocated = true;
          for (auto& c : fields_[f].data) c.assign(n_, 0.0);
        }
        return int(f);
      }
    Field f{info, std::vector<std::vector<double>>(size_t(info.components)), allocate};
    if (allocate)
      for (auto& c : f.data) c.assign(n_, 0.0);
    fields_.push_back(std::move(f));
    return int(fields_.size() - 1);
  }
  /// Whether a field is stored in this set (registered and allocated).
  bool has(int field) const { return field >= 0 && fields_[size_t(field)].allocated; }
  int find(const std::string& name) const {
    for (size_t f = 0; f < fields_.size(); ++f)
      if (fields_[f].info.name == name) return int(f);
    return -1;
  }
  const FieldInfo& info(int field) const { return fields_[size_t(field)].info; }
  int num_fields() const { return int(fields_.size()); }

  double* col(int field, int comp = 0) { return fields_[size_t(field)].data[size_t(comp)].data(); }
  const double* col(int field, int comp = 0) const {
    return fields_[size_t(field)].data[size_t(comp)].data();
  }
  /// Pointers to all components of a field, for kernels.
  template <int N>
  std::array<double*, N> cols(int field) {
    std::array<double*, N> a{};
    for (int c = 0; c < N; ++c) a[size_t(c)] = col(field, c);
    return a;
  }

  // Integer columns: original particle id (stable across sorting), material index, body index.
  std::vector<uint32_t> id;
  std::vector<uint16_t> material;
  std::vector<uint16_t> body;

  /// Grow or shrink every column; new particles get each field's `initial` value.
  void resize(size_t n) {
    n_ = n;
    for (auto& f : fields_)
      if (f.allocated)
        for (size_t c = 0; c < f.data.size(); ++c)
          f.data[c].resize(n, c < f.info.initial.size() ? f.info.initial[c] : 0.0);
    id.resize(n);
    material.resize(n);
    body.resize(n);
  }

  /// Remove the particles with remove[i] != 0 from every column, keeping the others' order.
  void erase(const std::vector<uint8_t>& remove) {
    // Everything before the first removed particle stays where it is.
    size_t first = 0;
    while (first < n_ && !remove[first]) ++first;
    auto compact = [&](auto& v) {
      size_t k = first;
      for (size_t i = first; i < n_; ++i)
        if (!remove[i]) v[k++] = v[i];
      v.resize(k);
      return k;
    };
    size_t kept = n_;
    for (auto& f : fields_)
      if (f.allocated)
        for (auto& c : f.data) kept = compact(c);
    compact(id);
    compact(material);
    kept = compact(body);
    n_ = kept;
  }

  /// Append the particles of `src` (a set's inactive body, kept aside): fields are matched by
  /// name; a field `src` does not hold gets its initial value.
  void append(const Particles& src) {
    const size_t n0 = n_;
    resize(n0 + src.n_);
    for (auto& f : fields_) {
      const int h = src.find(f.info.name);
      if (!f.allocated || !src.has(h)) continue;
      for (size_t c = 0; c < f.data.size(); ++c)
        std::copy(src.fields_[size_t(h)].data[c].begin(), src.fields_[size_t(h)].data[c].end(),
                  f.data[c].begin() + long(n0));
    }
    std::copy(src.id.begin(), src.id.end(), id.begin() + long(n0));
    std::copy(src.material.begin(), src.material.end(), material.begin() + long(n0));
    std::copy(src.body.begin(), src.body.end(), body.begin() + long(n0));
  }

  /// Copy every field into `dst` (the last-good snapshot): the columns in parallel once dst has
  /// this layout (after the first copy), a plain copy otherwise.
  void copy_to(Particles& dst, int threads) const {
    bool same = dst.fields_.size() == fields_.size();
    for (size_t f = 0; same && f < fields_.size(); ++f)
      same = dst.fields_[f].allocated == fields_[f].allocated &&
             dst.fields_[f].data.size() == fields_[f].data.size();
    if (!same) {
      dst = *this;
      return;
    }
    std::vector<std::pair<const std::vector<double>*, std::vector<double>*>> columns;
    for (size_t f = 0; f < fields_.size(); ++f)
      if (fields_[f].allocated)
        for (size_t c = 0; c < fields_[f].data.size(); ++c)
          columns.emplace_back(&fields_[f].data[c], &dst.fields_[f].data[c]);
    const int nc = int(columns.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int k = 0; k < nc; ++k) *columns[size_t(k)].second = *columns[size_t(k)].first;
    dst.id = id;
    dst.material = material;
    dst.body = body;
    dst.n_ = n_;
    for (size_t f = 0; f < fields_.size(); ++f) dst.fields_[f].info = fields_[f].info;
  }

  /// Reorder every column so that new[i] = old[order[i]] (after sorting by cell).
  void permute(const std::vector<uint32_t>& order, int threads = 1) {
    // Columns are independent: permute them in parallel, one scratch column per thread.
    std::vector<std::vector<double>*> columns;
    for (auto& f : fields_)
      if (f.allocated)
        for (auto& c : f.data) columns.push_back(&c);
    scratch_.resize(size_t(threads));
    const int nc = int(columns.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int k = 0; k < nc; ++k) {
      std::vector<double>& tmp = scratch_[size_t(omp_get_thread_num())];
      std::vector<double>& c = *columns[size_t(k)];
      tmp.resize(n_);
      for (size_t i = 0; i < n_; ++i) tmp[i] = c[order[i]];
      c.swap(tmp);
    }
    permute_int(id, order);
    permute_int(material, order);
    permute_int(body, order);
  }

  /// The deformation gradient F (row-major D x D, F_ij at component i*D + j), created as the
  /// identity on first request. Schemes update it with F <- (I + L dt) F when it exists, so it
  /// costs nothing unless a plugin (CPDI, a hyperelastic material, ...) asks for it.
  int request_deformation_gradient() {
    const bool is_new = !has(find("deformation_gradient"));
    const int h = request(deformation_gradient_info());
    if (is_new)
      for (int i = 0; i < D; ++i)
        for (size_t p = 0; p < n_; ++p) col(h, i * D + i)[p] = 1.0;
    return h;
  }

  static FieldInfo deformation_gradient_info() {
    std::vector<std::string> names;
    std::vector<double> identity(D * D, 0.0);
    for (int i = 0; i < D; ++i) {
      identity[size_t(i * D + i)] = 1.0;
      for (int j = 0; j < D; ++j) names.push_back(std::string(1, "xyz"[i]) + "xyz"[j]);
    }
    return {"deformation_gradient", D * D, "-", "deformation gradient F", names, identity};
  }

  /// Every field value of particle i (all components, field order), e.g. to retry a material
  /// update from the same state; restore_state writes such a snapshot back.
  std::vector<double> state_of(size_t i) const {
    std::vector<double> s;
    for (const auto& f : fields_)
      if (f.allocated)
        for (const auto& c : f.data) s.push_back(c[i]);
    return s;
  }
  void restore_state(size_t i, const std::vector<double>& s) {
    size_t k = 0;
    for (auto& f : fields_)
      if (f.allocated)
        for (auto& c : f.data) c[i] = s[k++];
  }

  size_t bytes_per_particle() const {
    size_t b = sizeof(uint32_t) + 2 * sizeof(uint16_t);
    for (const auto& f : fields_)
      if (f.allocated) b += sizeof(double) * size_t(f.info.components);
    return b;
  }

  static std::vector<std::string> axis_names() {
    std::vector<std::string> n{"x", "y", "z"};
    n.resize(D);
    return n;
  }
  static std::vector<std::string> stress_names() {
    std::vector<std::string> n{"xx", "yy", "zz", "xy", "yz", "xz"};
    n.resize(NS);
    return n;
  }

 private:
  struct Field {
    FieldInfo info;
    std::vector<std::vector<double>> data;
    bool allocated = true;
  };
  template <class T>
  void permute_int(std::vector<T>& v, const std::vector<uint32_t>& order) {
    std::vector<T> out(n_);
    for (size_t i = 0; i < n_; ++i) out[i] = v[order[i]];
    v.swap(out);
  }
  size_t n_ = 0;
  std::vector<Field> fields_;
  std::vector<std::vector<double>> scratch_;  // per thread
};

}  // namespace loam
