// Temp file + fsync + rename: the POSIX recipe for an all-or-nothing write.
#include "io/atomic_write.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <vector>

#include "io/input_file.h"

namespace jsa {
namespace {

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

void fsync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

// Creates the temporary file (mode 0644, or the mode of the file it replaces).
std::string create_temporary(const std::string& path) {
  const std::string directory = directory_of(path);
  struct stat info;
  if (::stat(directory.c_str(), &info) != 0 || !S_ISDIR(info.st_mode))
    input_error(path, "", "cannot write: directory '" + directory + "' does not exist");
  std::string name = path + ".tmp.XXXXXX";
  std::vector<char> pattern(name.begin(), name.end());
  pattern.push_back('\0');
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0)
    input_error(path, "",
                "cannot write in directory '" + directory + "' (" + std::strerror(errno) + ")");
  mode_t mode = 0644;
  if (::stat(path.c_str(), &info) == 0) mode = info.st_mode & 07777;
  ::fchmod(fd, mode);
  ::close(fd);
  return std::string(pattern.data());
}

}  // namespace

void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write) {
  struct stat info;
  if (::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode))
    input_error(path, "", "cannot write: is a directory");
  const std::string temporary = create_temporary(path);
  try {
    {
      std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
      if (!out) input_error(path, "", "cannot open temporary file '" + temporary + "'");
      write(out);
      out.flush();
      if (!out) input_error(path, "", "write failed (disk full?)");
    }
    fsync_path(temporary, O_RDONLY);
    if (std::rename(temporary.c_str(), path.c_str()) != 0)
      input_error(path, "", std::string("cannot replace the file (") + std::strerror(errno) + ")");
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
  fsync_path(directory_of(path), O_RDONLY | O_DIRECTORY);
}

}  // namespace jsa
