// Sphere, torus and capsule are surfaces of revolution of a profile curve in the
// (rho, z) half-plane; the cube is six grids. Orientation: a quad between ring i
// (lower on the profile) and ring i+1 is split as (i,j)(i,j+1)(i+1,j+1) and
// (i,j)(i+1,j+1)(i+1,j), whose normal (theta direction x profile direction) points outward.
#include "io/geometry/builtin_shapes.h"

#include <array>
#include <cmath>

#include "engine/check.h"

namespace jsa {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct ProfilePoint {
  double rho, z;                // distance from the z axis, height
  double normal_rho, normal_z;  // unit outward normal in the (rho, z) plane
};

class MeshBuilder {
 public:
  int add_vertex(const Eigen::RowVector3d& position, const Eigen::RowVector3d& normal) {
    positions_.push_back(position);
    normals_.push_back(normal.normalized());
    return int(positions_.size()) - 1;
  }
  void add_face(int a, int b, int c) { faces_.push_back({a, b, c}); }
  Mesh finish() const {
    Mesh mesh;
    mesh.vertices.resize(Index(positions_.size()), 3);
    mesh.normals.resize(Index(positions_.size()), 3);
    for (std::size_t i = 0; i < positions_.size(); ++i) {
      mesh.vertices.row(Index(i)) = positions_[i];
      mesh.normals.row(Index(i)) = normals_[i];
    }
    mesh.faces.resize(Index(faces_.size()), 3);
    for (std::size_t f = 0; f < faces_.size(); ++f)
      for (int k = 0; k < 3; ++k) mesh.faces(Index(f), k) = faces_[f][k];
    return mesh;
  }

 private:
  std::vector<Eigen::RowVector3d> positions_, normals_;
  std::vector<std::array<int, 3>> faces_;
};

// One ring of `around` vertices at profile point `p`, or a single vertex on the axis.
std::vector<int> add_ring(MeshBuilder& builder, const ProfilePoint& p, int around, bool pole) {
  std::vector<int> ring;
  const int count = pole ? 1 : around;
  for (int j = 0; j < count; ++j) {
    const double theta = 2 * kPi * j / around;
    const double c = pole ? 0.0 : std::cos(theta);
    const double s = pole ? 0.0 : std::sin(theta);
    const Eigen::RowVector3d position(p.rho * c, p.rho * s, p.z);
    const Eigen::RowVector3d normal(p.normal_rho * c, p.normal_rho * s, p.normal_z);
    ring.push_back(builder.add_vertex(position, normal));
  }
  return ring;
}

// Triangles between ring `low` and the ring `high` above it on the profile.
void connect_rings(MeshBuilder& builder, const std::vector<int>& low, const std::vector<int>& high,
                   int around) {
  for (int j = 0; j < around; ++j) {
    const int k = (j + 1) % around;
    if (low.size() == 1) {
      builder.add_face(low[0], high[k], high[j]);  // bottom pole fan
    } else if (high.size() == 1) {
      builder.add_face(high[0], low[j], low[k]);  // top pole fan
    } else {
      builder.add_face(low[j], low[k], high[k]);
      builder.add_face(low[j], high[k], high[j]);
    }
  }
}

// Revolves `profile` (ordered from bottom to top) around the z axis with `around`
// segments. If `closed_loop`, the last point connects back to the first (torus);
// otherwise the first and last points lie on the axis and become single poles.
Mesh revolve(const std::vector<ProfilePoint>& profile, int around, bool closed_loop) {
  MeshBuilder builder;
  const std::size_t count = profile.size();
  std::vector<std::vector<int>> rings;
  for (std::size_t i = 0; i < count; ++i) {
    const bool pole = !closed_loop && (i == 0 || i + 1 == count);
    rings.push_back(add_ring(builder, profile[i], around, pole));
  }
  const std::size_t bands = closed_loop ? count : count - 1;
  for (std::size_t i = 0; i < bands; ++i)
    connect_rings(builder, rings[i], rings[(i + 1) % count], around);
  return builder.finish();
}

// An arc of the circle of radius `radius` centred at (rho0, z0), angles from `start`
// to `end` (measured from the +rho axis towards +z), `steps` segments, both ends included.
void add_arc(std::vector<ProfilePoint>& profile, double rho0, double z0, double radius,
             double start, double end, int steps, bool include_end) {
  for (int i = 0; i <= steps; ++i) {
    if (i == steps && !include_end) break;
    const double phi = start + (end - start) * i / steps;
    const double c = std::cos(phi), s = std::sin(phi);
    profile.push_back({std::max(0.0, rho0 + radius * c), z0 + radius * s, c, s});
  }
}

Mesh sphere(int resolution) {
  std::vector<ProfilePoint> profile;
  add_arc(profile, 0, 0, 1, -kPi / 2, kPi / 2, resolution / 2, true);
  return revolve(profile, resolution, false);
}

Mesh torus(int resolution) {
  std::vector<ProfilePoint> profile;
  add_arc(profile, 1, 0, 0.4, 0, 2 * kPi, resolution / 2, false);
  return revolve(profile, resolution, true);
}

Mesh capsule(int resolution) {
  const double radius = 0.5, half_length = 0.5;
  const int cap_steps = resolution / 4, side_steps = resolution / 4;
  std::vector<ProfilePoint> profile;
  add_arc(profile, 0, -half_length, radius, -kPi / 2, 0, cap_steps, false);
  for (int i = 0; i < side_steps; ++i)
    profile.push_back({radius, -half_length + 2 * half_length * i / side_steps, 1, 0});
  add_arc(profile, 0, half_length, radius, 0, kPi / 2, cap_steps, true);
  return revolve(profile, resolution, false);
}

// Face (axis a, sign s): u x v = s e_a with u = e_b, v = e_c (s = +1) or swapped.
Mesh cube(int resolution) {
  const int n = resolution / 4;
  MeshBuilder builder;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {1, -1}) {
      Eigen::RowVector3d normal = Eigen::RowVector3d::Zero(), u = normal, v = normal;
      normal(axis) = sign;
      u((axis + (sign > 0 ? 1 : 2)) % 3) = 1;
      v((axis + (sign > 0 ? 2 : 1)) % 3) = 1;
      const int first = builder.add_vertex(0.5 * normal - 0.5 * u - 0.5 * v, normal);
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j)
          if (i + j > 0)
            builder.add_vertex(0.5 * normal + (double(i) / n - 0.5) * u + (double(j) / n - 0.5) * v,
                               normal);
      auto at = [&](int i, int j) { return first + i * (n + 1) + j; };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          builder.add_face(at(i, j), at(i + 1, j), at(i + 1, j + 1));
          builder.add_face(at(i, j), at(i + 1, j + 1), at(i, j + 1));
        }
    }
  return builder.finish();
}

}  // namespace

std::vector<std::string> builtin_shape_names() { return {"sphere", "torus", "cube", "capsule"}; }

Mesh builtin_shape(const std::string& name, int resolution) {
  if (resolution < 8)
    throw InputError("builtin shape '" + name + "': resolution " + std::to_string(resolution) +
                     " is below the minimum of 8");
  if (name == "sphere") return sphere(resolution);
  if (name == "torus") return torus(resolution);
  if (name == "cube") return cube(resolution);
  if (name == "capsule") return capsule(resolution);
  std::string valid;
  for (const std::string& known : builtin_shape_names())
    valid += (valid.empty() ? "" : ", ") + known;
  throw InputError("unknown builtin shape '" + name + "'; valid names: " + valid);
}

}  // namespace jsa
