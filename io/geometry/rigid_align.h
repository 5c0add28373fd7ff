// Rigid alignment of one point set onto another by a rotation about the origin
// (both centred at their means, as the unit frame puts them): the pose step of a
// collection (shapes stored in their authors' frames are turned into the frame
// of the first shape before the shared atlas sees them; docs/collections.md).
//
//   1. principal axes of both sets (eigenvectors of the second moments);
//   2. candidates: the rotations that carry one set of axes onto the other,
//      x -> x V_m S V_f^T with S a diagonal of signs and det = +1 (4 candidates),
//      and, when two eigenvalues are close (the axes are not defined), every
//      order of those axes as well (up to 24: the rotations of a cube);
//   3. each candidate refined by point-to-point ICP, rotation only (Kabsch on
//      the nearest pairs of both directions);
//   4. the refined candidate with the lowest symmetric Chamfer distance wins;
//      ties keep the earlier candidate (the fixed order above, identity first),
//      except that ICP from the input's own pose wins when it is within
//      `keep_input` of the best (families of shapes are often stored aligned,
//      and near-symmetric ones, like an ant end to end, score two poses alike);
//      optionally (`tie`), among the poses within a factor of the best, the one
//      whose nearest pairs join the most alike neighbourhoods wins;
//      the winner gets more ICP steps, until the rotation stops changing.
// Symmetric shapes: a mirror is never a candidate (det = +1), so a left/right
// symmetric shape cannot come out reflected; a shape with a front/back or
// top/bottom symmetry has two candidates of about the same Chamfer, and the
// report gives the runner-up's score so the caller can tell (`margin`).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/block.h"

namespace jsa {

struct RigidAlignOptions {
  Index samples = 3000;        // points of each set used (the first rows; pools are random draws)
  int icp_iterations = 40;     // ICP steps per candidate
  int final_iterations = 500;  // more ICP steps for the winner (point-to-point ICP slides slowly
                               // along directions a near-symmetric shape hardly pins)
  double close_eigenvalues = 0.15;  // relative gap |l_a - l_b| / l_a under which axes a, b may swap
  // The input's own pose (ICP started at the identity) is kept when its Chamfer
  // is within this factor of the best candidate's: a collection stored aligned
  // stays as it is unless another pose is clearly better (0: always the best).
  double keep_input = 1.25;
  // The share of the closest pairs, each way, that the score and the ICP
  // updates use (trimmed ICP); 1: every pair (the plain symmetric Chamfer).
  // Articulated shapes (legs in other poses) spend most of a plain Chamfer on
  // the limbs; a trimmed one is decided by the parts that do match.
  double trim = 1.0;
  // Near-ties between poses (an ant end to end: head and abdomen swap with a
  // Chamfer only a few percent worse) decided by what the parts look like, not
  // where they are: among the poses within `tie` of the best Chamfer, the one
  // whose nearest pairs join points of the most alike ball shares wins (a
  // point's ball shares: the fraction of its set within ten radii from 0.05 to
  // 1.2 times the set's RMS radius; rotation-invariant). 0 (the default): the
  // lowest Chamfer only. Off because it is not reliable: on the SHREC ants it
  // turns 5 of 9 poses right where the lowest Chamfer turns 3, but it turns a
  // shape with a moved limb end to end (docs/collections.md).
  double tie = 0;
  // > 0: the sets are N x 6 rows (points, unit normals), and the normals,
  // scaled by this weight, join the points in the nearest pairs, the Kabsch
  // update and the score, which is then the 6D Chamfer of L_6D (Eq. 6) between
  // [x, w n] rows. A pose that puts surface on surface facing the other way
  // (an ant's abdomen on another's head, end to end) scores worse than with
  // the points alone. 0: points only (N x 3 sets).
  double normal_weight = 0;
  // The distinct poses (more than 10 degrees apart) whose Chamfer is within
  // this factor of the lowest are reported in RigidAlignment::near_poses, for a
  // caller that can tell them apart by other means (the fit itself:
  // model/tool/pose_by_fit.h). 0: none reported.
  double near_factor = 1.25;
};

struct RigidAlignment {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // rows: moving x -> x * rotation ~ fixed
  double chamfer = 0;        // symmetric Chamfer (mean squared distance, both ways) after ICP
  double runner_up = 0;      // the best Chamfer of a candidate that ends > 10 degrees away
  int candidates = 0;        // rotations tried (the input's pose and the axis candidates)
  double input_chamfer = 0;  // ICP from the input's own pose
  bool kept_input = false;   // the input's pose won by the keep_input rule
  int tied = 1;              // distinct poses within `tie` of the best Chamfer
  bool tie_broken = false;   // the ball shares chose another pose than the lowest Chamfer
  // The poses within options.near_factor of the lowest Chamfer, one per pose
  // (> 10 degrees apart), lowest Chamfer first, each refined by ICP like the
  // winner (which is one of them unless a rule chose a pose outside): when there
  // is more than one, the choice between them was close.
  std::vector<Eigen::Matrix3d> near_poses;
  std::vector<double> near_chamfers;
  // Per near pose, its mean Chamfer to a whole collection, when a caller
  // settles the tie that way (model/tool/shape_input.h, settle_near_ties).
  std::vector<double> near_collection;
  double angle_degrees() const;  // of `rotation`
};

// moving, fixed: N x 3 and M x 3 points (any N, M >= 4), centred at the origin.
// Deterministic: no random draws, nearest neighbours with a fixed tie rule.
RigidAlignment rigid_align(const Block<double>& moving, const Block<double>& fixed,
                           const RigidAlignOptions& options = {});

// The frame of a collection's reference shape, so that nothing downstream
// depends on the pose its file happens to store: x -> x R puts the principal
// axes of `points` (N x 3, centred) on x, y, z, longest first, each of the
// first two pointing to the side of its larger third moment (det R = +1).
// Rotating the points by Q gives Q^T R: the same canonical points, whatever
// the input pose, unless two variances or a third moment nearly tie (a
// symmetric body), where the frame is one of the ties.
Eigen::Matrix3d canonical_rotation(const Block<double>& points);

// The angle of a rotation matrix, in degrees (0 for the identity, 180 at most).
double rotation_angle_degrees(const Eigen::Matrix3d& r);

}  // namespace jsa
