// io/geometry/intrinsic_descriptors: the values do not change when a surface
// is bent without stretching, moved or scaled; they do change along it (high
// at the ends of a strip); a point cloud and a surface in pieces work too.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/geometry/intrinsic_descriptors.h"
#include "test/geometry_strip.h"

namespace {

using jsa::Block;
using jsa::Index;
using test_geometry::strip;

}  // namespace

TEST_CASE("intrinsic descriptors: a fold, a motion and a scale leave them unchanged",
          "[geometry][intrinsic]") {
  const jsa::Mesh flat = strip(24, 4, false, 0), folded = strip(24, 4, true, 10);
  REQUIRE((flat.vertices - folded.vertices).cwiseAbs().maxCoeff() > 0.5);  // a different embedding
  const jsa::IntrinsicDescriptors a = jsa::intrinsic_descriptors(flat);
  const jsa::IntrinsicDescriptors b = jsa::intrinsic_descriptors(folded);
  REQUIRE(a.values.rows() == flat.vertices.rows());
  REQUIRE(a.values.cols() == jsa::kIntrinsicChannels);
  CHECK((a.values - b.values).cwiseAbs().maxCoeff() < 1e-12);

  // Every node a source: farthest-point sampling breaks the many exact ties of
  // a grid by rounding, which a motion changes; with all sources no choice is left.
  jsa::IntrinsicOptions all;
  all.sources = 1000;
  const jsa::IntrinsicDescriptors e = jsa::intrinsic_descriptors(flat, all);
  jsa::Mesh moved = folded;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  moved.vertices = ((folded.vertices * r) * 3.5).rowwise() + Eigen::RowVector3d(1, -2, 0.5);
  const jsa::IntrinsicDescriptors c = jsa::intrinsic_descriptors(moved, all);
  CHECK((e.values - c.values).cwiseAbs().maxCoeff() < 1e-9);

  // Along the strip: the ends are far from most of it, the middle is not.
  const Index end = 0, middle = 12 * 5 + 2;
  CHECK(e.values(end, 0) > 1.5 * e.values(middle, 0));
  CHECK(e.values(end, 2) > e.values(middle, 2));
  CHECK(a.values.allFinite());
}

TEST_CASE("intrinsic descriptors: point clouds, pieces, and the look-up at points",
          "[geometry][intrinsic]") {
  // Two strips apart: each piece gets a source, every value is finite.
  jsa::Mesh two = strip(8, 2, false, 0);
  const Index v = two.vertices.rows();
  jsa::Mesh other = strip(8, 2, false, 0);
  two.vertices.conservativeResize(2 * v, 3);
  two.vertices.bottomRows(v) = other.vertices.rowwise() + Eigen::RowVector3d(0, 0, 5);
  two.faces.conservativeResize(2 * other.faces.rows(), 3);
  two.faces.bottomRows(other.faces.rows()) = other.faces.array() + int(v);
  const jsa::IntrinsicDescriptors d = jsa::intrinsic_descriptors(two);
  CHECK(d.values.allFinite());
  CHECK((d.values.topRows(v) - d.values.bottomRows(v)).cwiseAbs().maxCoeff() < 1e-9);

  jsa::Mesh cloud;
  cloud.vertices = strip(24, 4, false, 0).vertices;
  const jsa::IntrinsicDescriptors p = jsa::intrinsic_descriptors(cloud);
  REQUIRE(p.nodes.rows() == cloud.vertices.rows());
  CHECK(p.values.allFinite());
  CHECK(p.values(0, 0) > p.values(12 * 5 + 2, 0));

  // Each point takes the row of its nearest node.
  Block<double> at(2, 3);
  at << 0.01, 0.0, 0.0, 3.0, 0.5, 0.02;
  const Block<double> h = jsa::descriptors_at(at, p.nodes, p.values);
  CHECK(h.row(0) == p.values.row(0));
  CHECK(h.row(1) == p.values.row(12 * 5 + 2));
}

TEST_CASE("intrinsic descriptors: ranks from 0 to 1, ties share their mean rank",
          "[geometry][intrinsic]") {
  Block<double> v(5, 2);
  v << 3, 1,  //
      1, 1,   //
      2, 1,   //
      2, 5,   //
      9, 0;
  jsa::rank_normalize(v);
  // Column 0: 1 < 2 = 2 < 3 < 9, ranks 0, 1.5, 3, 4 of 4.
  CHECK(v(1, 0) == 0);
  CHECK(v(2, 0) == Approx(1.5 / 4));
  CHECK(v(3, 0) == Approx(1.5 / 4));
  CHECK(v(0, 0) == Approx(0.75));
  CHECK(v(4, 0) == 1);
  // Column 1: 0 < 1 = 1 = 1 < 5.
  CHECK(v(4, 1) == 0);
  CHECK(v(0, 1) == Approx(0.5));
  CHECK(v(3, 1) == 1);
}
