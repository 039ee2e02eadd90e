// The `loam` command line: run, check, element-test, plot, plugins, schema, compare, bench.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>

#include "bench.hpp"
#include "compare.hpp"
#include "docs.hpp"
#include "element_test.hpp"
#include "framework/config.hpp"
#include "framework/launch.hpp"
#include "framework/runner.hpp"
#include "plot.hpp"
#ifdef LOAM_WITH_MPI
#include "framework/mpi/mpi_ranks.hpp"
#endif

namespace {

/// Every command's options and its CLI11 subcommand (set when given).
struct Commands {
  loam::RunOptions run_opt;
  std::string run_file;
  std::string check_file;
  std::vector<std::string> check_sets;
  loam::ElementTestOptions et_opt;
  std::string et_file;
  loam::PlotOptions plot_opt;
  std::string kind;
  bool markdown = false;
  bool schema_md = false;
  loam::CompareOptions cmp_opt;
  loam::BenchOptions bench_opt;
  CLI::App *run = nullptr, *check = nullptr, *element = nullptr, *plot = nullptr,
           *plugins = nullptr, *schema = nullptr, *compare = nullptr, *bench = nullptr;
};

/// run, check, element-test and plot: the commands on one run file or run.
void define_run_commands(CLI::App& app, Commands& c) {
  c.run = app.add_subcommand("run", "validate and run a scene");
  c.run->add_option("config", c.run_file, "run file (YAML)")->required();
  c.run->add_option("--set", c.run_opt.overrides, "override a key: path.to.key=value (repeatable)")
      ->allow_extra_args(false);
  c.run->add_option("--out", c.run_opt.out_dir, "output directory (default results/<config name>)");
  c.run->add_option("--resume", c.run_opt.resume,
                    "continue from a checkpoint: the run's output directory (its newest valid "
                    "checkpoint_*.h5) or one checkpoint file; the output goes on there");
  c.run->add_flag("--overwrite", c.run_opt.overwrite,
                  "replace the results in a non-empty output directory");
  c.run
      ->add_option("--threads", c.run_opt.threads,
                   "OpenMP threads (default: OMP_NUM_THREADS, else all cores within a container's "
                   "CPU quota)")
      ->check(CLI::Range(1, 1024));
  c.run->add_flag("--quiet", c.run_opt.quiet, "no progress lines");
  c.run->add_flag("--profile", c.run_opt.profile,
                  "time each phase of the step (summary.json: profile_seconds; under mpirun also "
                  "profile_seconds_by_rank)");

  c.check = app.add_subcommand("check", "validate a run file without running it");
  c.check->add_option("config", c.check_file, "run file (YAML)")->required();
  c.check->add_option("--set", c.check_sets, "override a key: path.to.key=value")
      ->allow_extra_args(false);

  c.element = app.add_subcommand(
      "element-test", "drive one material point along a laboratory path; write CSV and PNG");
  c.element->add_option("config", c.et_file, "element-test file (YAML: material, test)")
      ->required();
  c.element->add_option("--set", c.et_opt.overrides, "override a key: path.to.key=value")
      ->allow_extra_args(false);
  c.element->add_option("--out", c.et_opt.out_dir,
                        "output directory (default results/<file name>)");
  c.element->add_flag("--overwrite", c.et_opt.overwrite, "replace the results in the directory");
  c.element->add_flag("--quiet", c.et_opt.quiet, "no progress lines");

  c.plot = app.add_subcommand(
      "plot", "draw a run: a frame's particles coloured by a field, its history and verify series");
  c.plot->add_option("run", c.plot_opt.run_dir, "the run's output directory")->required();
  c.plot->add_option("--field", c.plot_opt.field,
                     "particle field (default: plastic_strain_eq, pore_pressure, displacement, "
                     "velocity or stress, the first the frame has); NAME:K one component");
  c.plot->add_option("--frame", c.plot_opt.frame,
                     "frame index (0 the first; default -1, the last)");
  c.plot->add_option("--set", c.plot_opt.set, "one particle set (default: all)");
  c.plot->add_option("--out", c.plot_opt.out, "PNG file (default RUN/plot.png)");
}

/// plugins, schema, compare and bench.
void define_tool_commands(CLI::App& app, Commands& c) {
  c.plugins = app.add_subcommand("plugins", "list plugins with their parameters");
  c.plugins->add_option("kind", c.kind, "only this kind (shape_function, material, ...)");
  c.plugins->add_flag("--markdown", c.markdown, "Markdown output");

  c.schema = app.add_subcommand("schema", "list the keys of a run file");
  c.schema->add_flag("--markdown", c.schema_md, "Markdown output");

  c.compare =
      app.add_subcommand("compare", "run a sweep of overrides; write compare.csv and pareto.png");
  c.compare
      ->add_option("sweep", c.cmp_opt.sweep_file,
                   "sweep file (YAML: base, axes, set, metrics, metric, series, threads)")
      ->required();
  c.compare->add_option("--out", c.cmp_opt.out_dir,
                        "output directory (default results/<sweep name>)");
  c.compare->add_option("--threads", c.cmp_opt.threads, "threads per variant")
      ->check(CLI::Range(1, 1024));
  c.compare->add_flag("--quiet", c.cmp_opt.quiet, "no progress lines");

  c.bench = app.add_subcommand("bench", "throughput benchmark on fixed scenes");
  c.bench->add_flag("--json", c.bench_opt.json, "one JSON object per run, nothing else");
  c.bench->add_option("--steps", c.bench_opt.steps, "timed steps per run")
      ->check(CLI::Range(1, 1000000));
  c.bench->add_option("--threads", c.bench_opt.threads, "thread counts to run (default 1 2)");
  c.bench->add_option("--scenes", c.bench_opt.scenes,
                      "scenes (default: elastic_block_2d elastic_block_3d; two_phase_ prefix: "
                      "the same block saturated, two_phase_single_point scheme; double_point_ "
                      "prefix: saturated with a liquid point beside every solid point, "
                      "two_phase_double_point scheme; apic_ and tpic_ prefixes: the scene with "
                      "transfer: apic or tpic (e.g. apic_two_phase_elastic_block_2d; linear tents "
                      "need --update usf); fbar_ prefix: the single-phase scene with volumetric: "
                      "fbar; _two_sets suffix: the block over two sets)");
  c.bench->add_option("--update", c.bench_opt.update, "musl, usl or usf");
  c.bench->add_option("--shape-functions", c.bench_opt.shapes,
                      "shape functions (default linear; all: every one)");
  c.bench->add_option("--repeat", c.bench_opt.repeat, "repeat each run and report the median")
      ->check(CLI::Range(1, 20));
  c.bench->add_flag("--profile", c.bench_opt.profile, "print where the step's time goes");
  c.bench->add_option("--materials", c.bench_opt.materials,
                      "instead of scenes: stress-update cost per particle of each material "
                      "(all, or one material name)");
}

/// Under mpirun -np N > 1: the refusal of a command that cannot run on ranks, before it writes
/// anything ("" when it can run).
std::string refusal_under_mpirun(const Commands& c) {
#ifdef LOAM_WITH_MPI
  const bool mpi_run = true;
#else
  const bool mpi_run = false;
#endif
  for (auto* cmd : {c.run, c.element, c.bench, c.compare})
    if (*cmd && !(cmd == c.run && mpi_run)) {
      const std::string refusal = loam::refuse_mpi_launch(
          cmd->get_name(), cmd == c.run ? "Build loam with MPI (tools/setup.sh --mpi) to run it "
                                          "on ranks, or run it without mpirun"
                                        : "Run it without mpirun");
      if (!refusal.empty()) return refusal;
    }
  return "";
}

/// `loam run`: serially, or under mpirun split over the ranks.
int run_scene(Commands& c, int argc, char** argv) {
  if (c.run_opt.quiet) spdlog::set_level(spdlog::level::warn);
#ifdef LOAM_WITH_MPI
  if (loam::mpi_launch_size() > 0) {  // mpirun: the run is split over its ranks
    try {
      loam::MpiSession mpi(argc, argv);
      if (mpi.rank() != 0) {
        c.run_opt.report = false;
        spdlog::set_level(spdlog::level::off);
      }
      return loam::run_file(c.run_file, c.run_opt);
    } catch (const std::exception& e) {
      fprintf(stderr, "loam: error: %s\n", e.what());
      loam::mpi_abort(1);
    }
  }
#endif
  return loam::run_file(c.run_file, c.run_opt);
}

/// `loam check`: validate only; every error at once, exit 2.
int check_command(const Commands& c) {
  loam::Diagnostics diag;
  auto cfg = loam::load_config(c.check_file, c.check_sets, diag);
  if (!diag.ok()) {
    fputs(diag.format().c_str(), stderr);
    return 2;
  }
  auto r = loam::check_config(cfg);
  if (r.exit_code) {
    fputs(r.message.c_str(), stderr);
    return r.exit_code;
  }
  fputs(r.warnings.c_str(), stderr);
  std::printf("%s: ok (%dD, %zu particles, %zu cells)\n", c.check_file.c_str(), cfg.dimension,
              r.summary["particles"].get<size_t>(), r.summary["cells"].get<size_t>());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"loam: explicit Material Point Method for geomechanics"};
  app.require_subcommand(1);
  app.set_version_flag("--version", loam::loam_version() + " (" + loam::git_commit() + ")");
  Commands c;
  define_run_commands(app, c);
  define_tool_commands(app, c);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  spdlog::set_pattern("[%H:%M:%S] %^%l%$ %v");
  if (const std::string refusal = refusal_under_mpirun(c); !refusal.empty()) {
    fputs(refusal.c_str(), stderr);
    return 2;
  }
  if (*c.run) return run_scene(c, argc, argv);
  if (*c.check) return check_command(c);
  if (*c.plugins) {
    std::string out;
    bool ok = loam::print_plugins(c.kind, c.markdown, out);
    fputs(out.c_str(), ok ? stdout : stderr);
    return ok ? 0 : 2;
  }
  if (*c.schema) {
    fputs(loam::print_config_schema(c.schema_md).c_str(), stdout);
    return 0;
  }
  if (*c.element) {
    if (c.et_opt.quiet) spdlog::set_level(spdlog::level::warn);
    return loam::run_element_test_file(c.et_file, c.et_opt);
  }
  if (*c.plot) return loam::run_plot(c.plot_opt);
  if (*c.bench) return loam::run_bench(c.bench_opt);
  if (*c.compare) return loam::run_compare(c.cmp_opt);
  return 0;
}
