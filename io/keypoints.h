// SHREC sparse correspondences (.vts): one keypoint per line, "vertex_index x y z"
// (or the index alone), the index 0-based into the mesh's vertex list. Line k of
// every file of a category is the same semantic point. We trust the index, not
// the coordinates.
#pragma once
#include <string>
#include <vector>

namespace jsa {

// Throws InputError naming file and line for a bad index; indices >= vertex_count
// are rejected when vertex_count >= 0.
std::vector<int> read_keypoints(const std::string& path, long vertex_count = -1);

}  // namespace jsa
