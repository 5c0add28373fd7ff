// A mesh made in code for the geometry tests that bend a surface without
// stretching it (intrinsic descriptors, functional maps).
#pragma once
#include "io/geometry/mesh.h"

namespace test_geometry {

// A strip of (nx x ny) squares of side 1/ny in the plane z = 0, two triangles
// each; with fold, the part x > crease turned up by 90 degrees about the line
// x = crease (a grid line: every edge keeps its length).
inline jsa::Mesh strip(int nx, int ny, bool fold, int crease) {
  jsa::Mesh m;
  const double side = 1.0 / ny;
  m.vertices.resize((nx + 1) * (ny + 1), 3);
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j) {
      const double x = i * side, y = j * side, c = crease * side;
      const jsa::Index v = i * (ny + 1) + j;
      if (fold && i > crease)
        m.vertices.row(v) << c, y, x - c;
      else
        m.vertices.row(v) << x, y, 0;
    }
  m.faces.resize(2 * nx * ny, 3);
  jsa::Index f = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const int a = i * (ny + 1) + j, b = a + ny + 1;
      m.faces.row(f++) << a, b, b + 1;
      m.faces.row(f++) << a, b + 1, a + 1;
    }
  return m;
}

}  // namespace test_geometry
