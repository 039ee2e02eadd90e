#pragma once
// Running helper programs (the Python plot scripts, `loam run` for each variant of a sweep).
#include <string>

namespace loam {

/// Run a shell command, capturing stdout and stderr; returns its exit code (128 + signal if
/// it was killed, -1 if it could not start).
int run_command(const std::string& cmd, std::string& output);

/// Quote a string for /bin/sh.
std::string shell_quote(const std::string& s);

/// Debian's interpreter (which has python3-matplotlib from tools/setup.sh) if present, else the
/// python3 on PATH (a pyenv python3 may lack matplotlib).
std::string python_interpreter();

}  // namespace loam
