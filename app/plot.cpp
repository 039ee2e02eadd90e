#include "plot.hpp"

#include <cstdio>
#include <filesystem>

#include "process.hpp"

namespace loam {

int run_plot(const PlotOptions& opt) {
  std::string cmd = python_interpreter() + " " +
                    shell_quote(std::string(LOAM_TOOLS_DIR) + "/loam_plot.py") + " " +
                    shell_quote(opt.run_dir) + " --frame " + std::to_string(opt.frame);
  if (!opt.field.empty()) cmd += " --field " + shell_quote(opt.field);
  if (!opt.set.empty()) cmd += " --set " + shell_quote(opt.set);
  if (!opt.out.empty()) cmd += " --out " + shell_quote(opt.out);
  std::string output;
  const int code = run_command(cmd, output);
  if (code == 0) {
    std::printf("wrote %s", output.c_str());
    return 0;
  }
  if (code == 127 || code < 0) {
    std::fprintf(stderr,
                 "loam plot: error: cannot start %s (install python3, python3-h5py and "
                 "python3-matplotlib: tools/setup.sh does)\n%s",
                 python_interpreter().c_str(), output.c_str());
    return 1;
  }
  std::fputs(output.c_str(), stderr);
  return code == 2 ? 2 : 1;
}

}  // namespace loam
