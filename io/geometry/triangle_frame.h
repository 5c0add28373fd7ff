// One triangle of a surface in its own orthonormal 2D frame: its area and the
// gradient operator of the linear interpolant, so that the Jacobian of a UV map
// on the triangle is J = [uv corners as columns] * grad^T (2 x 2, rows du, dv).
// With this frame det J > 0 exactly when the UV triangle keeps the 3D
// triangle's orientation (counter-clockwise seen from its normal).
#pragma once
#include <cmath>

#include "engine/block.h"

namespace jsa {

struct TriangleFrame {
  double area = 0;                   // 3D area
  Eigen::Matrix<double, 2, 3> grad;  // row 0: d/dx of the corner weights, row 1: d/dy
};

// The 3D triangle (p0, p1, p2) laid in the plane as (0, 0), (|e1|, 0), (a, b)
// with b > 0; grad = M^-1 [[-1, 1, 0], [-1, 0, 1]] with M's rows the edges.
// A degenerate triangle gets area 0 and a zero gradient.
inline TriangleFrame triangle_frame(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                    const Eigen::Vector3d& p2) {
  TriangleFrame t;
  const Eigen::Vector3d e1 = p1 - p0, e2 = p2 - p0;
  const double l1 = e1.norm();
  const double cross = e1.cross(e2).norm();
  t.area = 0.5 * cross;
  t.grad.setZero();
  if (!(l1 > 0) || !(cross > 0)) return t;
  const double a = e1.dot(e2) / l1, b = cross / l1;
  // M = [[l1, 0], [a, b]]; M^-1 = [[1/l1, 0], [-a/(l1 b), 1/b]].
  Eigen::Matrix2d minv;
  minv << 1 / l1, 0, -a / (l1 * b), 1 / b;
  Eigen::Matrix<double, 2, 3> d;
  d << -1, 1, 0, -1, 0, 1;
  t.grad = minv * d;
  return t;
}

// J (2 x 2) of the UV map on a triangle with corner UVs q0, q1, q2.
inline Eigen::Matrix2d uv_jacobian(const TriangleFrame& t, const Eigen::Vector2d& q0,
                                   const Eigen::Vector2d& q1, const Eigen::Vector2d& q2) {
  Eigen::Matrix<double, 2, 3> q;
  q << q0, q1, q2;
  return q * t.grad.transpose();
}

// Twice the signed area of a UV triangle.
inline double signed_area2(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                           const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

}  // namespace jsa
