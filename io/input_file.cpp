// Opening a user's file and shaping the one-line errors about it.
#include "io/input_file.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "engine/check.h"

namespace jsa {

void input_error(const std::string& path, const std::string& where, const std::string& what) {
  std::string message = path;
  if (!where.empty()) message += ":" + where;
  throw InputError(message + ": " + what);
}

std::string line_label(std::int64_t line) { return "line " + std::to_string(line); }

void check_regular_file(const std::string& path) {
  struct stat info;
  if (::stat(path.c_str(), &info) != 0)
    input_error(path, "", std::string("cannot open (") + std::strerror(errno) + ")");
  if (S_ISDIR(info.st_mode)) input_error(path, "", "is a directory, expected a shape file");
}

std::string read_input_file(const std::string& path) {
  check_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) input_error(path, "", "cannot open for reading");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  std::string content = bytes.str();
  if (content.empty()) input_error(path, "", "file is empty");
  return content;
}

void reject_binary_bytes(const std::string& path, const std::string& bytes) {
  const auto nul = bytes.find('\0');
  if (nul == std::string::npos) return;
  const auto line = 1 + std::count(bytes.begin(), bytes.begin() + nul, '\n');
  input_error(path, line_label(line),
              "binary data (NUL byte at offset " + std::to_string(nul) +
                  ") in a text format; is the extension right?");
}

std::string extension_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace jsa
