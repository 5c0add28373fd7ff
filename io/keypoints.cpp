#include "io/keypoints.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/check.h"

namespace jsa {

std::vector<int> read_keypoints(const std::string& path, long vertex_count) {
  // An ifstream opens a directory without complaint and then reads nothing.
  if (std::filesystem::is_directory(path))
    throw InputError(path + ": is a directory, expected a .vts keypoint file");
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open keypoint file");
  std::vector<int> index;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream s(line);
    std::string first;
    if (!(s >> first) || first[0] == '#') continue;
    long v = -1;
    size_t used = 0;
    try {
      v = std::stol(first, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != first.size())
      throw InputError(path + ":" + std::to_string(lineno) + ": expected a vertex index, got '" +
                       first + "'");
    if (v < 0)
      throw InputError(path + ":" + std::to_string(lineno) + ": negative vertex index " + first);
    if (vertex_count >= 0 && v >= vertex_count)
      throw InputError(path + ":" + std::to_string(lineno) + ": vertex index " + first +
                       " is beyond the mesh's " + std::to_string(vertex_count) + " vertices");
    if (index.size() > 10000000) throw InputError(path + ": too many keypoints");
    index.push_back(int(v));
  }
  if (index.empty()) throw InputError(path + ": no keypoints");
  return index;
}

}  // namespace jsa
