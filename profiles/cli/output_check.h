#pragma once
/// Output files are checked before a command runs, so an unwritable path fails at once instead
/// of after a long run whose results would be lost.
#include <fstream>
#include <stdexcept>
#include <string>

namespace bw::cli {

/// Throws std::runtime_error("<option>: cannot write <path>") unless `path` opens for writing.
/// It is opened to append (an existing file keeps its content until the run rewrites it; a
/// missing one is created empty). An empty path (the option not given) passes.
inline void requireWritable(const std::string& path, const char* option) {
  if (path.empty()) return;
  if (!std::ofstream(path, std::ios::app)) throw std::runtime_error(std::string(option) + ": cannot write " + path);
}

}  // namespace bw::cli
