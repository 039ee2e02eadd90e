#pragma once
// Output writer plugin interface: one frame per output time, into the run's output directory.
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace loam {

/// A file of the run that could not be written (disk full, a file size limit, the directory
/// removed or read-only): the run stops with exit code 4 and this message, naming the file and
/// the operating system's reason (strerror of errno at the failure).
struct WriteError : std::runtime_error {
  std::string file;
  WriteError(const std::string& f, const std::string& reason)
      : std::runtime_error("cannot write " + f + ": " + reason), file(f) {}
  /// The reason from errno (set by the failing call), or `fallback` if errno is 0.
  static std::string os_reason(const char* fallback = "the write failed") {
    return errno ? std::string(std::strerror(errno)) : std::string(fallback);
  }
};

/// Write `text` to `file` whole or not at all: into file.tmp, flushed and checked, then renamed
/// (summary.json, verify.csv, the XDMF index). A failure removes the .tmp and throws WriteError.
void write_file_atomically(const std::string& file, const std::string& text);

template <int D>
class Simulation;

template <int D>
class Writer {
 public:
  static constexpr const char* kind = "writer";
  virtual ~Writer() = default;
  /// `fields` are particle field handles to write besides position.
  virtual void open(const std::string& directory, Simulation<D>&,
                    const std::vector<int>& fields) = 0;
  /// Write one frame; `label` is "" for a regular frame or e.g. "failed" for the last state.
  virtual void write(Simulation<D>&, const std::string& label) = 0;
  virtual void close() {}
  /// Checkpoints: the frames written so far (a writer keeping an index needs them to go on
  /// after --resume), as text; restored after open().
  virtual std::string state() const { return ""; }
  virtual void restore_state(const std::string&) {}
};

}  // namespace loam
