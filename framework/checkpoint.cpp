#include "checkpoint.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>

#include "writer.hpp"

namespace loam {

CheckpointWriter::CheckpointWriter(const std::string& file)
    : file_(file), tmp_(file + ".tmp"), guard_(tmp_) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  errno = 0;
  const hid_t f = H5Fcreate(tmp_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (f < 0) throw WriteError(file_, WriteError::os_reason("HDF5 could not create it"));
  handle_ = f;
}

CheckpointWriter::~CheckpointWriter() {
  if (handle_ >= 0) {
    H5Fclose(hid_t(handle_));
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void CheckpointWriter::raw(const std::string& name, const void* data, size_t n, long long type) {
  const hsize_t dims[1] = {hsize_t(n)};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t ds = H5Dcreate2(hid_t(handle_), name.c_str(), hid_t(type), space, H5P_DEFAULT,
                              H5P_DEFAULT, H5P_DEFAULT);
  if (ds < 0 || (n > 0 && H5Dwrite(ds, hid_t(type), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0))
    ok_ = false;
  if (ds >= 0) H5Dclose(ds);
  H5Sclose(space);
}

void CheckpointWriter::doubles(const std::string& name, const double* v, size_t n) {
  raw(name, v, n, H5T_NATIVE_DOUBLE);
}
void CheckpointWriter::u32(const std::string& name, const std::vector<uint32_t>& v) {
  raw(name, v.data(), v.size(), H5T_NATIVE_UINT32);
}
void CheckpointWriter::u16(const std::string& name, const std::vector<uint16_t>& v) {
  raw(name, v.data(), v.size(), H5T_NATIVE_UINT16);
}
void CheckpointWriter::text(const std::string& name, const std::string& s) {
  raw(name, s.data(), s.size(), H5T_NATIVE_CHAR);
}

void CheckpointWriter::close() {
  errno = 0;
  const bool closed = H5Fclose(hid_t(handle_)) >= 0;
  handle_ = -1;
  std::string reason;
  if (!ok_ || !closed) reason = WriteError::os_reason("HDF5 could not write it");
  if (reason.empty()) {  // durable before it gets its name
    const int fd = ::open(tmp_.c_str(), O_RDONLY);
    if (fd < 0 || ::fsync(fd) != 0) reason = WriteError::os_reason("fsync failed");
    if (fd >= 0) ::close(fd);
  }
  std::error_code ec;
  if (!reason.empty()) {
    std::filesystem::remove(tmp_, ec);
    throw WriteError(file_, reason);
  }
  std::filesystem::rename(tmp_, file_, ec);
  if (ec) throw WriteError(file_, ec.message());
}

CheckpointReader::CheckpointReader(const std::string& file) : file_(file) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw std::runtime_error("cannot read checkpoint " + file);
  handle_ = f;
}

CheckpointReader::~CheckpointReader() {
  if (handle_ >= 0) H5Fclose(hid_t(handle_));
}

bool CheckpointReader::has(const std::string& name) const {
  return H5Lexists(hid_t(handle_), name.c_str(), H5P_DEFAULT) > 0;
}

size_t CheckpointReader::length(const std::string& name) const {
  if (!has(name)) throw std::runtime_error("checkpoint " + file_ + " has no '" + name + "'");
  const hid_t ds = H5Dopen2(hid_t(handle_), name.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(ds);
  hsize_t dims[1] = {0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  H5Sclose(space);
  H5Dclose(ds);
  return size_t(dims[0]);
}

void CheckpointReader::raw(const std::string& name, void* data, long long type) const {
  const hid_t ds = H5Dopen2(hid_t(handle_), name.c_str(), H5P_DEFAULT);
  const bool ok = ds >= 0 && H5Dread(ds, hid_t(type), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0;
  if (ds >= 0) H5Dclose(ds);
  if (!ok) throw std::runtime_error("checkpoint " + file_ + ": cannot read '" + name + "'");
}

std::vector<double> CheckpointReader::doubles(const std::string& name) const {
  std::vector<double> v(length(name));
  if (!v.empty()) raw(name, v.data(), H5T_NATIVE_DOUBLE);
  return v;
}
double CheckpointReader::scalar(const std::string& name) const {
  const auto v = doubles(name);
  if (v.size() != 1) throw std::runtime_error("checkpoint " + file_ + ": '" + name + "' size");
  return v[0];
}
std::vector<uint32_t> CheckpointReader::u32(const std::string& name) const {
  std::vector<uint32_t> v(length(name));
  if (!v.empty()) raw(name, v.data(), H5T_NATIVE_UINT32);
  return v;
}
std::vector<uint16_t> CheckpointReader::u16(const std::string& name) const {
  std::vector<uint16_t> v(length(name));
  if (!v.empty()) raw(name, v.data(), H5T_NATIVE_UINT16);
  return v;
}
std::string CheckpointReader::text(const std::string& name) const {
  std::string s(length(name), '\0');
  if (!s.empty()) raw(name, s.data(), H5T_NATIVE_CHAR);
  return s;
}

}  // namespace loam
