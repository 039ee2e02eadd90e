#include "writer.hpp"

#include <filesystem>
#include <fstream>

#include "interrupt.hpp"

namespace loam {

void write_file_atomically(const std::string& file, const std::string& text) {
  const std::string tmp = file + ".tmp";
  const TemporaryFileGuard guard(tmp);  // a second signal removes it
  errno = 0;
  bool written;
  {
    std::ofstream out(tmp);
    out << text;
    out.flush();
    written = bool(out);
  }
  std::error_code ec;
  if (!written) {
    const std::string reason = WriteError::os_reason();
    std::filesystem::remove(tmp, ec);
    throw WriteError(file, reason);
  }
  std::filesystem::rename(tmp, file, ec);
  if (ec) throw WriteError(file, ec.message());
}

}  // namespace loam
