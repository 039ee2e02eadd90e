#include "element_test.hpp"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "framework/config.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "process.hpp"

namespace loam {

namespace {

const std::vector<std::string> kPaths = {"triaxial_drained", "triaxial_undrained", "oedometer",
                                         "isotropic", "simple_shear"};

using Mat3 = std::array<std::array<double, 3>, 3>;

/// How one increment is driven: prescribed velocity-gradient components, plus groups of normal
/// stress components held at a target by solving for their (shared) strain rate. A triaxial
/// test holds sigma_yy and sigma_zz with one unknown L_yy = L_zz: the axisymmetric solution,
/// unique even where the lateral split of perfectly plastic flow is not.
struct Increment {
  Mat3 L{};                                  // prescribed part (1/s)
  std::vector<std::vector<int>> controlled;  // per unknown: the normal components it drives
  std::vector<double> target;                // mean sigma_ii of each group (Pa, tension +)
};

/// The loading stages of a path: `count` increments of the same kind each.
struct LoadingStage {
  Increment inc;
  int count = 0;
};

std::vector<LoadingStage> stages_of(const ElementTest& t) {
  const double dt = t.duration / t.increments;
  const double rate = t.strain / t.increments / dt;  // strain per increment / dt
  const double s0 = -t.confining;
  Increment inc;
  if (t.path == "triaxial_drained") {
    inc.L[0][0] = -rate;  // axial compression along x; sigma_yy = sigma_zz = -p'0
    inc.controlled = {{1, 2}};
    inc.target = {s0};
  } else if (t.path == "triaxial_undrained") {
    inc.L[0][0] = -rate;  // isochoric: the lateral strains are half the axial one, opposite
    inc.L[1][1] = inc.L[2][2] = 0.5 * rate;
  } else if (t.path == "oedometer") {
    inc.L[0][0] = -rate;  // no lateral strain
  } else if (t.path == "isotropic") {
    inc.L[0][0] = inc.L[1][1] = inc.L[2][2] = -rate / 3;  // strain = volumetric strain
  } else if (t.path == "simple_shear") {
    inc.L[0][1] = rate;  // v_x = gamma_dot y: shear with spin; sigma_yy held, no lateral strain
    inc.controlled = {{1}};
    inc.target = {s0};
  } else {
    throw std::invalid_argument("unknown element-test path '" + t.path + "'");
  }
  std::vector<LoadingStage> st{{inc, t.increments}};
  const int n_unload = int(std::lround(t.unload_strain / t.strain * t.increments));
  if (n_unload > 0 && (t.path == "oedometer" || t.path == "isotropic")) {
    Increment back = inc;
    for (auto& row : back.L)
      for (double& v : row) v = -v;
    st.push_back({back, n_unload});
  }
  return st;
}

/// One 3D material point inside a minimal simulation (the material's set-up needs one).
class Point {
 public:
  Point(const Params& material, double confining) {
    Diagnostics diag;
    // A one-cell grid with a single particle; its material is replaced below.
    LoadedConfig cfg = load_config_text(
        "grid: {extent: [1, 1, 1], cell_size: 1}\n"
        "bodies:\n"
        "  - name: sample\n"
        "    generator: {type: box, min: [0, 0, 0], max: [1, 1, 1]}\n"
        "    particles_per_cell: 1\n"
        "    material: {type: linear_elastic, E: 1, nu: 0, density: 1}\n"
        "time: {end: 1}\n",
        "<element test>", {}, diag);
    if (!diag.ok()) throw std::logic_error("element test: " + diag.format());
    sim_ = std::make_unique<Simulation<3>>(cfg.params, 1, diag);
    if (!diag.ok()) throw std::logic_error("element test: " + diag.format());
    sim_->materials[0] = Registry::instance().create<Material, 3>(material);
    auto& P = sim_->sets[0].particles;
    // The mass follows the tested material's density (density-dependent models read m / V).
    P.col(P.mass)[0] = P.col(P.volume)[0] * sim_->materials[0]->density();
    sim_->materials[0]->setup(*sim_, 0, diag);
    if (!diag.ok()) throw std::runtime_error(diag.format());
    for (int c = 0; c < 6; ++c) P.col(P.stress, c)[0] = c < 3 ? -confining : 0.0;
    sim_->materials[0]->initialize(P, 0, 1);
    L_.assign(9 * kBlock, 0.0);
    batch_.begin = 0;
    batch_.count = 1;
    batch_.L = L_.data();
    batch_.particles = &P;
  }

  Particles<3>& particles() { return sim_->sets[0].particles; }
  double stress(int c) const {
    return sim_->sets[0].particles.col(sim_->sets[0].particles.stress, c)[0];
  }

  /// Every field value of the particle, to retry an increment from the same state.
  std::vector<double> save() const { return sim_->sets[0].particles.state_of(0); }
  void restore(const std::vector<double>& s) { sim_->sets[0].particles.restore_state(0, s); }

