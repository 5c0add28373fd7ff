// Cutting a mesh into charts where a per-vertex UV map (psi's) tears or folds.
// An edge is a seam when it is non-manifold, joins inconsistently oriented
// faces, or is torn (its UV length, areas equalised, is many times its 3D
// length). Faces whose UVs are usable (no torn edge, not degenerate, bounded
// symmetric Dirichlet energy) group into orientation regions; each region large
// enough is a chart's core, and the other faces join the nearest core by a
// breadth-first growth over the dual graph (so small folds and slivers are
// repaired inside a chart instead of becoming charts). Every chart is then
// checked to be a topological disk (Euler characteristic 1, one boundary loop)
// and made one: a genus-0 chart by cutting along shortest paths between its
// boundary loops (one chart, longer seams), any other by splitting it in two
// until it is. Degenerate faces are skipped.
#pragma once
#include <string>
#include <vector>

#include "io/geometry/mesh.h"

namespace jsa {

struct CutOptions {
  // An edge whose UV length (UVs scaled to the total 3D area) exceeds this many
  // times its 3D length is torn: psi jumps across it, so it becomes a seam.
  double torn_ratio = 4;
  // A face's UVs are usable when its symmetric Dirichlet energy (4 for an
  // isometry, after the global area scaling) is below this.
  double max_face_energy = 40;
  // An orientation region of usable faces becomes a chart's core when its 3D
  // area is at least this fraction of the total and it has >= min_core_faces.
  double min_core_area_fraction = 0.002;
  int min_core_faces = 8;
  // Splits of a chart that is not a disk before it falls back to single faces.
  int max_split_depth = 16;
};

// A chart as a mesh of its own: local vertices are corners of the chart's faces
// that meet across the chart's inner edges (a vertex of the input met by two
// separate fans of the chart, as at a bow-tie or at the end of a seam, becomes
// two local vertices).
struct ChartMesh {
  std::vector<int> faces;  // input face ids, ascending
  Faces local;             // faces.size() x 3 indices into vertex, corner for corner with the input
  std::vector<int> vertex;   // input vertex of each local vertex
  int orientation = 1;       // +1, or -1 when psi maps the chart's core mirrored
  std::vector<char> usable;  // per face: psi's UVs usable there
  // Empty, or per local vertex: the UVs of the chart this one was split from
  // (a locally injective map at the 3D scale), a start to try before psi's.
  Block<double> inherited_uv;
};

struct CutResult {
  std::vector<ChartMesh> charts;
  std::vector<int> skipped_faces;  // degenerate faces (repeated index or zero 3D area): no chart
  Index torn_edges = 0;            // inner edges cut because psi tears across them
  Index slits_closed = 0;          // torn edges glued back: they ended inside their chart
  Index nonmanifold_edges = 0;     // edges used by more than two faces
  Index inconsistent_edges = 0;    // edges whose two faces disagree on orientation
  Index boundary_edges = 0;        // edges of one face (holes, open borders)
  Index path_cuts = 0;             // shortest paths cut to make a genus-0 chart a disk
  Index split_charts = 0;          // charts split because they were not disks
  Index unusable_faces = 0;        // faces whose psi UVs need repair
  std::vector<std::string> warnings;
};

// positions: V x 3; faces: F x 3; uv: V x 2 (one UV per vertex). Deterministic.
CutResult cut_charts(const Block<double>& positions, const Faces& faces, const Block<double>& uv,
                     const CutOptions& options = {});

// The chart of `faces` (input face ids) whose inner edges are those in
// `inner` (neighbour[3 f + k] = 3 g + l when edge k of f is glued to edge l of
// g, -1 when not): local vertices from corners glued across inner edges.
ChartMesh build_chart_mesh(const Faces& faces, const std::vector<int>& chart_faces,
                           const std::vector<int>& neighbour, const std::vector<int>& face_chart,
                           int chart);

// Euler characteristic V - E + F and the number of boundary loops of a chart.
struct ChartTopology {
  int euler = 0;
  int boundary_loops = 0;
  bool is_disk() const { return euler == 1 && boundary_loops == 1; }
};
ChartTopology chart_topology(const ChartMesh& chart);

// The boundary loops of a chart as local vertex ids, each in the order of the
// faces' orientation (the chart lies to the left).
std::vector<std::vector<int>> boundary_loops(const Faces& local, Index vertex_count);

}  // namespace jsa

namespace jsa {

// A disk chart cut in two along the dual graph: faces go to the nearer of two
// far-apart seeds (a double breadth-first sweep). Returns the two halves (with
// their own local vertices, usable flags and orientation), or nothing if the
// chart has one face or a half is not a disk.
// With the input's positions (V x 3, indexed by chart.vertex) the distances
// are 3D lengths between face centroids (Dijkstra) instead of dual-graph steps.
// With `uv` (per local vertex of the chart) each half inherits its part of it.
std::vector<ChartMesh> split_chart(const ChartMesh& chart, const Block<double>* positions = nullptr,
                                   const Block<double>* uv = nullptr);

}  // namespace jsa
