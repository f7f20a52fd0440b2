#include "collision/content/byte_reader.h"

#include <filesystem>
#include <system_error>

namespace bw {

void requireRegularFile(const std::string& path, const std::string& expected) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) failFile(path, "file", "does not exist (expected " + expected + ")");
  if (std::filesystem::is_directory(st)) failFile(path, "file", "is a directory, expected " + expected);
  if (!std::filesystem::is_regular_file(st)) failFile(path, "file", "is not a regular file, expected " + expected);
}

}  // namespace bw
