#pragma once
// Checkpoint files (docs/architecture.md): one HDF5 file per checkpoint holding flat,
// named arrays (doubles stored bit for bit, so a resumed run continues exactly: NaN and -0
// included), written under a temporary name, flushed to disk (fsync) and renamed.
// What a run stores in them and how it resumes: Run<D>::write_checkpoint / restore_checkpoint
// (runner.cpp).
#include <cstdint>
#include <string>
#include <vector>

#include "interrupt.hpp"

namespace loam {

/// Writes arrays into a new checkpoint; close() makes it durable and gives it its name.
class CheckpointWriter {
 public:
  /// Creates `file`.tmp (WriteError if it cannot).
  explicit CheckpointWriter(const std::string& file);
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;
  void doubles(const std::string& name, const double* v, size_t n);
  void doubles(const std::string& name, const std::vector<double>& v) {
    doubles(name, v.data(), v.size());
  }
  void scalar(const std::string& name, double v) { doubles(name, &v, 1); }
  void u32(const std::string& name, const std::vector<uint32_t>& v);
  void u16(const std::string& name, const std::vector<uint16_t>& v);
  void text(const std::string& name, const std::string& s);
  /// Close, fsync and rename to `file` (WriteError if any step fails; the .tmp is removed).
  void close();

 private:
  std::string file_, tmp_;
  TemporaryFileGuard guard_;  // a second signal removes the .tmp
  long long handle_ = -1;
  bool ok_ = true;
  void raw(const std::string& name, const void* data, size_t n, long long type);
};

/// Reads a checkpoint; every getter throws std::runtime_error naming the array if it is absent.
class CheckpointReader {
 public:
  explicit CheckpointReader(const std::string& file);  // std::runtime_error if unreadable
  ~CheckpointReader();
  CheckpointReader(const CheckpointReader&) = delete;
  CheckpointReader& operator=(const CheckpointReader&) = delete;
  bool has(const std::string& name) const;
  std::vector<double> doubles(const std::string& name) const;
  double scalar(const std::string& name) const;
  std::vector<uint32_t> u32(const std::string& name) const;
  std::vector<uint16_t> u16(const std::string& name) const;
  std::string text(const std::string& name) const;

 private:
  std::string file_;
  long long handle_ = -1;
  size_t length(const std::string& name) const;
  void raw(const std::string& name, void* data, long long type) const;
};

}  // namespace loam
