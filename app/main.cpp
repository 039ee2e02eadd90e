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

int main(int argc, char** argv) {
  CLI::App app{"loam: explicit Material Point Method for geomechanics"};
  app.require_subcommand(1);
  app.set_version_flag("--version", loam::loam_version() + " (" + loam::git_commit() + ")");

  loam::RunOptions run_opt;
  std::string run_file;
  auto* run = app.add_subcommand("run", "validate and run a scene");
  run->add_option("config", run_file, "run file (YAML)")->required();
  run->add_option("--set", run_opt.overrides, "override a key: path.to.key=value (repeatable)")
      ->allow_extra_args(false);
  run->add_option("--out", run_opt.out_dir, "output directory (default results/<config name>)");
  run->add_option("--resume", run_opt.resume,
                  "continue from a checkpoint: the run's output directory (its newest valid "
                  "checkpoint_*.h5) or one checkpoint file; the output goes on there");
  run->add_flag("--overwrite", run_opt.overwrite,
                "replace the results in a non-empty output directory");
  run->add_option(
         "--threads", run_opt.threads,
         "OpenMP threads (default: OMP_NUM_THREADS, else all cores within a container's CPU quota)")
      ->check(CLI::Range(1, 1024));
  run->add_flag("--quiet", run_opt.quiet, "no progress lines");
  run->add_flag("--profile", run_opt.profile,
                "time each phase of the step (summary.json: profile_seconds; under mpirun also "
                "profile_seconds_by_rank)");

  std::string check_file;
  std::vector<std::string> check_sets;
  auto* check = app.add_subcommand("check", "validate a run file without running it");
  check->add_option("config", check_file, "run file (YAML)")->required();
  check->add_option("--set", check_sets, "override a key: path.to.key=value")
      ->allow_extra_args(false);

  loam::ElementTestOptions et_opt;
  std::string et_file;
  auto* element = app.add_subcommand(
      "element-test", "drive one material point along a laboratory path; write CSV and PNG");
  element->add_option("config", et_file, "element-test file (YAML: material, test)")->required();
  element->add_option("--set", et_opt.overrides, "override a key: path.to.key=value")
      ->allow_extra_args(false);
  element->add_option("--out", et_opt.out_dir, "output directory (default results/<file name>)");
  element->add_flag("--overwrite", et_opt.overwrite, "replace the results in the directory");
  element->add_flag("--quiet", et_opt.quiet, "no progress lines");

  loam::PlotOptions plot_opt;
  auto* plot = app.add_subcommand(
      "plot", "draw a run: a frame's particles coloured by a field, its history and verify series");
  plot->add_option("run", plot_opt.run_dir, "the run's output directory")->required();
  plot->add_option("--field", plot_opt.field,
                   "particle field (default: plastic_strain_eq, pore_pressure, displacement, "
                   "velocity or stress, the first the frame has); NAME:K one component");
  plot->add_option("--frame", plot_opt.frame, "frame index (0 the first; default -1, the last)");
  plot->add_option("--set", plot_opt.set, "one particle set (default: all)");
  plot->add_option("--out", plot_opt.out, "PNG file (default RUN/plot.png)");

  std::string kind;
  bool markdown = false;
  auto* plugins = app.add_subcommand("plugins", "list plugins with their parameters");
  plugins->add_option("kind", kind, "only this kind (shape_function, material, ...)");
  plugins->add_flag("--markdown", markdown, "Markdown output");

  bool schema_md = false;
  auto* schema = app.add_subcommand("schema", "list the keys of a run file");
  schema->add_flag("--markdown", schema_md, "Markdown output");

  loam::CompareOptions cmp_opt;
  auto* compare =
      app.add_subcommand("compare", "run a sweep of overrides; write compare.csv and pareto.png");
  compare
      ->add_option("sweep", cmp_opt.sweep_file,
                   "sweep file (YAML: base, axes, set, metrics, metric, series, threads)")
      ->required();
  compare->add_option("--out", cmp_opt.out_dir, "output directory (default results/<sweep name>)");
  compare->add_option("--threads", cmp_opt.threads, "threads per variant")
      ->check(CLI::Range(1, 1024));
  compare->add_flag("--quiet", cmp_opt.quiet, "no progress lines");

  loam::BenchOptions bench_opt;
  auto* bench = app.add_subcommand("bench", "throughput benchmark on fixed scenes");
  bench->add_flag("--json", bench_opt.json, "one JSON object per run, nothing else");
  bench->add_option("--steps", bench_opt.steps, "timed steps per run")
      ->check(CLI::Range(1, 1000000));
  bench->add_option("--threads", bench_opt.threads, "thread counts to run (default 1 2)");
  bench->add_option("--scenes", bench_opt.scenes,
                    "scenes (default: elastic_block_2d elastic_block_3d; two_phase_ prefix: "
                    "the same block saturated, two_phase_single_point scheme; double_point_ "
                    "prefix: saturated with a liquid point beside every solid point, "
                    "two_phase_double_point scheme; apic_ and tpic_ prefixes: the scene with "
                    "transfer: apic or tpic (e.g. apic_two_phase_elastic_block_2d; linear tents "
                    "need --update usf); fbar_ prefix: the single-phase scene with volumetric: "
                    "fbar; _two_sets suffix: the block over two sets)");
  bench->add_option("--update", bench_opt.update, "musl, usl or usf");
  bench->add_option("--shape-functions", bench_opt.shapes,
                    "shape functions (default linear; all: every one)");
  bench->add_option("--repeat", bench_opt.repeat, "repeat each run and report the median")
      ->check(CLI::Range(1, 20));
  bench->add_flag("--profile", bench_opt.profile, "print where the step's time goes");
  bench->add_option("--materials", bench_opt.materials,
                    "instead of scenes: stress-update cost per particle of each material "
                    "(all, or one material name)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  spdlog::set_pattern("[%H:%M:%S] %^%l%$ %v");

  // Under mpirun -np N > 1: refuse the commands that cannot run on ranks, before they write
  // anything.
#ifdef LOAM_WITH_MPI
  const bool mpi_run = true;
#else
  const bool mpi_run = false;
#endif
  for (auto* cmd : {run, element, bench, compare})
    if (*cmd && !(cmd == run && mpi_run)) {
      const std::string refusal = loam::refuse_mpi_launch(
          cmd->get_name(), cmd == run ? "Build loam with MPI (tools/setup.sh --mpi) to run it "
                                        "on ranks, or run it without mpirun"
                                      : "Run it without mpirun");
      if (!refusal.empty()) {
        fputs(refusal.c_str(), stderr);
        return 2;
      }
    }

  if (*run) {
    if (run_opt.quiet) spdlog::set_level(spdlog::level::warn);
#ifdef LOAM_WITH_MPI
    if (loam::mpi_launch_size() > 0) {  // mpirun: the run is split over its ranks
      try {
        loam::MpiSession mpi(argc, argv);
        if (mpi.rank() != 0) {
          run_opt.report = false;
          spdlog::set_level(spdlog::level::off);
        }
        return loam::run_file(run_file, run_opt);
      } catch (const std::exception& e) {
        fprintf(stderr, "loam: error: %s\n", e.what());
        loam::mpi_abort(1);
      }
    }
#endif
    return loam::run_file(run_file, run_opt);
  }
  if (*check) {
    loam::Diagnostics diag;
    auto cfg = loam::load_config(check_file, check_sets, diag);
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
    std::printf("%s: ok (%dD, %zu particles, %zu cells)\n", check_file.c_str(), cfg.dimension,
                r.summary["particles"].get<size_t>(), r.summary["cells"].get<size_t>());
    return 0;
  }
  if (*plugins) {
    std::string out;
    bool ok = loam::print_plugins(kind, markdown, out);
    fputs(out.c_str(), ok ? stdout : stderr);
    return ok ? 0 : 2;
  }
  if (*schema) {
    fputs(loam::print_config_schema(schema_md).c_str(), stdout);
    return 0;
  }
  if (*element) {
    if (et_opt.quiet) spdlog::set_level(spdlog::level::warn);
    return loam::run_element_test_file(et_file, et_opt);
  }
  if (*plot) return loam::run_plot(plot_opt);
  if (*bench) return loam::run_bench(bench_opt);
  if (*compare) return loam::run_compare(cmp_opt);
  return 0;
}
