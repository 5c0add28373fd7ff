// Principal axes, their proper sign and order candidates, ICP, lowest Chamfer.
#include "io/geometry/rigid_align.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "engine/check.h"
#include "io/geometry/nearest.h"

namespace jsa {
namespace {

// Eigenvectors of the second moments as columns, eigenvalues ascending, det = +1.
void principal_axes(const Block<double>& p, Eigen::Matrix3d& axes, Eigen::Vector3d& values) {
  const Eigen::Matrix3d c = p.transpose() * p / double(p.rows());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(c);
  axes = eig.eigenvectors();
  values = eig.eigenvalues();
  if (axes.determinant() < 0) axes.col(2) *= -1;
}

// The rotation R minimising sum |x_i R - y_i|^2 (rows), from H = sum x_i^T y_i:
// R = U D V^T with H = U S V^T and D = diag(1, 1, det(U V^T)) (Kabsch).
Eigen::Matrix3d kabsch(const Eigen::Matrix3d& h) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

// The sets as the search sees them: N x 3 points, or N x 6 rows [x, w n] with
// the normals scaled by RigidAlignOptions::normal_weight.
struct Sets {
  const Block<double>& moving;
  const Block<double>& fixed;
  const NearestIndex<double>& moving_index;
  const NearestIndex<double>& fixed_index;
  double trim;  // RigidAlignOptions::trim
};

// Rows turned by r: the points, and the normals with them.
Block<double> posed(const Block<double>& rows, const Eigen::Matrix3d& r) {
  Block<double> out(rows.rows(), rows.cols());
  for (Index c = 0; c < rows.cols(); c += 3) out.middleCols(c, 3) = rows.middleCols(c, 3) * r;
  return out;
}

// sum x^T y over a pair of rows, each 3-column group with its own: the
// cross-covariance whose Kabsch rotation minimises sum |x R - y|^2 + |w n R - w m|^2.
void add_pair(Eigen::Matrix3d& h, const Block<double>& a, Index i, const Block<double>& b,
              Index j) {
  for (Index c = 0; c < a.cols(); c += 3)
    h += a.row(i).segment(c, 3).transpose() * b.row(j).segment(c, 3);
}

// The pairs one direction keeps: all of them, or the `trim` share closest.
// Returns the mean squared distance over the kept pairs; keep[i] says which.
double kept_pairs(const std::vector<double>& d2, double trim, std::vector<char>& keep) {
  const size_t n = d2.size();
  keep.assign(n, 1);
  if (trim >= 1) {
    double sum = 0;
    for (double d : d2) sum += d;
    return sum / double(n);
  }
  const size_t k = std::max<size_t>(1, size_t(trim * double(n)));
  std::vector<double> sorted = d2;
  std::nth_element(sorted.begin(), sorted.begin() + long(k - 1), sorted.end());
  const double cut = sorted[k - 1];
  // Ties at the cut are kept in index order, so exactly k pairs count.
  size_t below = 0;
  for (double d : d2) below += d < cut;
  size_t at_cut = k - below;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool in = d2[i] < cut || (d2[i] == cut && at_cut > 0 && at_cut--);
    keep[i] = in;
    if (in) sum += d2[i];
  }
  return sum / double(k);
}

// Symmetric (trimmed) Chamfer of (moving R, fixed), and the Kabsch update from
// the same pairs.
double chamfer_and_update(const Sets& s, const Eigen::Matrix3d& r, Eigen::Matrix3d* next) {
  std::vector<int> nn;
  std::vector<double> d2;
  std::vector<char> keep;
  const Block<double> moved = posed(s.moving, r);
  s.fixed_index.query(moved, nn, &d2);
  const double forward = kept_pairs(d2, s.trim, keep);
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (Index i = 0; i < moved.rows(); ++i)
    if (keep[size_t(i)]) add_pair(h, s.moving, i, s.fixed, nn[size_t(i)]);
  // |x R - y| = |x - y R^T|: the fixed points' neighbours among the unmoved ones.
  const Block<double> back = posed(s.fixed, r.transpose());
  s.moving_index.query(back, nn, &d2);
  const double backward = kept_pairs(d2, s.trim, keep);
  for (Index j = 0; j < back.rows(); ++j)
    if (keep[size_t(j)]) add_pair(h, s.moving, nn[size_t(j)], s.fixed, j);
  if (next) *next = kabsch(h);
  return forward + backward;
}

// Ball shares (RigidAlignOptions::tie): for every point, the fraction of its
// set within each of ten radii, relative to the set's RMS radius. They do
// not change under a rotation, and they tell a thick part (a wide cap in every
// ball) from a thin or busy one (legs, antennae) that sits in the same place.
Block<double> ball_shares(const Block<double>& p) {
  constexpr std::array<double, 10> radii{0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9, 1.2};
  const double rms = std::sqrt(p.rowwise().squaredNorm().mean());
  std::array<double, radii.size()> r2;
  for (size_t k = 0; k < radii.size(); ++k) r2[k] = radii[k] * radii[k] * rms * rms;
  const Index n = p.rows();
  Block<double> out(n, Index(radii.size()));
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n; ++i) {
    std::array<Index, radii.size()> count{};
    for (Index j = 0; j < n; ++j) {
      const double d2 = (p.row(i) - p.row(j)).squaredNorm();
      for (size_t k = 0; k < radii.size(); ++k) count[k] += d2 < r2[k];
    }
    for (size_t k = 0; k < radii.size(); ++k) out(i, Index(k)) = double(count[k]) / double(n);
  }
  return out;
}

