// Pose-invariant descriptors of a surface (beyond the paper, issue 19): at every
// point, statistics of its geodesic distances to the rest of the surface. A
// bent arm and a straight one carry the same values (the distances are measured
// along the surface), so matching them tells a collection where the hand is
// whatever the pose; the extrinsic Chamfer terms alone match a folded hand to
// the chest it lies on (docs/collections.md, twelfth round).
//
// Geodesic distances are approximated by shortest paths along the mesh's edges
// (a point cloud: its k nearest neighbours), from S sources chosen by farthest-
// point sampling, so the sources spread evenly over the surface. Per vertex v,
// with d_1..d_S its distances to the sources, divided by sqrt(A / 4 pi) (A the
// surface's area: 1 for the unit sphere, so the values do not change with the
// size of the shape or with how far its limbs reach):
//
//   h(v) = [ mean_s d_s,  quantile_0.2 {d_s},  quantile_0.8 {d_s} ]
//
// The mean is the average geodesic distance (high at the tips of limbs, low on
// the trunk), the quantiles separate a point near much of the surface from one
// near a little of it. Sources out of reach (another connected component) are
// left out of v's statistics.
#pragma once
#include "io/geometry/mesh.h"

namespace jsa {

constexpr int kIntrinsicChannels = 3;

struct IntrinsicOptions {
  int sources = 64;    // S
  int neighbours = 8;  // graph of a point cloud: each point joined to its k nearest
};

struct IntrinsicDescriptors {
  Block<double> nodes;  // G x 3: the graph's vertices (the mesh's; a cloud's, at most 4000 of them)
  Block<double> values;  // G x kIntrinsicChannels: h at each node
};

// h at the nodes of the shape's graph. A point cloud has no area: its distances
// are divided by its largest distance from its mean instead (not pose-invariant).
IntrinsicDescriptors intrinsic_descriptors(const Mesh& mesh, const IntrinsicOptions& o = {});

// h at `points` (N x 3, in the frame of `nodes`): each point takes its nearest node's row.
Block<double> descriptors_at(const Block<double>& points, const Block<double>& nodes,
                             const Block<double>& values);

// Each column replaced by its empirical distribution function over the rows,
// rank / (N - 1) in [0, 1] (equal values share their mean rank). On a shape's
// pool (uniform samples by area) this is the fraction of the surface with a
// lower value: every shape's descriptors then have the same distribution, so
// matching them moves no surface from one part to another (a pull that raw
// values, offset from shape to shape, made: docs/collections.md, twelfth round).
void rank_normalize(Block<double>& values);

}  // namespace jsa
