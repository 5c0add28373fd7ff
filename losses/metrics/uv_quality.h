// How good is a UV map? Measures the parametrization S: UV -> 3D of a triangle
// mesh (from the 2D chart coordinates to the surface, the direction of the paper's
// phi): flips, degenerate and torn triangles, Sander et al. 2001 stretch (L2,
// Linf), symmetric Dirichlet energy, conformal distortion, UV overlap by
// rasterisation, seam length and chart count. Definitions: docs/uv-quality.md.
#pragma once
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "engine/block.h"
#include "io/geometry/mesh.h"

namespace jsa {

struct UvQualityOptions {
  // A triangle is torn when one of its edges is longer in UV (after scaling the
  // UVs to the total 3D area) than torn_ratio times in 3D: it straddles a cut.
  double torn_ratio = 10;
  // Pixels per side of the square the UV bounding box is rasterised into to
  // measure overlap (the longer side of the box spans all of them).
  int overlap_resolution = 1024;
};

// Triangle sets: a triangle is "degenerate" if its UV or 3D area is tiny, "torn"
// as above, and "measured" otherwise. Flips and all distortion numbers are over
// the measured triangles, weighted by 3D area. Every distortion number is of the
// Jacobian J = dS/d(s, t) (3 x 2), with singular values Gamma >= gamma, after
// the UVs are scaled so that total UV area = total 3D area; an isometry scores
// stretch 1, Dirichlet 4, conformal 1. NaN (null in JSON) if nothing is measured.
struct UvQuality {
  Index triangles = 0;               // F
  double area_3d = 0;                // sum of 3D triangle areas
  double area_uv = 0;                // sum of |UV triangle areas|, before scaling
  double uv_scale = 0;               // sqrt(area_3d / area_uv): the factor applied to the UVs
  Index measured = 0;                // triangles neither degenerate nor torn
  Index degenerate = 0;              // UV area < 1e-12 area_uv / F or 3D area < 1e-12 area_3d / F
  Index torn = 0;                    // some edge has |uv| * uv_scale > torn_ratio * |3D|
  double torn_area_fraction = 0;     // 3D area of torn triangles / area_3d
  std::vector<int> torn_faces;       // their indices, ascending
  bool mirrored = false;             // the majority orientation (by 3D area) has negative UV area
  Index flipped = 0;                 // measured triangles whose UV orientation is the minority one
  double flipped_area_fraction = 0;  // 3D area of flipped triangles / area_3d
  std::vector<int> flipped_faces;    // their indices, ascending
  double stretch_l2 = 0;             // sqrt(sum A3 (Gamma^2 + gamma^2) / 2 / sum A3), Sander et al.
  double stretch_linf = 0;           // max Gamma
  double symmetric_dirichlet = 0;    // mean over A3 of Gamma^2 + gamma^2 + Gamma^-2 + gamma^-2
  double conformal_distortion = 0;   // mean over A3 of Gamma / gamma: the angle distortion
  double area_distortion = 0;        // mean over A3 of max(Gamma gamma, 1 / (Gamma gamma))
  // Pixels covered by >= 2 UV triangles / pixels covered by >= 1; torn triangles
  // are not drawn (they span the cut and would cover the chart they cross).
  double overlap_ratio = 0;
  double seam_length = 0;         // 3D length of edges shared in 3D but not in UV
  Index charts = 0;               // components of faces joined through shared UV edges
  Index charts_without_torn = 0;  // the same with the torn faces left out
  // Sum of |UV triangle areas| (unscaled) / area of the box holding the UVs and
  // [0, 1]^2: the share of a unit-square texture the map uses.
  double packing_efficiency = 0;
};

// positions: V x 3; faces: F x 3 indices into positions; uv: U x 2; uv_faces:
// F x 3 indices into uv, corner for corner with faces (pass faces itself when
// the UVs are per vertex). Throws InputError on mismatched shapes or indices.
// Uses OpenMP; the result does not depend on the thread count.
UvQuality measure_uv_quality(const Block<double>& positions, const Faces& faces,
                             const Block<double>& uv, const Faces& uv_faces,
                             const UvQualityOptions& options = {});

// The report as JSON text (unmeasured numbers are null); no JSON type in the API.
std::string to_json(const UvQuality& q, int indent = 2);
std::string to_text(const UvQuality& q);  // a two-column table, one quantity per line

}  // namespace jsa
