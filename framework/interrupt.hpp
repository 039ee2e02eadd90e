#pragma once
// Clean interruption of a run by SIGINT or SIGTERM (docs/architecture.md "Runs that survive"):
// the first signal only records itself, and the time loop stops after the step it is in,
// writing a last frame, the history, probes and summary.json (status: interrupted; exit code
// 128 + signal: 130, 143). A second signal stops at once: the handler removes the temporary
// files of the outputs still open (history.csv.tmp and probe CSVs, and any frame, XDMF index,
// summary.json or checkpoint being written: every .tmp lives under a TemporaryFileGuard, so no
// reader takes one for data) and exits 128 + signal; the files already completed stay valid.
#include <string>
#include <utility>

namespace loam {

/// Installs the handlers for its lifetime (the time loop's) and restores the previous ones.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  /// The signal received since the guard was installed, or 0.
  static int requested();
};

/// Temporary files the second signal removes (an output being written under a .tmp name).
void register_temporary_file(const std::string& path);
void unregister_temporary_file(const std::string& path);

/// Registers a temporary file for its lifetime: create it before the file and let it end after
/// the rename (or the removal), so a second signal at any moment in between removes the file.
class TemporaryFileGuard {
 public:
  explicit TemporaryFileGuard(std::string path) : path_(std::move(path)) {
    register_temporary_file(path_);
  }
  ~TemporaryFileGuard() { unregister_temporary_file(path_); }
  TemporaryFileGuard(const TemporaryFileGuard&) = delete;
  TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;

 private:
  std::string path_;
};

/// "SIGINT", "SIGTERM" or "signal N".
std::string signal_name(int signal);

}  // namespace loam
