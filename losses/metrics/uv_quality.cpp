#include "losses/metrics/uv_quality.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <tuple>
#include <utility>

#include "engine/check.h"
#include "engine/parallel.h"

namespace jsa {
namespace {

void check_inputs(const Block<double>& positions, const Faces& faces, const Block<double>& uv,
                  const Faces& uv_faces, const UvQualityOptions& options) {
  auto fail = [](const std::string& what) { throw InputError("measure_uv_quality: " + what); };
  if (positions.cols() != 3) fail("positions must have 3 columns");
  if (uv.cols() != 2) fail("uv must have 2 columns");
  if (faces.rows() != uv_faces.rows()) {
    fail("faces has " + std::to_string(faces.rows()) + " rows but uv_faces has " +
         std::to_string(uv_faces.rows()) + "; give one UV triangle per 3D triangle");
  }
  for (Index i = 0; i < positions.rows(); ++i) {
    if (!positions.row(i).allFinite()) fail("position " + std::to_string(i) + " is not finite");
  }
  for (Index i = 0; i < uv.rows(); ++i) {
    if (!uv.row(i).allFinite()) fail("uv " + std::to_string(i) + " is not finite");
  }
  auto check_indices = [&](const Faces& f, Index n, const char* name, const char* target) {
    for (Index r = 0; r < f.rows(); ++r) {
      for (int c = 0; c < 3; ++c) {
        if (f(r, c) < 0 || f(r, c) >= n) {
          fail(std::string(name) + " row " + std::to_string(r) + " refers to " + target + " " +
               std::to_string(f(r, c)) + ", but there are " + std::to_string(n));
        }
      }
    }
  };
  check_indices(faces, positions.rows(), "faces", "position");
  check_indices(uv_faces, uv.rows(), "uv_faces", "uv");
  if (!(options.torn_ratio > 0)) fail("torn_ratio must be positive");
  if (options.overlap_resolution < 1 || options.overlap_resolution > 65536) {
    fail("overlap_resolution must be in [1, 65536]");
  }
}

// Union-find over faces, with path halving; the root is the smallest index of
// the set, so the partition (and anything derived from it) is deterministic.
struct FaceSets {
  std::vector<int> parent;
  explicit FaceSets(Index n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(int a, int b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// One corner of a face, and the undirected edge from it to the next corner,
// keyed by its two endpoint indices (smaller first).
struct EdgeUse {
  int lo, hi, face, corner;
  bool operator<(const EdgeUse& o) const {
    return std::tie(lo, hi, face, corner) < std::tie(o.lo, o.hi, o.face, o.corner);
  }
};

// Every edge of every face keyed by the indices in `f`, sorted so that uses of
// the same edge are adjacent. Edges whose two ends are the same index are left out.
std::vector<EdgeUse> sorted_edges(const Faces& f) {
  std::vector<EdgeUse> e;
  e.reserve(3 * f.rows());
  for (Index r = 0; r < f.rows(); ++r) {
    for (int c = 0; c < 3; ++c) {
      const int a = f(r, c), b = f(r, (c + 1) % 3);
      if (a != b) e.push_back({std::min(a, b), std::max(a, b), int(r), c});
    }
  }
  std::sort(e.begin(), e.end());
  return e;
}

// Calls group(begin, end) on each run of uses of one edge.
template <class G>
void for_each_edge(const std::vector<EdgeUse>& e, G&& group) {
  for (size_t b = 0; b < e.size();) {
    size_t end = b + 1;
    while (end < e.size() && e[end].lo == e[b].lo && e[end].hi == e[b].hi) ++end;
    group(b, end);
    b = end;
  }
}

// Overlap by scanline rasterisation. The UVs of the drawn triangles are mapped
// to pixel units: the bounding box's longer side spans `resolution` pixels,
// pixel (i, j) has its centre at (i + 1/2, j + 1/2). A triangle covers the
// centres with y in [y_min, y_max) and, on each row, x in [x_left, x_right):
// half-open on both axes, with each edge's crossing computed the same way from
// both of its triangles, so a centre on an edge shared by two triangles that lie
// side by side belongs to exactly one of them and seams never count as overlap.
struct Coverage {
  long long covered = 0;     // pixel centres inside >= 1 triangle
  long long overlapped = 0;  // pixel centres inside >= 2 triangles
};

Coverage rasterise_coverage(const Block<double>& uv, const Faces& uv_faces,
                            const std::vector<char>& drawn, int resolution) {
  const Index F = uv_faces.rows();
  Eigen::RowVector2d lo = Eigen::RowVector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::RowVector2d hi = -lo;
  for (Index f = 0; f < F; ++f) {
    if (!drawn[f]) continue;
    for (int c = 0; c < 3; ++c) {
      lo = lo.cwiseMin(uv.row(uv_faces(f, c)));
      hi = hi.cwiseMax(uv.row(uv_faces(f, c)));
    }
  }
  const double extent = (hi - lo).maxCoeff();
  if (!(extent > 0)) return {};  // nothing drawn, or everything on one point
  const double to_pixels = resolution / extent;
  const double R = resolution;
  auto pixel = [&](int f, int c) -> Eigen::Vector2d {
    return ((uv.row(uv_faces(f, c)) - lo) * to_pixels).transpose();
  };
  // First pixel index i with i + 1/2 >= x, clamped to [0, R].
  auto first_centre_at_or_after = [&](double x) {
    return int(std::ceil(std::clamp(x - 0.5, 0.0, R)));
  };

  // Triangles listed per row they touch (compressed rows: row j owns
  // in_row[row_begin[j] .. row_begin[j + 1])), in ascending face order.
  std::vector<int> first_row(F, 0), end_row(F, 0);
  std::vector<Index> row_begin(resolution + 1, 0);
  for (Index f = 0; f < F; ++f) {
    if (!drawn[f]) continue;
    double y0 = std::numeric_limits<double>::infinity(), y1 = -y0;
    for (int c = 0; c < 3; ++c) {
      y0 = std::min(y0, pixel(f, c).y());
      y1 = std::max(y1, pixel(f, c).y());
    }
    first_row[f] = first_centre_at_or_after(y0);
    end_row[f] = first_centre_at_or_after(y1);
    for (int j = first_row[f]; j < end_row[f]; ++j) ++row_begin[j + 1];
  }
  for (int j = 0; j < resolution; ++j) row_begin[j + 1] += row_begin[j];
  std::vector<int> in_row(row_begin[resolution]);
  {
    std::vector<Index> next(row_begin.begin(), row_begin.end() - 1);
    for (Index f = 0; f < F; ++f) {
      for (int j = first_row[f]; j < end_row[f]; ++j) in_row[next[j]++] = int(f);
    }
  }

  // Rows are independent: each writes its own two counters.
  std::vector<long long> row_covered(resolution, 0), row_overlapped(resolution, 0);
  parallel_rows(
      resolution,
      [&](Index row0, Index row1) {
        std::vector<int> hits(resolution);  // triangles covering each pixel of the row
        for (Index j = row0; j < row1; ++j) {
          std::fill(hits.begin(), hits.end(), 0);
          const double y = double(j) + 0.5;
          for (Index k = row_begin[j]; k < row_begin[j + 1]; ++k) {
            const int f = in_row[k];
            double x[2];
            int crossings = 0;
            for (int c = 0; c < 3; ++c) {
              Eigen::Vector2d a = pixel(f, c), b = pixel(f, (c + 1) % 3);
              if (a.y() == b.y()) continue;        // horizontal: the rows above and below decide
              if (a.y() > b.y()) std::swap(a, b);  // the same order from both triangles
              if (y < a.y() || y >= b.y() || crossings == 2) continue;
              x[crossings++] = a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
            }
            if (crossings != 2) continue;
            const int i0 = first_centre_at_or_after(std::min(x[0], x[1]));
            const int i1 = first_centre_at_or_after(std::max(x[0], x[1]));
            for (int i = i0; i < i1; ++i) ++hits[i];
          }
          for (int i = 0; i < resolution; ++i) {
            row_covered[j] += hits[i] >= 1;
            row_overlapped[j] += hits[i] >= 2;
          }
        }
      },
      8);
  Coverage out;
  for (int j = 0; j < resolution; ++j) {
    out.covered += row_covered[j];
    out.overlapped += row_overlapped[j];
  }
  return out;
}

}  // namespace

UvQuality measure_uv_quality(const Block<double>& positions, const Faces& faces,
                             const Block<double>& uv, const Faces& uv_faces,
                             const UvQualityOptions& options) {
  check_inputs(positions, faces, uv, uv_faces, options);
  const Index F = faces.rows();
  UvQuality q;
  q.triangles = F;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  q.stretch_l2 = q.stretch_linf = q.symmetric_dirichlet = q.conformal_distortion =
      q.area_distortion = nan;
  if (F == 0) return q;

  auto p = [&](Index f, int c) -> Eigen::Vector3d {
    return positions.row(faces(f, c)).transpose();
  };
  auto t = [&](Index f, int c) -> Eigen::Vector2d { return uv.row(uv_faces(f, c)).transpose(); };

  // Per-face areas: 3D area, and the signed UV area (positive counter-clockwise).
  std::vector<double> area3(F), signed_area_uv(F);
  parallel_rows(F, [&](Index f0, Index f1) {
    for (Index f = f0; f < f1; ++f) {
      area3[f] = 0.5 * (p(f, 1) - p(f, 0)).cross(p(f, 2) - p(f, 0)).norm();
      const Eigen::Vector2d e1 = t(f, 1) - t(f, 0), e2 = t(f, 2) - t(f, 0);
      signed_area_uv[f] = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
    }
  });
  for (Index f = 0; f < F; ++f) {
    q.area_3d += area3[f];
    q.area_uv += std::abs(signed_area_uv[f]);
  }
  // s' = uv_scale * s makes the UV area equal the 3D area, so that the
  // distortion numbers do not depend on the units of the UVs.
  q.uv_scale = q.area_uv > 0 ? std::sqrt(q.area_3d / q.area_uv) : 1.0;

  // Classify: degenerate (tiny area either side), torn (an edge far longer in
  // UV than in 3D), measured (the rest). Then the Jacobian of S on each
  // measured face: with P = [p1 - p0, p2 - p0] (3 x 2) and Q = [s1 - s0, s2 - s0]
  // (2 x 2, scaled UVs), S is affine on the face and J = [S_s, S_t] = P Q^-1.
  // Its singular values are the square roots of the eigenvalues of J^T J =
  // [[a, b], [b, c]]: Gamma^2 = (a + c + sqrt((a - c)^2 + 4 b^2)) / 2, and,
  // without cancellation, gamma = (A3 / A_uv') / Gamma since Gamma gamma = |S_s x S_t|.
  const double tiny_uv = 1e-12 * q.area_uv / double(F), tiny_3d = 1e-12 * q.area_3d / double(F);
  std::vector<char> degenerate(F), torn(F);
  std::vector<double> sigma_max(F, 0), sigma_min(F, 0);
  parallel_rows(F, [&](Index f0, Index f1) {
    for (Index f = f0; f < f1; ++f) {
      const double a_uv = std::abs(signed_area_uv[f]);
      degenerate[f] = a_uv <= 0 || a_uv < tiny_uv || area3[f] <= 0 || area3[f] < tiny_3d;
      torn[f] = false;
      for (int c = 0; c < 3; ++c) {
        const double len_uv = q.uv_scale * (t(f, (c + 1) % 3) - t(f, c)).norm();
        const double len_3d = (p(f, (c + 1) % 3) - p(f, c)).norm();
        if (len_uv > options.torn_ratio * len_3d) torn[f] = true;
      }
      if (degenerate[f] || torn[f]) continue;
      Eigen::Matrix<double, 3, 2> P;
      P << p(f, 1) - p(f, 0), p(f, 2) - p(f, 0);
      Eigen::Matrix2d Q;
      Q << t(f, 1) - t(f, 0), t(f, 2) - t(f, 0);
      Q *= q.uv_scale;
      const Eigen::Matrix<double, 3, 2> J = P * Q.inverse();
      const double a = J.col(0).squaredNorm(), b = J.col(0).dot(J.col(1));
      const double c = J.col(1).squaredNorm();
      sigma_max[f] = std::sqrt(0.5 * (a + c + std::sqrt((a - c) * (a - c) + 4 * b * b)));
      const double area_ratio = area3[f] / (q.uv_scale * q.uv_scale * std::abs(signed_area_uv[f]));
      sigma_min[f] = area_ratio / sigma_max[f];
    }
  });

  // Orientation: the sign of the UV area carrying more 3D area is "correct"
  // (a whole map may be a mirror image); the other sign is flipped.
  double positive = 0, negative = 0;
  for (Index f = 0; f < F; ++f) {
    if (degenerate[f] || torn[f]) continue;
    (signed_area_uv[f] > 0 ? positive : negative) += area3[f];
  }
  q.mirrored = negative > positive;

  double measured_area = 0, flipped_area = 0, torn_area = 0;
  double sum_l2 = 0, sum_dirichlet = 0, sum_conformal = 0, sum_area = 0, max_sigma = 0;
  for (Index f = 0; f < F; ++f) {
    if (degenerate[f]) ++q.degenerate;
    if (torn[f]) {
      ++q.torn;
      torn_area += area3[f];
      q.torn_faces.push_back(int(f));
    }
    if (degenerate[f] || torn[f]) continue;
    ++q.measured;
    if ((signed_area_uv[f] > 0) == q.mirrored) {
      ++q.flipped;
      flipped_area += area3[f];
      q.flipped_faces.push_back(int(f));
    }
    const double G = sigma_max[f], g = sigma_min[f], w = area3[f];
    measured_area += w;
    sum_l2 += w * 0.5 * (G * G + g * g);
    sum_dirichlet += w * (G * G + g * g + 1 / (G * G) + 1 / (g * g));
    sum_conformal += w * G / g;
    sum_area += w * std::max(G * g, 1 / (G * g));  // Gamma gamma: 3D area / scaled UV area
    max_sigma = std::max(max_sigma, G);
  }
  if (q.area_3d > 0) {
    q.torn_area_fraction = torn_area / q.area_3d;
    q.flipped_area_fraction = flipped_area / q.area_3d;
  }
  if (q.measured > 0 && measured_area > 0) {
    q.stretch_l2 = std::sqrt(sum_l2 / measured_area);
    q.stretch_linf = max_sigma;
    q.symmetric_dirichlet = sum_dirichlet / measured_area;
    q.conformal_distortion = sum_conformal / measured_area;
    q.area_distortion = sum_area / measured_area;
  }
  // Packing: UV area over the box that holds the UVs and the unit square.
  if (uv.rows() > 0) {
    const Eigen::RowVector2d lo = uv.colwise().minCoeff().cwiseMin(Eigen::RowVector2d(0, 0));
    const Eigen::RowVector2d hi = uv.colwise().maxCoeff().cwiseMax(Eigen::RowVector2d(1, 1));
    q.packing_efficiency = q.area_uv / ((hi(0) - lo(0)) * (hi(1) - lo(1)));
  }

  // Overlap: every triangle except the torn ones (degenerate ones cover nothing).
  std::vector<char> drawn(F);
  for (Index f = 0; f < F; ++f) drawn[f] = !torn[f];
  const Coverage cover = rasterise_coverage(uv, uv_faces, drawn, options.overlap_resolution);
  q.overlap_ratio = cover.covered > 0 ? double(cover.overlapped) / double(cover.covered) : 0.0;

  // Seams: a 3D edge used by exactly two faces, whose ends carry different UV
  // indices in the two faces.
  const std::vector<EdgeUse> edges_3d = sorted_edges(faces);
  for_each_edge(edges_3d, [&](size_t b, size_t e) {
    if (e - b != 2) return;
    const EdgeUse& u = edges_3d[b];
    const EdgeUse& v = edges_3d[b + 1];
    // UV index at the 3D vertex `vertex` of face `face`, seen from its corner `corner` or the next.
    auto uv_at = [&](const EdgeUse& use, int vertex) {
      const int c = faces(use.face, use.corner) == vertex ? use.corner : (use.corner + 1) % 3;
      return uv_faces(use.face, c);
    };
    if (uv_at(u, u.lo) != uv_at(v, u.lo) || uv_at(u, u.hi) != uv_at(v, u.hi)) {
      q.seam_length += (positions.row(u.lo) - positions.row(u.hi)).norm();
    }
  });

  // Charts: faces joined through UV edges they share; once over all faces,
  // once over the faces that are not torn.
  const std::vector<EdgeUse> edges_uv = sorted_edges(uv_faces);
  FaceSets all(F), untorn(F);
  for_each_edge(edges_uv, [&](size_t b, size_t e) {
    int first_untorn = -1;
    for (size_t k = b; k < e; ++k) {
      const int f = edges_uv[k].face;
      all.join(edges_uv[b].face, f);
      if (torn[f]) continue;
      if (first_untorn < 0) first_untorn = f;
      untorn.join(first_untorn, f);
    }
  });
  for (Index f = 0; f < F; ++f) {
    q.charts += all.find(int(f)) == int(f);
    q.charts_without_torn += !torn[f] && untorn.find(int(f)) == int(f);
  }
  return q;
}

std::string to_json(const UvQuality& q, int indent) {
  // NaN has no JSON spelling: a number that was not measured is written as null.
  auto number = [](double v) { return std::isnan(v) ? nlohmann::json() : nlohmann::json(v); };
  nlohmann::json j;
  j["map"] = "S: uv -> 3D, uv scaled to the 3D area";
  j["triangles"] = q.triangles;
  j["area_3d"] = q.area_3d;
  j["area_uv"] = q.area_uv;
  j["uv_scale"] = q.uv_scale;
  j["measured"] = q.measured;
  j["degenerate"] = q.degenerate;
  j["torn"] = q.torn;
  j["torn_area_fraction"] = q.torn_area_fraction;
  j["torn_faces"] = q.torn_faces;
  j["mirrored"] = q.mirrored;
  j["flipped"] = q.flipped;
  j["flipped_area_fraction"] = q.flipped_area_fraction;
  j["flipped_faces"] = q.flipped_faces;
  j["stretch_l2"] = number(q.stretch_l2);
  j["stretch_linf"] = number(q.stretch_linf);
  j["symmetric_dirichlet"] = number(q.symmetric_dirichlet);
  j["conformal_distortion"] = number(q.conformal_distortion);
  j["area_distortion"] = number(q.area_distortion);
  j["packing_efficiency"] = q.packing_efficiency;
  j["overlap_ratio"] = q.overlap_ratio;
  j["seam_length"] = q.seam_length;
  j["charts"] = q.charts;
  j["charts_without_torn"] = q.charts_without_torn;
  return j.dump(indent);
}

std::string to_text(const UvQuality& q) {
  std::ostringstream s;
  auto row = [&](const char* name, const std::string& value, const char* ideal) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-22s %14s", name, value.c_str());
    s << line << (*ideal ? "   " : "") << ideal << "\n";
  };
  auto num = [](double v) {
    char b[64];
    std::snprintf(b, sizeof b, "%.6g", v);
    return std::string(b);
  };
  auto count_and_share = [&](Index n, double fraction) {
    char b[64];
    std::snprintf(b, sizeof b, "%lld (%.3g%%)", (long long)n, 100 * fraction);
    return std::string(b);
  };
  s << "UV quality of S: uv -> 3D (uv scaled by " << num(q.uv_scale) << " to the 3D area)\n";
  row("triangles", std::to_string(q.triangles), "");
  row("area 3D", num(q.area_3d), "");
  row("area UV", num(q.area_uv), "before scaling");
  row("degenerate", std::to_string(q.degenerate), "ideal 0");
  row("torn (of 3D area)", count_and_share(q.torn, q.torn_area_fraction), "ideal 0; cut edges");
  row("flipped (of 3D area)", count_and_share(q.flipped, q.flipped_area_fraction), "ideal 0");
  row("mirrored", q.mirrored ? "yes" : "no", "whole map reflected; harmless");
  row("measured", std::to_string(q.measured), "neither degenerate nor torn");
  row("stretch L2", num(q.stretch_l2), "ideal 1");
  row("stretch Linf", num(q.stretch_linf), "ideal 1");
  row("symmetric Dirichlet", num(q.symmetric_dirichlet), "ideal 4");
  row("conformal distortion", num(q.conformal_distortion), "ideal 1; angle distortion");
  row("area distortion", num(q.area_distortion), "ideal 1");
  row("overlap ratio", num(q.overlap_ratio), "ideal 0; torn not drawn");
  row("seam length", num(q.seam_length), "3D length of UV cuts");
  row("charts", std::to_string(q.charts), "");
  row("charts without torn", std::to_string(q.charts_without_torn), "");
  row("packing efficiency", num(q.packing_efficiency), "UV area / box with the unit square");
  return s.str();
}

}  // namespace jsa