  /// One step as a scheme does it: V *= det(I + L dt), then the material's stress update.
  void step(const Mat3& L, double dt) {
    auto& P = sim_->sets[0].particles;
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        L_[size_t(i * 3 + j) * kBlock] = L[size_t(i)][size_t(j)];
        F(i, j) += L[size_t(i)][size_t(j)] * dt;
      }
    P.col(P.volume)[0] *= F.determinant();
    // F^{n+1} = (I + L dt) F^n, as the schemes do when a material requested F.
    if (const int h = P.find("deformation_gradient"); h >= 0) {
      Eigen::Matrix3d Fn;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Fn(i, j) = P.col(h, i * 3 + j)[0];
      const Eigen::Matrix3d Fnew = F * Fn;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) P.col(h, i * 3 + j)[0] = Fnew(i, j);
    }
    batch_.dt = dt;
    sim_->materials[0]->update_stress(batch_);
  }

 private:
  std::unique_ptr<Simulation<3>> sim_;
  std::vector<double> L_;
  MaterialBatch<3> batch_;
};

/// Apply one increment, solving for the controlled strain rates by Newton's method with a
/// finite-difference Jacobian. Returns "" or why it failed. `guess` carries the previous
/// increment's solution (a good first guess along a smooth path).
std::string apply_increment(Point& pt, const Increment& inc, double dt, double scale,
                            std::vector<double>& guess, Mat3& L_out) {
  const size_t m = inc.controlled.size();
  Mat3 L = inc.L;
  if (m == 0) {
    pt.step(L, dt);
    L_out = L;
    return "";
  }
  const auto saved = pt.save();
  auto residual = [&](const std::vector<double>& u, std::vector<double>& r) {
    pt.restore(saved);
    for (size_t k = 0; k < m; ++k)
      for (int i : inc.controlled[k]) L[size_t(i)][size_t(i)] = u[k];
    pt.step(L, dt);
    r.assign(m, 0.0);
    for (size_t k = 0; k < m; ++k) {
      for (int i : inc.controlled[k]) r[k] += pt.stress(i);
      r[k] = r[k] / double(inc.controlled[k].size()) - inc.target[k];
    }
  };
  double rate_scale = 0;
  for (const auto& row : inc.L)
    for (double v : row) rate_scale = std::max(rate_scale, std::fabs(v));
  const double tol = 1e-10 * scale;
  std::vector<double> u = guess, r, rp;
  residual(u, r);
  for (int it = 0; it < 50; ++it) {
    double worst = 0;
    for (double x : r) worst = std::max(worst, std::fabs(x));
    if (!std::isfinite(worst)) return "the stress is not finite";
    if (worst <= tol) {
      guess = u;
      L_out = L;
      return "";
    }
    Eigen::MatrixXd J(m, m);
    for (size_t j = 0; j < m; ++j) {
      std::vector<double> up = u;
      const double h = 1e-7 * std::max(rate_scale, std::fabs(u[j])) + 1e-300;
      up[j] += h;
      residual(up, rp);
      for (size_t i = 0; i < m; ++i) J(long(i), long(j)) = (rp[i] - r[i]) / h;
    }
    Eigen::VectorXd rv(m);
    for (size_t i = 0; i < m; ++i) rv[long(i)] = r[i];
    Eigen::VectorXd du = J.fullPivLu().solve(rv);
    if (!du.allFinite()) return "singular stiffness in the stress-controlled directions";
    for (size_t i = 0; i < m; ++i) u[i] -= du[long(i)];
    residual(u, r);
  }
  return "the confining stress could not be held (no convergence in 50 Newton iterations)";
}

}  // namespace