// The mean L1 distance between the ball shares of nearest pairs, both ways, at
// the pose r, each radius weighted by 1 / its mean share (so the small balls,
// whose shares are small numbers, count as much as the large ones): small when
// every part lands on a part that looks like it.
double share_mismatch(const Sets& s, const Eigen::Matrix3d& r, const Block<double>& moving_shares,
                      const Block<double>& fixed_shares) {
  // Each radius counts alike: differences relative to the radius' mean share.
  const Eigen::RowVectorXd w =
      2.0 / (moving_shares.colwise().mean() + fixed_shares.colwise().mean()).array().max(1e-12);
  std::vector<int> nn;
  std::vector<double> d2;
  std::vector<char> keep;
  double sum = 0;
  Index pairs = 0;
  // One direction: the points of `from` (already posed) against their nearest
  // in `to`, over the pairs the score keeps (RigidAlignOptions::trim), so a
  // moved limb is left out here as it is from the Chamfer.
  auto one_way = [&](const Block<double>& from, const Block<double>& from_shares,
                     const NearestIndex<double>& to, const Block<double>& to_shares) {
    to.query(from, nn, &d2);
    kept_pairs(d2, s.trim, keep);
    for (Index i = 0; i < from.rows(); ++i)
      if (keep[size_t(i)]) {
        sum += (from_shares.row(i) - to_shares.row(nn[size_t(i)])).cwiseAbs().cwiseProduct(w).sum();
        ++pairs;
      }
  };
  one_way(posed(s.moving, r), moving_shares, s.fixed_index, fixed_shares);
  one_way(posed(s.fixed, r.transpose()), fixed_shares, s.moving_index, moving_shares);
  return sum / double(pairs);
}

}  // namespace

Eigen::Matrix3d canonical_rotation(const Block<double>& points) {
  JSA_CHECK(points.cols() == 3 && points.rows() >= 4, "canonical_rotation takes N x 3 points");
  Eigen::Matrix3d axes;
  Eigen::Vector3d values;
  principal_axes(points, axes, values);
  // Largest variance first: x R = coordinates along the axes, longest first.
  Eigen::Matrix3d r;
  for (int k = 0; k < 3; ++k) r.col(k) = axes.col(2 - k);
  // Each of the first two axes points to the side of its larger third moment
  // (the heavier tail); the third completes a proper rotation.
  for (int k = 0; k < 2; ++k) {
    const Eigen::VectorXd t = points * r.col(k);
    if (t.array().cube().sum() < 0) r.col(k) *= -1;
  }
  r.col(2) = r.col(0).cross(r.col(1));
  return r;
}

