// The starting wrap (model/heuristics/wrap.h): the octahedral map covers the sphere once,
// outward, with its seams where the header says; the ellipsoid of a point set
// has the set's axes and half-widths; the fit puts phi on the wrap with outward
// normals and psi near its inverse.
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>

#include "model/heuristics/orientation.h"
#include "model/heuristics/wrap.h"
#include "model/tool/trainer.h"
#include "test/normal_draws.h"
#include "test/sphere_pool.h"

using namespace jsa;
using test_support::sphere_pool;

namespace {

Eigen::Vector3d sphere_at(double u, double v) {
  double p[3], n[3];
  octahedral_sphere(u, v, p, n);
  return {p[0], p[1], p[2]};
}

}  // namespace

TEST_CASE("octahedral_sphere: on the sphere, outward, seams paired on the square's edges",
          "[wrap]") {
  Rng rng(5);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const double u = rng.uniform(0, 1), v = rng.uniform(0, 1);
    double p[3], n[3];
    octahedral_sphere(u, v, p, n);
    const Eigen::Vector3d q(p[0], p[1], p[2]), m(n[0], n[1], n[2]);
    CHECK(std::abs(q.norm() - 1) < 1e-12);
    CHECK((m - q).norm() < 1e-12);  // the unit sphere's outward normal is the point
    // J_u x J_v by central differences points outward (Eq. 2's convention),
    // away from the fold lines |s| + |t| = 1 and s = 0, t = 0 where W has kinks.
    const double s = 2 * u - 1, t = 2 * v - 1, h = 1e-6;
    if (std::abs(std::abs(s) + std::abs(t) - 1) < 1e-3 || std::abs(s) < 1e-3 || std::abs(t) < 1e-3)
      continue;
    const Eigen::Vector3d ju = (sphere_at(u + h, v) - sphere_at(u - h, v)) / (2 * h);
    const Eigen::Vector3d jv = (sphere_at(u, v + h) - sphere_at(u, v - h)) / (2 * h);
    CHECK(ju.cross(jv).dot(q) > 0);
    ++checked;
  }
  CHECK(checked > 1900);
  // The square's boundary folds onto four seams: each edge is glued to itself mirrored.
  for (double a : {0.0, 0.1, 0.37, 0.5, 0.9}) {
    CHECK((sphere_at(0, a) - sphere_at(0, 1 - a)).norm() < 1e-12);
    CHECK((sphere_at(1, a) - sphere_at(1, 1 - a)).norm() < 1e-12);
    CHECK((sphere_at(a, 0) - sphere_at(1 - a, 0)).norm() < 1e-12);
    CHECK((sphere_at(a, 1) - sphere_at(1 - a, 1)).norm() < 1e-12);
  }
  // Onto: every direction has an image point within a grid step.
  const int g = 200;
  std::vector<Eigen::Vector3d> grid;
  for (int i = 0; i <= g; ++i)
    for (int j = 0; j <= g; ++j) grid.push_back(sphere_at(double(i) / g, double(j) / g));
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    Eigen::Vector3d d = test_support::normal_vector3(rng);
    d.normalize();
    double best = 1e9;
    for (const auto& p : grid) best = std::min(best, (p - d).norm());
    worst = std::max(worst, best);
  }
  INFO("farthest direction from the 200 x 200 grid's image: " << worst);
  CHECK(worst < 4.0 / g);
}

