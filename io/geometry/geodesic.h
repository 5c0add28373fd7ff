// Geodesic distances on a triangle mesh, approximated by shortest paths along
// its edges (Dijkstra). Used where a collection must tell parts apart whatever
// the pose: distances measured along the surface do not change when a limb
// bends (io/geometry/intrinsic_descriptors.h, model/tool/geodesic_refinement.h).
#pragma once
#include <utility>
#include <vector>

#include "io/geometry/mesh.h"

namespace jsa {

// The graph as compressed rows: the neighbours of v are
// neighbour[start[v] .. start[v + 1]), with the lengths of the edges.
struct EdgeGraph {
  std::vector<int> start, neighbour;
  std::vector<double> length;
  Index size() const { return Index(start.size()) - 1; }
};

// The graph of `nodes` joined by `edges` (each pair once or twice, any order),
// edges as long as the segments between their nodes.
EdgeGraph edge_graph(const Block<double>& nodes, const std::vector<std::pair<int, int>>& edges);

// The edges of a triangle mesh's faces, each as (lower, higher) index.
std::vector<std::pair<int, int>> face_edges(const Mesh& mesh);

// The total area of a triangle mesh's faces.
double surface_area(const Mesh& mesh);

// d[v]: the shortest path from `source` to v along g (infinity out of reach).
void distances_from(const EdgeGraph& g, int source, std::vector<double>& d);

// n nodes by farthest-point sampling along g: the first is the node farthest
// from node 0, each next the node farthest from all chosen so far (unreached
// nodes first, so every connected component gets one); ties: the lowest index.
// distances[k] receives the shortest paths from the k-th chosen node.
std::vector<int> farthest_nodes(const EdgeGraph& g, int n,
                                std::vector<std::vector<double>>& distances);

}  // namespace jsa
