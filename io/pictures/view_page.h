// The viewer page of `jsatlas view`: one self-contained HTML file (three.js and
// every array inlined) that shows each shape of a run, turnable, coloured by its
// UVs, beside the 2D domain, and for a collection carries a clicked vertex to
// every other shape. This file only packs plain arrays into the page; what goes
// in them (charts, correspondences, metrics) is computed by the caller.
// The HTML/JS template is io/pictures/view_page.html, embedded at build time.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/block.h"
#include "io/geometry/mesh.h"
#include "io/pictures/image.h"

namespace jsa {

struct ViewShape {
  std::string name;        // shown above the shape (e.g. the input's file name)
  Block<double> vertices;  // V x 3, the input in its unit frame (every shape is shown in its own)
  Faces faces;             // F x 3; 0 x 3 for a point cloud (then shown as points)
  Block<double> uv;  // V x 2 texture-frame coordinates of psi at each vertex; 0 x 2 if no chart
  Block<double> domain_vertices;  // D x 3, phi of the meshed domain's vertices (unit frame)
  Faces domain_faces;             // the meshed domain's triangles (shared by every shape)
  Block<double> domain_uv;        // D x 2 texture-frame coordinates of those vertices
  // correspondence[j][k]: the vertex of shape j's input nearest to phi_j(psi_this(vertex k));
  // empty for j == this shape (and for a single shape).
  std::vector<std::vector<int>> correspondence;
  std::vector<int> keypoints;  // vertex index of keypoint m (empty: no keypoints given)
  // keypoint_error[j][m]: |phi_j(psi_this(keypoint m)) - keypoint m of j| in j's unit frame.
  std::vector<std::vector<double>> keypoint_error;
};

struct ViewDomain {
  Block<double> means;  // K x 2 Gaussian means of P, texture-frame coordinates
  double sigma = 0;     // their common sigma, in texture-frame units
};

struct ViewCurves {  // losses.csv: one column per term
  std::vector<std::string> names;
  std::vector<double> iterations;
  std::vector<std::vector<double>> values;  // values[c][row]
};

struct ViewTableRow {
  std::string group, key, value;  // e.g. "eval.json", "chamfer_l2", "3.4e-3"
};

struct ViewPage {
  std::string title;
  std::vector<ViewShape> shapes;
  ViewDomain domain;
  Image texture;  // the run's texture (the MTLs' image); empty: the page shows none
  ViewCurves curves;
  std::vector<ViewTableRow> table;
};

// three.js as Debian's libjs-three ships it (non-module builds).
struct ThreeJs {
  std::string three;           // three.min.js
  std::string orbit_controls;  // OrbitControls.js, the form that attaches THREE.OrbitControls
};

// Reads three.min.js and OrbitControls.js from `dir` (empty: /usr/share/javascript/three).
// Throws InputError naming the libjs-three package if they are missing.
ThreeJs read_three_js(const std::string& dir = "");

// The whole page. Arrays are quantised (positions and UVs to 16 bits over their
// bounding box, indices to 16 or 32 bits) and base64-encoded.
std::string view_page_html(const ViewPage& page, const ThreeJs& three);

// Bytes as base64 (RFC 4648, with padding).
std::string base64(const std::uint8_t* data, std::size_t size);

}  // namespace jsa
