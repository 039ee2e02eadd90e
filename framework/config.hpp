#pragma once
// Loading a run configuration: YAML file, --set overrides, out-of-tree plugin libraries, and
// validation of the whole tree against the schema (every error at once, before any work).
#include <string>
#include <vector>

#include "diagnostics.hpp"
#include "params.hpp"

namespace loam {

/// The schema of a run file (top level). Documented by `loam plugins --config`.
Schema config_schema();

struct LoadedConfig {
  Params params;
  int dimension = 0;
  std::string file;
  std::string name;  // file stem, for the default output directory
  /// The validation's plausibility warnings (ParamSpec::plausible), before accept_warnings:
  /// the run adds its own (the step budget) and prints them all (run_warnings).
  std::vector<Diagnostic> warnings;
};

/// The warnings of a run, `found` and the config's, less those its accept_warnings lists, as
/// located lines; a listed key without a warning is itself a warning (a typo in the path, or a
/// value that is plausible after all).
std::string run_warnings(const LoadedConfig& config, const Diagnostics& found);

/// Read, override, validate. On any error, diag holds every message and the result is unusable.
LoadedConfig load_config(const std::string& file, const std::vector<std::string>& overrides,
                         Diagnostics& diag);
/// Same, from YAML text (used by tests and `loam bench`).
LoadedConfig load_config_text(const std::string& text, const std::string& label,
                              const std::vector<std::string>& overrides, Diagnostics& diag);

/// Read any YAML input file (e.g. an element test), apply --set overrides, load its `plugins:`
/// libraries and validate it against `schema` for a fixed dimension.
Params load_yaml_file(const std::string& file, const std::vector<std::string>& overrides,
                      const Schema& schema, int dimension, Diagnostics& diag);

}  // namespace loam