double rotation_angle_degrees(const Eigen::Matrix3d& r) {
  const double c = std::clamp((r.trace() - 1) / 2, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

double RigidAlignment::angle_degrees() const { return rotation_angle_degrees(rotation); }

RigidAlignment rigid_align(const Block<double>& moving_all, const Block<double>& fixed_all,
                           const RigidAlignOptions& o) {
  const Index columns = o.normal_weight > 0 ? 6 : 3;
  JSA_CHECK(moving_all.cols() == columns && fixed_all.cols() == columns,
            "rigid_align takes N x "
                << columns << (columns == 6 ? " rows (points, unit normals)" : " points"));
  JSA_CHECK(moving_all.rows() >= 4 && fixed_all.rows() >= 4,
            "rigid_align needs at least 4 points per set");
  JSA_CHECK(o.samples >= 4 && o.icp_iterations >= 0 && o.final_iterations >= 0 && o.trim > 0 &&
                o.trim <= 1 && o.normal_weight >= 0 && o.near_factor >= 0,
            "bad rigid_align options");
  Block<double> moving = moving_all.topRows(std::min(o.samples, moving_all.rows()));
  Block<double> fixed = fixed_all.topRows(std::min(o.samples, fixed_all.rows()));
  if (columns == 6) {
    moving.rightCols(3) *= o.normal_weight;
    fixed.rightCols(3) *= o.normal_weight;
  }
  const NearestIndex<double> moving_index(moving), fixed_index(fixed);
  const Sets sets{moving, fixed, moving_index, fixed_index, o.trim};

  Eigen::Matrix3d vm, vf;
  Eigen::Vector3d lm, lf;
  principal_axes(moving.leftCols(3), vm, lm);
  principal_axes(fixed.leftCols(3), vf, lf);
  // Axes a and b may be exchanged when their eigenvalues are close in either set.
  auto close = [&](int a, int b) {
    for (const Eigen::Vector3d* l : {&lm, &lf}) {
      const double hi = std::max((*l)(a), (*l)(b));
      if (hi <= 0 || std::abs((*l)(a) - (*l)(b)) <= o.close_eigenvalues * hi) return true;
    }
    return false;
  };

  // Candidates in a fixed order: the identity order of axes first, and within
  // an order the sign patterns from (+, +, +).
  std::array<int, 3> perm{0, 1, 2};
  std::vector<Eigen::Matrix3d> candidates;
  do {
    bool allowed = true;
    for (int a = 0; a < 3; ++a)
      allowed = allowed && (perm[size_t(a)] == a || close(a, perm[size_t(a)]));
    if (!allowed) continue;
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
      for (int a = 0; a < 3; ++a) m(a, perm[size_t(a)]) = (signs >> a) & 1 ? -1.0 : 1.0;
      if (m.determinant() < 0) continue;  // a reflection: never a change of pose
      // x -> coordinates on the moving axes (x vm) -> the fixed axes (m) -> space (vf^T).
      candidates.push_back(vm * m * vf.transpose());
    }
  } while (std::next_permutation(perm.begin(), perm.end()));

  auto icp = [&](Eigen::Matrix3d r, int iterations) {
    Eigen::Matrix3d next;
    for (int k = 0; k < iterations; ++k) {
      chamfer_and_update(sets, r, &next);
      const double change = (next - r).cwiseAbs().maxCoeff();
      r = next;
      if (change < 1e-10) break;
    }
    return r;
  };
  // The input's own pose first.
  candidates.insert(candidates.begin(), Eigen::Matrix3d::Identity());
  std::vector<Eigen::Matrix3d> refined;
  std::vector<double> scores;
  for (const Eigen::Matrix3d& start : candidates) {
    refined.push_back(icp(start, o.icp_iterations));
    scores.push_back(chamfer_and_update(sets, refined.back(), nullptr));
  }
  size_t best = 0;
  for (size_t c = 1; c < scores.size(); ++c)
    if (scores[c] < scores[best]) best = c;
  RigidAlignment out;
  out.input_chamfer = scores[0];
  if (best != 0 && o.keep_input > 0 && scores[0] <= o.keep_input * scores[best]) {
    best = 0;
    out.kept_input = true;
  } else if (o.tie > 0) {
    // One representative (the lowest Chamfer) per distinct pose within `tie`.
    std::vector<size_t> tied{best};
    std::vector<size_t> order(scores.size());
    for (size_t c = 0; c < order.size(); ++c) order[c] = c;
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return scores[a] < scores[b]; });
    for (size_t c : order) {
      if (scores[c] > o.tie * scores[best]) break;
      bool distinct = true;
      for (size_t t : tied)
        distinct = distinct && rotation_angle_degrees(refined[c].transpose() * refined[t]) > 10;
      if (distinct) tied.push_back(c);
    }
    out.tied = int(tied.size());
    if (tied.size() > 1) {
      const Block<double> moving_shares = ball_shares(moving.leftCols(3)),
                          fixed_shares = ball_shares(fixed.leftCols(3));
      double least = share_mismatch(sets, refined[best], moving_shares, fixed_shares);
      const size_t lowest = best;
      for (size_t t = 1; t < tied.size(); ++t) {
        const double m = share_mismatch(sets, refined[tied[t]], moving_shares, fixed_shares);
        if (m < least) least = m, best = tied[t];
      }
      out.tie_broken = best != lowest;
    }
  }
  out.rotation = icp(refined[best], o.final_iterations);
  out.chamfer = chamfer_and_update(sets, out.rotation, nullptr);
  if (o.near_factor > 0) {
    std::vector<size_t> order(scores.size());
    for (size_t c = 0; c < order.size(); ++c) order[c] = c;
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return scores[a] < scores[b]; });
    std::vector<size_t> kept;
    for (size_t c : order) {
      if (scores[c] > o.near_factor * scores[order[0]]) break;
      bool distinct = true;
      for (size_t t : kept)
        distinct = distinct && rotation_angle_degrees(refined[c].transpose() * refined[t]) > 10;
      if (!distinct) continue;
      kept.push_back(c);
      // The winner's pose is represented by the winner, as refined above.
      const bool winner = rotation_angle_degrees(refined[c].transpose() * refined[best]) <= 10;
      const Eigen::Matrix3d r = winner ? out.rotation : icp(refined[c], o.final_iterations);
      out.near_poses.push_back(r);
      out.near_chamfers.push_back(winner ? out.chamfer : chamfer_and_update(sets, r, nullptr));
    }
  }
  out.candidates = int(candidates.size());
  out.runner_up = -1;
  for (size_t c = 0; c < scores.size(); ++c) {
    if (rotation_angle_degrees(refined[c].transpose() * refined[best]) <= 10) continue;
    if (out.runner_up < 0 || scores[c] < out.runner_up) out.runner_up = scores[c];
  }
  return out;
}

}  // namespace jsa