int ElementTestResult::column(const std::string& name) const {
  for (size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return int(i);
  return -1;
}

double ElementTestResult::at(long row, const std::string& name) const {
  const int c = column(name);
  if (c < 0) throw std::out_of_range("element test: no column '" + name + "'");
  const size_t r = row < 0 ? rows.size() - size_t(-row) : size_t(row);
  if (r >= rows.size()) throw std::out_of_range("element test: no row " + std::to_string(row));
  return rows[r][size_t(c)];
}

void ElementTestResult::write_csv(const std::string& file) const {
  std::ofstream out(file);
  for (size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << "\n";
  char buf[32];
  for (const auto& row : rows) {
    for (size_t i = 0; i < row.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%.10g", row[i]);
      out << (i ? "," : "") << buf;
    }
    out << "\n";
  }
  if (!out) throw std::runtime_error("cannot write " + file);
}

Schema element_test_schema() {
  Schema s;
  s.string_list("plugins", "shared libraries with out-of-tree plugins, loaded before validation");
  s.plugin("material", "material", "the material under test (any material plugin, 3D)").required();
  Schema t;
  t.choice("path", kPaths,
           "loading path: triaxial_drained (axial compression along x at constant lateral "
           "stress), triaxial_undrained (isochoric), oedometer (axial, no lateral strain), "
           "isotropic, simple_shear (gamma_xy at constant sigma_yy, no lateral strain)")
      .required();
  t.real("confining_stress", "Pa",
         "initial isotropic effective stress p'0 (compression positive); also the lateral "
         "stress held in triaxial_drained and the normal stress in simple_shear")
      .def("100e3")
      .non_negative();
  t.real("strain", "-",
         "target strain of the loading stage, compression positive: axial (triaxial, oedometer), "
         "volumetric (isotropic), engineering shear gamma_xy (simple_shear)")
      .required()
      .positive()
      .below(1);
  t.real("unload_strain", "-",
         "oedometer and isotropic: strain recovered after loading (0: no unloading)")
      .def("0")
      .non_negative();
  t.integer("increments", "increments of the loading stage (unloading uses the same size)")
      .def("100")
      .min(1);
  t.real("duration", "s", "time of the loading stage (rate-dependent materials)")
      .def("1")
      .positive();
  t.real("void_ratio", "-",
         "initial void ratio for the void_ratio column when the material keeps none")
      .positive();
  t.check([](const Params& p, Diagnostics& d) {
    if (p.real("unload_strain") > p.real("strain"))
      d.error(p.where("unload_strain"), p.path("unload_strain"),
              "unload_strain = " + format_number(p.real("unload_strain")) +
                  " exceeds the loading strain " + format_number(p.real("strain")));
    const std::string& path = p.text("path");
    if (p.real("unload_strain") > 0 && path != "oedometer" && path != "isotropic")
      d.error(p.where("unload_strain"), p.path("unload_strain"),
              "unloading is available for the oedometer and isotropic paths, not " + path);
  });
  s.section("test", t, "the loading path").required();
  return s;
}

ElementTest element_test_from(const Params& t) {
  ElementTest e;
  e.path = t.text("path");
  e.confining = t.real("confining_stress");
  e.strain = t.real("strain");
  e.unload_strain = t.real("unload_strain");
  e.increments = int(t.integer("increments"));
  e.duration = t.real("duration");
  if (t.has("void_ratio")) e.void_ratio = t.real("void_ratio");
  return e;
}

ElementTestResult run_element_test(const Params& material, const ElementTest& test) {
  ElementTestResult res;
  Point pt(material, test.confining);
  auto& P = pt.particles();
  res.columns = {"step",   "eps_xx", "eps_yy", "eps_zz", "eps_xy",    "eps_yz", "eps_xz",
                 "sig_xx", "sig_yy", "sig_zz", "sig_xy", "sig_yz",    "sig_xz", "p",
                 "q",      "eps_a",  "eps_v",  "eps_q",  "void_ratio"};
  // State fields the material requested (everything a scheme-free particle does not have).
  const int void_field = P.find("void_ratio");
  std::vector<std::pair<int, int>> state;  // (field, component)
  for (int f = 0; f < P.num_fields(); ++f) {
    if (f == P.position || f == P.velocity || f == P.mass || f == P.volume || f == P.stress ||
        f == void_field)
      continue;
    const FieldInfo& info = P.info(f);
    for (int c = 0; c < info.components; ++c) {
      state.push_back({f, c});
      res.columns.push_back(
          info.components == 1 ? info.name : info.name + "_" + info.component_names[size_t(c)]);
    }
  }
  const double V0 = P.col(P.volume)[0];
  Mat3 eps{};
  auto record = [&](int step) {
    std::vector<double> row{double(step)};
    for (auto [i, j] : {std::pair{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}})
      row.push_back(eps[size_t(i)][size_t(j)]);
    double s[6];
    for (int c = 0; c < 6; ++c) row.push_back(s[c] = pt.stress(c));
    const double p = -(s[0] + s[1] + s[2]) / 3;
    const double sd[3] = {s[0] + p, s[1] + p, s[2] + p};
    const double j2 = 0.5 * (sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]) + s[3] * s[3] +
                      s[4] * s[4] + s[5] * s[5];
    row.push_back(p);
    row.push_back(std::sqrt(3 * j2));
    const double ev = eps[0][0] + eps[1][1] + eps[2][2];
    double ee = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double e = eps[size_t(i)][size_t(j)] - (i == j ? ev / 3 : 0.0);
        ee += e * e;
      }
    row.push_back(-eps[0][0]);
    row.push_back(-ev);
    row.push_back(std::sqrt(2.0 / 3.0 * ee));
    row.push_back(void_field >= 0 ? P.col(void_field)[0]
                                  : (1 + test.void_ratio) * P.col(P.volume)[0] / V0 - 1);
    for (auto [f, c] : state) row.push_back(P.col(f, c)[0]);
    res.rows.push_back(std::move(row));
  };
  record(0);
  const double dt = test.duration / test.increments;
  const double scale = std::max(test.confining, 1.0);
  int step = 0;
  for (const LoadingStage& stage : stages_of(test)) {
    std::vector<double> guess(stage.inc.controlled.size(), 0.0);
    for (int i = 0; i < stage.count; ++i) {
      Mat3 L{};
      const std::string why = apply_increment(pt, stage.inc, dt, scale, guess, L);
      if (!why.empty()) {
        res.failure = "increment " + std::to_string(step + 1) + ": " + why;
        return res;
      }
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          eps[size_t(a)][size_t(b)] +=
              0.5 * (L[size_t(a)][size_t(b)] + L[size_t(b)][size_t(a)]) * dt;
      record(++step);
      for (int c = 0; c < 6; ++c)
        if (!std::isfinite(pt.stress(c))) {
          res.failure = "increment " + std::to_string(step) + ": the stress is not finite";
          return res;
        }
    }
  }
  return res;
}