TEST_CASE("enclosing_ellipsoid: a box's axes and half-widths, a right-handed frame", "[wrap]") {
  // Uniform in a box of half-widths (3, 2, 1) rotated about z by 30 degrees and
  // moved to (1, -2, 0.5): second moments a^2 / 3, so radii sqrt(3 lambda) = a.
  Rng rng(6);
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  Block<float> pool(200000, 6);
  for (Index i = 0; i < pool.rows(); ++i) {
    const double x = rng.uniform(-3, 3), y = rng.uniform(-2, 2), z = rng.uniform(-1, 1);
    pool.row(i) << float(1 + c * x - s * y), float(-2 + s * x + c * y), float(0.5 + z), 0, 0, 0;
  }
  const Ellipsoid e = enclosing_ellipsoid(pool);
  CHECK(e.center[0] == Approx(1).margin(0.02));
  CHECK(e.center[1] == Approx(-2).margin(0.02));
  CHECK(e.center[2] == Approx(0.5).margin(0.02));
  CHECK(e.radii[0] == Approx(3).epsilon(0.01));
  CHECK(e.radii[1] == Approx(2).epsilon(0.01));
  CHECK(e.radii[2] == Approx(1).epsilon(0.01));
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) r(i, k) = e.axes[i][k];
  CHECK(std::abs(std::abs(r(0, 0) * c + r(1, 0) * s) - 1) <
        1e-3);  // first axis along the long side
  CHECK(r.determinant() == Approx(1).epsilon(1e-9));
  // A flat set keeps a fifth of its largest radius, so the wrap stays a closed surface.
  for (Index i = 0; i < pool.rows(); ++i) pool(i, 2) = 0.5f;
  CHECK(enclosing_ellipsoid(pool).radii[2] == Approx(0.2 * 3).epsilon(0.01));
  // The map of an ellipsoid: on it, normal outward and of unit length.
  for (double u : {0.2, 0.5, 0.8})
    for (double v : {0.1, 0.6}) {
      double p[3], n[3];
      e.map(u, v, p, n);
      Eigen::Vector3d q(p[0] - e.center[0], p[1] - e.center[1], p[2] - e.center[2]);
      Eigen::Vector3d local = r.transpose() * q;
      double level = 0;
      for (int k = 0; k < 3; ++k) level += std::pow(local(k) / e.radii[k], 2);
      CHECK(level == Approx(1).epsilon(1e-9));
      CHECK(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) == Approx(1).epsilon(1e-12));
      CHECK(n[0] * q(0) + n[1] * q(1) + n[2] * q(2) > 0);
    }
}

TEST_CASE("wrap_initialize: phi lands on the wrap facing out, psi near its inverse", "[wrap]") {
  AtlasOptions o;
  o.gaussians = 1024;  // sigma = 1/32: few samples of P fall outside the square W is fitted on
  o.width = 32;
  o.hidden_layers = 3;
  Atlas<float> atlas(o);
  Rng init(7);
  atlas.initialize(init);
  // Targets: a sphere of radius 0.5 (surface samples: radii sqrt(3 * 0.25 / 3) = 0.5).
  Block<double> sphere = sphere_pool(20000, 8);
  Block<float> pool = sphere.cast<float>();
  pool.leftCols(3) *= 0.5f;
  pool.rightCols(3) *= float(o.alpha);
  const double before = back_facing_fraction(atlas, pool, 2000, init);
  Rng rng(9);
  const WrapReport r = wrap_initialize(atlas, {pool}, 800, 1000, 2e-3, rng);
  Rng check(10);
  const double after = back_facing_fraction(atlas, pool, 2000, check);
  INFO("RMS error phi " << r.phi_error << ", psi " << r.psi_error << "; back-facing before "
                        << before << ", after " << after);
  CHECK(r.phi_error < 0.05);  // of a radius-0.5 sphere
  CHECK(r.psi_error < 0.12);  // psi cannot follow the seams exactly
  CHECK(after < 0.03);
  // Nothing to do without steps, and a pool per shape is required.
  CHECK(wrap_initialize(atlas, {pool}, 0, 1000, 1e-3, rng).phi_error == 0);
  CHECK_THROWS(wrap_initialize(atlas, {pool, pool}, 10, 100, 1e-3, rng));
}

TEST_CASE("Trainer: the wrap runs once, before the first step, and is seeded", "[wrap]") {
  FitOptions o;
  o.atlas.gaussians = 32;
  o.atlas.width = 16;
  o.atlas.hidden_layers = 2;
  o.points = 200;
  o.pool = 2000;
  o.iterations = 3;
  o.wrap_steps = 50;
  const Block<double> pool = sphere_pool(2000, 11);
  Trainer a(o, pool), b(o, pool);
  a.step();
  CHECK(b.wrap().phi_error > 0);
  CHECK(b.wrap().phi_error == 0);  // the second call does nothing
  b.step();
  CHECK(a.atlas().params.values() == b.atlas().params.values());
  o.wrap_steps = 0;
  Trainer c(o, pool);
  c.step();
  CHECK(c.atlas().params.values() != a.atlas().params.values());
}
