// Example: the Chamfer distance of Eq. (6) between two point sets
// (losses/chamfer.h): as a tape op with its gradient, as a plain function with
// the matches, against an obvious double loop, and through check_gradients.
// Exits non-zero if any of them disagree.
#include <cmath>
#include <cstdio>
#include <exception>

#include "engine/gradcheck.h"
#include "engine/rng.h"
#include "losses/chamfer.h"

using namespace jsa;

constexpr double kPi = 3.14159265358979323846;

// The oracle, straight from Eq. (6): mean over X of the squared distance to the
// nearest y, plus the mean over Y of the squared distance to the nearest x.
double chamfer_by_hand(const Block<double>& x, const Block<double>& y) {
  auto one_way = [](const Block<double>& a, const Block<double>& b) {
    double total = 0;
    for (Index i = 0; i < a.rows(); ++i)
      total += (b.rowwise() - a.row(i)).rowwise().squaredNorm().minCoeff();
    return total / double(a.rows());
  };
  return one_way(x, y) + one_way(y, x);
}

int main() try {
  // X: 200 points on the unit circle; Y: 150 points on a circle of radius 1.2,
  // shifted. Random angles keep the nearest neighbours free of ties.
  Rng rng(3);
  Block<double> x(200, 2), y(150, 2);
  for (Index i = 0; i < x.rows(); ++i) {
    const double a = rng.uniform(0, 2 * kPi);
    x.row(i) << std::cos(a), std::sin(a);
  }
  for (Index j = 0; j < y.rows(); ++j) {
    const double a = rng.uniform(0, 2 * kPi);
    y.row(j) << 0.1 + 1.2 * std::cos(a), 1.2 * std::sin(a);
  }

  Tape<double> t;
  const Var vx = t.variable(x), vy = t.constant(y);  // gradient wanted for X only
  const Var cd = chamfer(t, vx, vy);
  t.backward(cd);
  ChamferMatches<double> matches;
  const double plain = chamfer_distance(x, y, &matches);
  const double by_hand = chamfer_by_hand(x, y);
  std::printf("CD(X, Y): tape %.10f  plain %.10f  by hand %.10f\n", t.scalar(cd), plain, by_hand);
  std::printf("x_0 = (% .3f, % .3f) is matched to y_%d, dCD/dx_0 = (% .5f, % .5f)\n", x(0, 0),
              x(0, 1), matches.x_to_y[0], t.grad(vx)(0, 0), t.grad(vx)(0, 1));

  // Central differences on both sets (the matches are fixed for steps this small).
  const GraphBuilder f = [](Tape<double>& t, const std::vector<Var>& in) {
    return chamfer(t, in[0], in[1]);
  };
  const GradCheckResult check = check_gradients(f, {x, y});
  std::printf("gradient check: %d entries, worst relative error %.2e\n", check.checked,
              check.worst_relative);
  if (!check.ok) std::printf("%s\n", check.report.c_str());

  const bool ok =
      std::abs(t.scalar(cd) - by_hand) < 1e-12 && std::abs(plain - by_hand) < 1e-12 && check.ok;
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {  // JSA_CHECK and InputError throw
  std::fprintf(stderr, "example_chamfer_points: %s\n", e.what());
  return 1;
}