ElementTestResult run_element_test(const std::string& material_yaml, const ElementTest& test) {
  Diagnostics diag;
  YAML::Node node;
  try {
    node = YAML::Load(material_yaml);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("element test material: malformed YAML: " + e.msg);
  }
  ValidationContext ctx;
  ctx.file = "<material>";
  ctx.dimension = 3;
  Params m =
      validate_plugin(node, "material", 0, "material", Location{"<material>", 1, 1}, ctx, diag);
  if (!diag.ok()) throw std::runtime_error(diag.format());
  return run_element_test(m, test);
}

ElementTestConfig load_element_test(const std::string& file,
                                    const std::vector<std::string>& overrides, Diagnostics& diag) {
  ElementTestConfig c;
  c.file = file;
  c.name = std::filesystem::path(file).stem().string();
  Params p = load_yaml_file(file, overrides, element_test_schema(), 3, diag);
  if (!diag.ok()) return c;
  c.material = p.section("material");
  c.test = element_test_from(p.section("test"));
  return c;
}

int run_element_test_file(const std::string& file, const ElementTestOptions& opt) {
  namespace fs = std::filesystem;
  Diagnostics diag;
  ElementTestConfig cfg = load_element_test(file, opt.overrides, diag);
  if (!diag.ok()) {
    fputs(diag.format().c_str(), stderr);
    return 2;
  }
  const fs::path dir = opt.out_dir.empty() ? fs::path("results") / cfg.name : fs::path(opt.out_dir);
  const fs::path csv = dir / (cfg.name + ".csv"), png = dir / (cfg.name + ".png");
  // Never overwrite results silently (the same rule as `loam run`).
  if (fs::exists(dir) && !fs::is_directory(dir)) {
    fprintf(stderr, "%s:1:1: error: output path %s is a file\n", file.c_str(), dir.c_str());
    return 2;
  }
  if (fs::exists(dir) && !fs::is_empty(dir) && !opt.overwrite) {
    fprintf(stderr,
            "%s:1:1: error: output directory %s is not empty; pass --overwrite to replace its "
            "results or --out DIR\n",
            file.c_str(), dir.c_str());
    return 2;
  }
  ElementTestResult r;
  try {
    r = run_element_test(cfg.material, cfg.test);
  } catch (const std::exception& e) {
    fprintf(stderr, "%s:1:1: error: material: %s\n", file.c_str(), e.what());
    return 2;
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  fs::remove(png, ec);  // a stale plot must not sit beside a new CSV
  r.write_csv(csv.string());
  if (!opt.quiet) {
    spdlog::info("{}: {} on {}, {} increments -> {}", cfg.name, cfg.test.path, cfg.material.type(),
                 r.rows.size() - 1, csv.string());
    spdlog::info("final: p' = {:.6g} Pa, q = {:.6g} Pa, eps_a = {:.4g}, eps_v = {:.4g}",
                 r.at(-1, "p"), r.at(-1, "q"), r.at(-1, "eps_a"), r.at(-1, "eps_v"));
  }
  std::string out;
  const std::string cmd = python_interpreter() + " " +
                          shell_quote(std::string(LOAM_TOOLS_DIR) + "/element_test_plot.py") + " " +
                          shell_quote(csv.string()) + " --out " + shell_quote(png.string());
  if (run_command(cmd, out) == 0) {
    if (!opt.quiet) spdlog::info("wrote {}", png.string());
  } else {
    spdlog::warn("{} not written (python3 with matplotlib needed): {}", png.string(), out);
  }
  if (!r.failure.empty()) {
    fprintf(stderr, "%s: element test stopped early: %s\n", file.c_str(), r.failure.c_str());
    return 3;
  }
  return 0;
}

}  // namespace loam
