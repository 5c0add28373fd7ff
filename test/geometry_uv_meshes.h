// Small meshes made in code for the UV geometry tests: a flat grid, a
// hemisphere cap (a curved disk), a closed sphere, with per-vertex UVs chosen
// to be valid, folded or torn on purpose.
#pragma once
#include <cmath>

#include "io/geometry/mesh.h"

namespace test_uv {

struct UvInput {
  jsa::Block<double> positions;  // V x 3
  jsa::Faces faces;              // F x 3
  jsa::Block<double> uv;         // V x 2 (psi's stand-in)
};

// nx x ny cells over [0, 1]^2 at z = 0, counter-clockwise from +z; uv = (x, y).
inline UvInput flat_grid(int nx, int ny) {
  UvInput m;
  m.positions.resize((nx + 1) * (ny + 1), 3);
  m.uv.resize((nx + 1) * (ny + 1), 2);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const int v = j * (nx + 1) + i;
      m.positions.row(v) << double(i) / nx, double(j) / ny, 0;
      m.uv.row(v) << double(i) / nx, double(j) / ny;
    }
  m.faces.resize(2 * nx * ny, 3);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
      const int f = 2 * (j * nx + i);
      m.faces.row(f) << a, b, c;
      m.faces.row(f + 1) << a, c, d;
    }
  return m;
}

// The grid bent over a cylinder of radius 1/pi around the y axis (a half
// cylinder): still a disk, now curved, uv still (x, y) before bending.
inline UvInput half_cylinder(int nx, int ny) {
  UvInput m = flat_grid(nx, ny);
  for (jsa::Index v = 0; v < m.positions.rows(); ++v) {
    const double x = m.positions(v, 0), y = m.positions(v, 1), a = M_PI * x, r = 1 / M_PI;
    m.positions.row(v) << r * (1 - std::cos(a)), y, r * std::sin(a);
  }
  return m;
}

// Latitude-longitude sphere of radius 1 (poles shared), outward facing, uv
// the orthographic projection (x, y): the two hemispheres mirror each other.
inline UvInput sphere(int n_around, int n_rings) {
  UvInput m;
  const int V = 2 + n_around * (n_rings - 1);
  m.positions.resize(V, 3);
  m.positions.row(0) << 0, 0, 1;
  m.positions.row(V - 1) << 0, 0, -1;
  for (int r = 1; r < n_rings; ++r)
    for (int k = 0; k < n_around; ++k) {
      const double th = M_PI * r / n_rings, ph = 2 * M_PI * k / n_around;
      m.positions.row(1 + (r - 1) * n_around + k) << std::sin(th) * std::cos(ph),
          std::sin(th) * std::sin(ph), std::cos(th);
    }
  std::vector<Eigen::Vector3i> f;
  auto ring = [&](int r, int k) { return 1 + (r - 1) * n_around + (k % n_around); };
  for (int k = 0; k < n_around; ++k) f.push_back({0, ring(1, k), ring(1, k + 1)});
  for (int r = 1; r + 1 < n_rings; ++r)
    for (int k = 0; k < n_around; ++k) {
      f.push_back({ring(r, k), ring(r + 1, k), ring(r + 1, k + 1)});
      f.push_back({ring(r, k), ring(r + 1, k + 1), ring(r, k + 1)});
    }
  for (int k = 0; k < n_around; ++k)
    f.push_back({V - 1, ring(n_rings - 1, k + 1), ring(n_rings - 1, k)});
  m.faces.resize(jsa::Index(f.size()), 3);
  for (size_t i = 0; i < f.size(); ++i) m.faces.row(jsa::Index(i)) = f[i].transpose();
  m.uv = m.positions.leftCols(2);
  return m;
}

}  // namespace test_uv
