// The training loop: same seed -> same run; a resumed run follows the same
// trajectory bit for bit; and a small atlas actually learns a sphere.
#include <catch2/catch.hpp>
#include <cmath>
#include <sstream>

#include "engine/parallel.h"
#include "model/tool/domain_mesh.h"
#include "model/tool/trainer.h"
#include "test/sphere_pool.h"

using namespace jsa;
using test_support::sphere_pool;

namespace {

FitOptions small_options() {
  FitOptions o;
  o.atlas.gaussians = 256;
  o.atlas.width = 32;
  o.atlas.hidden_layers = 3;
  o.points = 256;
  o.iterations = 400;
  o.lr = 1e-3;
  return o;
}

}  // namespace

TEST_CASE("trainer: the same seed gives the same losses, bit for bit", "[trainer]") {
  const Block<double> pool = sphere_pool(4000, 1);
  Trainer a(small_options(), pool), b(small_options(), pool);
  for (int i = 0; i < 5; ++i) {
    a.step();
    b.step();
    REQUIRE(a.last().total == b.last().total);
  }
  FitOptions other = small_options();
  other.seed = 2;
  Trainer c(other, pool);
  c.step();
  CHECK(c.last().total != a.last().total);
}

TEST_CASE("trainer: a resumed run follows the uninterrupted trajectory", "[trainer]") {
  const Block<double> pool = sphere_pool(4000, 1);
  Trainer straight(small_options(), pool);
  std::vector<double> expected;
  for (int i = 0; i < 8; ++i) {
    straight.step();
    expected.push_back(straight.last().total);
  }
  Trainer first(small_options(), pool);
  for (int i = 0; i < 4; ++i) first.step();
  std::stringstream state;
  first.save_state(state);
  Trainer second(small_options(), pool);
  second.load_state(state, "test state");
  REQUIRE(second.iteration() == 4);
  for (int i = 4; i < 8; ++i) {
    second.step();
    CHECK(second.last().total == expected[i]);
  }
}

TEST_CASE("trainer: a truncated state is rejected", "[trainer]") {
  const Block<double> pool = sphere_pool(1000, 1);
  Trainer t(small_options(), pool);
  t.step();
  std::stringstream state;
  t.save_state(state);
  std::string bytes = state.str();
  std::stringstream cut(bytes.substr(0, bytes.size() / 2));
  Trainer u(small_options(), pool);
  CHECK_THROWS_AS(u.load_state(cut, "cut"), InputError);
}

TEST_CASE("trainer: a small atlas learns the unit sphere", "[trainer]") {
  const Block<double> pool = sphere_pool(20000, 3);
  Trainer t(small_options(), pool);
  t.step();
  const double initial = t.last().surface;
  while (!t.finished()) t.step();
  const double final_6d = t.last().surface;
  INFO("L_6D initial " << initial << ", after 400 iterations " << final_6d);
  // Measured 0.064 (from 1.6) on this machine: the bounds leave a wide margin.
  CHECK(final_6d < 0.1 * initial);
  CHECK(final_6d < 0.1);
}

TEST_CASE("trainer: a NaN is caught, the last good state restored, and training goes on",
          "[trainer]") {
  const Block<double> pool = sphere_pool(4000, 1);
  Trainer t(small_options(), pool);
  for (int i = 0; i < 3; ++i) t.step();
  const std::vector<float> before = t.atlas().params.values();
  const double lr_before = t.learning_rate();
  t.inject_faults(3, 1);
  t.step();  // the fault: nothing applied, state restored to the snapshot of iteration 0
  CHECK(t.iteration() == 3);
  CHECK(t.faults() == 1);
  CHECK(t.learning_rate() == Approx(0.5 * lr_before));
  CHECK(t.atlas().params.values() != before);  // back at the iteration-0 snapshot, not at 3
  for (float v : t.atlas().params.values()) REQUIRE(std::isfinite(v));
  t.step();
  CHECK(t.iteration() == 4);
  CHECK(std::isfinite(t.last().total));
}

TEST_CASE("trainer: repeated faults stop with NumericalFault", "[trainer]") {
  const Block<double> pool = sphere_pool(2000, 1);
  FitOptions o = small_options();
  o.max_faults = 3;
  Trainer t(o, pool);
  t.step();
  t.inject_faults(1, 100);
  for (int i = 0; i < 3; ++i) t.step();  // three recoveries
  CHECK(t.faults() == 3);
  CHECK_THROWS_AS(t.step(), NumericalFault);  // the fourth in a row gives up
  CHECK(t.iteration() == 1);
  for (float v : t.atlas().params.values()) REQUIRE(std::isfinite(v));
}

TEST_CASE("trainer: dense L_6D is seeded and learns the unit sphere", "[trainer]") {
  const Block<double> pool = sphere_pool(20000, 3);
  FitOptions o = small_options();
  o.dense_surface = true;
  Trainer a(o, pool), b(o, pool);
  a.step();
  b.step();
  REQUIRE(a.last().total == b.last().total);
  const double initial = a.last().surface;
  while (!a.finished()) a.step();
  INFO("dense L_6D after 400 iterations " << a.last().surface << ", initial " << initial);
  CHECK(a.last().surface < 0.1 * initial);
  // The surface itself: samples of P mapped by phi lie near the unit sphere
  // with outward normals.
  const Block<double> uv = a.atlas().params.value(a.atlas().domain.means()).cast<double>();
  Block<double> points, normals;
  evaluate_surface(a.atlas(), uv, points, normals, 0);
  double radial = 0, facing = 0;
  for (Index i = 0; i < points.rows(); ++i) {
    radial += std::abs(points.row(i).norm() - 1.0);
    facing += normals.row(i).dot(points.row(i).normalized());
  }
  radial /= double(points.rows());
  facing /= double(points.rows());
  INFO("mean | |phi(mu)| - 1 | = " << radial << ", mean n . x = " << facing);
  CHECK(radial < 0.05);
  CHECK(facing > 0.9);
}
