#pragma once
// Element tests: one material point of any material plugin driven along a laboratory path
// (triaxial drained/undrained, oedometer with unloading, isotropic compression, simple shear),
// as a geotechnical laboratory tests a soil sample. Used by `loam element-test CFG` and by the
// unit tests of every material (tests call run_element_test directly).
//
// The point is a 3D material point (Material<3>); the axial direction is x. Strain increments
// are applied as a velocity gradient L over a time step dt = duration / increments, exactly as
// the MPM schemes call the material (volume updated first by det(I + L dt), then
// update_stress). Stress-controlled components (the confining stress of a drained triaxial
// test, the normal stress of simple shear) are met by a Newton iteration on the unknown strain
// increments with a finite-difference Jacobian, to 1e-10 of the stress scale.
#include <limits>
#include <string>
#include <vector>

#include "framework/diagnostics.hpp"
#include "framework/params.hpp"

namespace loam {

/// The loading path of an element test. Signs: confining stress and strains are given
/// compression positive (the laboratory convention); the material itself is tension positive.
struct ElementTest {
  /// triaxial_drained | triaxial_undrained | oedometer | isotropic | simple_shear
  std::string path = "triaxial_drained";
  double confining = 100e3;  // Pa, initial isotropic effective stress p'0 (> 0 for soils)
  /// Target strain of the loading stage: axial strain (triaxial, oedometer), volumetric strain
  /// (isotropic), engineering shear strain gamma_xy (simple shear).
  double strain = 0.1;
  /// Oedometer and isotropic paths: strain recovered after loading (0 = no unloading stage).
  double unload_strain = 0;
  int increments = 100;  // of the loading stage (unloading uses the same increment size)
  double duration = 1;   // s, time of the loading stage (matters for rate-dependent materials)
  /// Initial void ratio used for the void_ratio column when the material keeps no "void_ratio"
  /// field (e = (1 + e0) V/V0 - 1); NaN leaves the column NaN.
  double void_ratio = std::numeric_limits<double>::quiet_NaN();
};

/// One row per increment (row 0 is the initial state). Columns, in order:
///   step, eps_xx eps_yy eps_zz eps_xy eps_yz eps_xz  (accumulated sum of sym(L) dt; tension +)
///   sig_xx sig_yy sig_zz sig_xy sig_yz sig_xz        (Cauchy stress, Pa, tension +)
///   p q          (p' = -tr(sig)/3 compression +, q = sqrt(3/2 s:s), Pa)
///   eps_a eps_v eps_q   (axial -eps_xx and volumetric -tr(eps), compression +;
///                        deviatoric sqrt(2/3 e:e))
///   void_ratio, then every state field the material requested (one column per component).
struct ElementTestResult {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  /// Empty on success; otherwise why the test stopped early (rows hold what was computed).
  std::string failure;

  /// Index of a column, or -1.
  int column(const std::string& name) const;
  /// Value of column `name` in row `row` (row -1 = last); throws std::out_of_range if unknown.
  double at(long row, const std::string& name) const;
  /// Write as CSV (header line, then rows with 10 significant digits).
  void write_csv(const std::string& file) const;
};

/// The YAML schema of an element-test file: `material:` (a material plugin) and `test:`.
Schema element_test_schema();

/// Read the `test:` section of a validated element-test file.
ElementTest element_test_from(const Params& test_section);

/// Run `test` on a validated material plugin map (validated for dimension 3).
ElementTestResult run_element_test(const Params& material, const ElementTest& test);

/// Convenience for unit tests: the material as YAML text, e.g.
/// "{type: mohr_coulomb, E: 20e6, nu: 0.3, density: 2000, c: 0, phi: 30, psi: 0}".
/// Throws std::runtime_error with the formatted diagnostics if the material map is invalid.
ElementTestResult run_element_test(const std::string& material_yaml, const ElementTest& test);

/// Validate an element-test file (with --set overrides). Errors go to diag, all at once.
struct ElementTestConfig {
  Params material;
  ElementTest test;
  std::string file, name;
};
ElementTestConfig load_element_test(const std::string& file,
                                    const std::vector<std::string>& overrides, Diagnostics& diag);

struct ElementTestOptions {
  std::vector<std::string> overrides;
  std::string out_dir;  // default results/<file stem>
  bool overwrite = false;
  bool quiet = false;
};

/// `loam element-test FILE`: validate, run, write OUT/<stem>.csv and (python3 + matplotlib)
/// OUT/<stem>.png. Returns the exit code: 0 ok, 2 bad input, 3 the test stopped early.
int run_element_test_file(const std::string& file, const ElementTestOptions& options);

}  // namespace loam
