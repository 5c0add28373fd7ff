#include "io/geometry/valid_uv.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "engine/check.h"
#include "io/geometry/uv_align.h"
#include "io/geometry/uv_injectivity.h"
#include "io/geometry/uv_repair.h"

namespace jsa {
namespace {

struct ChartOut {
  std::vector<int> faces;  // input faces
  Faces local;             // into uv
  Block<double> uv;        // final (aligned) UVs
  Block<double> uv3;       // the same before alignment, at the 3D scale (what the packer takes)
  double area = 0;         // UV area
  ChartStart start = ChartStart::failed;
  bool reverted = false, mirrored = false, single = false;
  int iterations = 0;
  double area3 = 0, energy_start = 0, energy_end = 0;
};

double uv_area(const Faces& local, const Block<double>& uv) {
  double a = 0;
  for (Index f = 0; f < local.rows(); ++f)
    a += 0.5 *
         std::abs(signed_area2(uv.row(local(f, 0)).transpose(), uv.row(local(f, 1)).transpose(),
                               uv.row(local(f, 2)).transpose()));
  return a;
}

// One face on its own: laid out isometrically, then similar to psi's triangle.
ChartOut single_face(const Block<double>& positions, const Faces& faces, const Block<double>& psi,
                     int f) {
  ChartOut c;
  c.faces = {f};
  c.local.resize(1, 3);
  c.local << 0, 1, 2;
  c.single = true;
  Block<double> p(3, 3), target(3, 2);
  for (int k = 0; k < 3; ++k)
    p.row(k) = positions.row(faces(f, k)), target.row(k) = psi.row(faces(f, k));
  const Eigen::Vector3d e1 = (p.row(1) - p.row(0)).transpose(),
                        e2 = (p.row(2) - p.row(0)).transpose();
  const double l1 = e1.norm();
  c.uv = Block<double>::Zero(3, 2);
  c.uv.row(1) << l1, 0;
  c.uv.row(2) << e1.dot(e2) / l1, e1.cross(e2).norm() / l1;
  c.uv3 = c.uv;
  c.uv = fit_similarity(c.uv, target).apply(c.uv);
  c.area = uv_area(c.local, c.uv);
  c.start = ChartStart::tutte;
  return c;
}

// What one chart came to: charts done, or its two halves to do again.
struct ChartOutcome {
  std::vector<ChartOut> done;
  std::vector<ChartMesh> halves;
};

// psi_per_3d: psi's length per 3D length over the mesh's usable faces.
ChartOutcome process_chart(const Block<double>& positions, const Faces& faces,
                           const Block<double>& psi_uv, const ChartMesh& m, const ValidUvOptions& o,
                           int depth, double psi_per_3d) {
  const SlimOptions& slim_options = o.slim;
  const Index Vc = Index(m.vertex.size());
  Block<double> pos(Vc, 3), psi(Vc, 2);
  for (Index v = 0; v < Vc; ++v) {
    pos.row(v) = positions.row(m.vertex[size_t(v)]);
    psi.row(v) = psi_uv.row(m.vertex[size_t(v)]);
  }
  if (m.orientation < 0) psi.col(0) *= -1;  // a mirrored chart: its psi UVs, unmirrored
  // Bring psi to the 3D scale over the usable faces so SLIM starts near its optimum.
  double a3 = 0, a2 = 0;
  for (Index f = 0; f < m.local.rows(); ++f) {
    const Eigen::RowVector3d p0 = pos.row(m.local(f, 0)), p1 = pos.row(m.local(f, 1)),
                             p2 = pos.row(m.local(f, 2));
    const double area3 = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    if (!m.usable[size_t(f)]) continue;
    a3 += area3;
    a2 += 0.5 * std::abs(signed_area2(psi.row(m.local(f, 0)).transpose(),
                                      psi.row(m.local(f, 1)).transpose(),
                                      psi.row(m.local(f, 2)).transpose()));
  }
  const double scale = a2 > 0 && a3 > 0 ? std::sqrt(a3 / a2) : 1.0;
  // A large chart, mostly usable, whose psi UVs overlap themselves across it
  // (its usable parts land on one another) and cannot be repaired: halves are
  // likelier to keep psi's layout than Tutte's circle is to recover it, so it
  // is split before Tutte is computed.
  const bool split_first =
      depth < o.max_split_depth && Index(m.faces.size()) >= o.split_before_tutte_faces &&
      std::count(m.usable.begin(), m.usable.end(), 1) > Index(m.faces.size()) / 2;
  ChartStartResult start;
  if (m.inherited_uv.rows() == Vc && m.inherited_uv.allFinite() &&
      chart_is_injective(m.local, m.inherited_uv)) {
    start.uv = m.inherited_uv;  // its part of the parent's map (already at the 3D scale)
    start.start = ChartStart::inherited;
  } else {
    start = start_chart_uv(pos, m.local, scale * psi, m.usable, 3, /*tutte=*/!split_first);
  }
  // The chart cut in two (each half is done again by the caller); empty if it cannot be cut.
  auto halves = [&](const Block<double>* inherit = nullptr) {
    ChartOutcome out;
    out.halves = split_chart(m, &positions, inherit);
    if (out.halves.size() != 2) out.halves.clear();
    return out;
  };
  if (start.start == ChartStart::failed && split_first) {
    ChartOutcome out = halves();
    if (!out.halves.empty()) return out;
    start = start_chart_uv(pos, m.local, scale * psi, m.usable);
  }
  if (start.start == ChartStart::failed) {
    ChartOutcome out;
    for (int f : m.faces) out.done.push_back(single_face(positions, faces, psi_uv, f));
    return out;
  }
  ChartOut c;
  c.faces = m.faces;
  c.local = m.local;
  c.start = start.start;
  c.mirrored = m.orientation < 0;
  Block<double> uv = start.uv;
  // Each iterate keeps every triangle positive; the boundary is checked too, so
  // the last iterate whose boundary is simple (hence injective) is kept.
  const SlimReport rep =
      slim_symmetric_dirichlet(pos, m.local, uv, slim_options,
                               [&, loops = boundary_loops(m.local, Vc)](const Block<double>& x) {
                                 return !boundary_self_intersects(loops, x);
                               });
  c.iterations = rep.iterations;
  for (Index f = 0; f < m.local.rows(); ++f) {
    const Eigen::RowVector3d p0 = pos.row(m.local(f, 0)), p1 = pos.row(m.local(f, 1)),
                             p2 = pos.row(m.local(f, 2));
    c.area3 += 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }
  c.energy_start = rep.energy_start, c.energy_end = rep.energy_end;
  if (!chart_is_injective(m.local, uv)) {  // SLIM keeps triangles positive, not the boundary simple
    uv = start.uv;
    c.reverted = true;
    c.energy_end = c.energy_start;
  }
  // Align onto psi (the unmirrored one), weighting each vertex by the usable
  // area around it: where psi was unusable its UVs say nothing.
  std::vector<double> w(size_t(Vc), 0);
  for (Index f = 0; f < m.local.rows(); ++f)
    if (m.usable[size_t(f)])
      for (int k = 0; k < 3; ++k) w[size_t(m.local(f, k))] += 1;
  if (std::all_of(w.begin(), w.end(), [](double x) { return x == 0; }))
    for (Index v = 0; v < Vc; ++v) w[size_t(v)] = psi.row(v).allFinite() ? 1.0 : 0.0;
  auto place = [&](const Block<double>& map) {
    c.uv3 = map;
    // The scale within 2x of psi's mean: where psi is unusable over most of
    // the chart its UVs are folded or collapsed, and the fitted scale with them
    // (a teddy's chart came out 5x too small).
    c.uv = fit_similarity(map, psi, w, 0.5 * psi_per_3d, 2 * psi_per_3d).apply(map);
    if (m.orientation < 0) {
      // Back to psi's place: the mirrored target's centroid is psi's mirrored.
      double sw = 0, cx = 0;
      for (Index v = 0; v < Vc; ++v)
        if (w[size_t(v)] > 0) sw += w[size_t(v)], cx += w[size_t(v)] * psi(v, 0);
      c.uv.col(0).array() -= 2 * cx / sw;
    }
    c.area = uv_area(c.local, c.uv);
  };
  place(uv);
  // Still far from an isometry: SLIM was stopped by the boundary (the chart's
  // flattening overlaps itself) or the chart cannot flatten. SLIM again with
  // the boundary free, from where it stopped: if that comes out injective the
  // chart is done; else it is cut in two and each half starts from its part of
  // that map (a half of an overlapping flattening is usually injective, and
  // already near its optimum).
  if (c.energy_end > o.split_energy && depth < o.max_split_depth && rep.time_capped &&
      !c.reverted) {
    // SLIM ran out of time, not out of descent (a very large chart): its
    // injective map is the halves' start.
    ChartOutcome out = halves(&c.uv3);
    if (!out.halves.empty()) return out;
  } else if (c.energy_end > o.split_energy && depth < o.max_split_depth) {
    Block<double> free_uv = c.reverted ? start.uv : c.uv3;
    const SlimReport again = slim_symmetric_dirichlet(pos, m.local, free_uv, slim_options);
    c.iterations += again.iterations;
    if (again.energy_end <= o.split_energy && chart_is_injective(m.local, free_uv)) {
      c.reverted = false;
      c.energy_end = again.energy_end;
      place(free_uv);
    } else {
      ChartOutcome out = halves(again.energy_end < c.energy_end ? &free_uv : nullptr);
      if (!out.halves.empty()) return out;
    }
  }
  ChartOutcome out;
  out.done.push_back(std::move(c));
  return out;
}

}  // namespace

ValidUv make_valid_uv(const Block<double>& positions, const Faces& faces,
                      const Block<double>& psi_uv, const ValidUvOptions& o,
                      const UvProgress& progress) {
  JSA_CHECK(psi_uv.rows() == positions.rows() && psi_uv.cols() == 2,
            "make_valid_uv: one UV per vertex");
  const auto t0 = std::chrono::steady_clock::now();
  auto report = [&](const std::string& stage, double x) {
    if (progress) progress(stage, x);
  };
  report("cut", 0);
  CutResult cut = cut_charts(positions, faces, psi_uv, o.cut);
  report("cut", 1);
  ValidUv out;
  // Charts are done in rounds: every pending chart once (the large ones one at
  // a time with OpenMP inside, the others in parallel with each other), and the
  // halves of those split go to the next round. Each chart is named by its path
  // (its index in the cut, then 0/1 per split), and the charts done are put in
  // the order of their paths: the result does not depend on the scheduling.
  struct Job {
    ChartMesh mesh;
    std::vector<int> path;
  };
  std::vector<Job> pending;
  double done = 0, total = 0;
  for (size_t i = 0; i < cut.charts.size(); ++i) {
    total += double(cut.charts[i].faces.size());
    pending.push_back({std::move(cut.charts[i]), {int(i)}});
  }
  double usable3 = 0, usable2 = 0;
  for (const Job& job : pending)
    for (size_t i = 0; i < job.mesh.faces.size(); ++i) {
      if (!job.mesh.usable[i]) continue;
      const int f = job.mesh.faces[i];
      const Eigen::Vector3d p0 = positions.row(faces(f, 0)).transpose(),
                            p1 = positions.row(faces(f, 1)).transpose(),
                            p2 = positions.row(faces(f, 2)).transpose();
      usable3 += 0.5 * (p1 - p0).cross(p2 - p0).norm();
      usable2 += 0.5 * std::abs(signed_area2(psi_uv.row(faces(f, 0)).transpose(),
                                             psi_uv.row(faces(f, 1)).transpose(),
                                             psi_uv.row(faces(f, 2)).transpose()));
    }
  const double psi_per_3d = usable3 > 0 && usable2 > 0 ? std::sqrt(usable2 / usable3) : 1.0;
  std::vector<std::pair<std::vector<int>, ChartOut>> finished;
  report("charts", 0);
  for (int depth = 0; !pending.empty(); ++depth) {
    const size_t n = pending.size();
    std::vector<ChartOutcome> outcomes(n);
    std::vector<size_t> order(n);
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return pending[a].mesh.faces.size() > pending[b].mesh.faces.size();
    });
    // One chart larger than all the others together runs alone with the
    // threads inside it (over triangles; its sparse factorisations stay
    // serial); otherwise the charts run in parallel with each other.
    size_t large = 0;
    Index rest = 0;
    for (size_t i = 1; i < n; ++i) rest += Index(pending[order[i]].mesh.faces.size());
    if (n > 0 && Index(pending[order[0]].mesh.faces.size()) >= o.large_chart_faces &&
        Index(pending[order[0]].mesh.faces.size()) > rest)
      large = 1;
    for (size_t i = 0; i < large; ++i)
      outcomes[order[i]] =
          process_chart(positions, faces, psi_uv, pending[order[i]].mesh, o, depth, psi_per_3d);
      // Each chart writes only its own slot.
#pragma omp parallel for schedule(dynamic, 1)
    for (long long i = (long long)large; i < (long long)n; ++i)
      outcomes[order[size_t(i)]] = process_chart(
          positions, faces, psi_uv, pending[order[size_t(i)]].mesh, o, depth, psi_per_3d);
    std::vector<Job> next;
    for (size_t i = 0; i < n; ++i) {
      for (size_t k = 0; k < outcomes[i].done.size(); ++k) {
        std::vector<int> path = pending[i].path;
        path.push_back(int(k));
        done += double(outcomes[i].done[k].faces.size());
        finished.push_back({std::move(path), std::move(outcomes[i].done[k])});
      }
      for (size_t k = 0; k < outcomes[i].halves.size(); ++k) {
        std::vector<int> path = pending[i].path;
        path.push_back(int(k));
        next.push_back({std::move(outcomes[i].halves[k]), std::move(path)});
      }
    }
    pending.swap(next);
    report("charts", done / std::max(total, 1.0));
  }
  report("charts", 1);
  std::stable_sort(finished.begin(), finished.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<ChartOut> charts;
  for (auto& f : finished) charts.push_back(std::move(f.second));
  ValidUvStats& s = out.stats;
  double area3 = 0;
  for (const ChartOut& c : charts) {
    ++s.charts;
    s.from_psi += !c.single && c.start == ChartStart::psi;
    s.repaired += !c.single && c.start == ChartStart::repaired;
    s.lscm += !c.single && c.start == ChartStart::lscm;
    s.inherited += !c.single && c.start == ChartStart::inherited;
    s.tutte += !c.single && c.start == ChartStart::tutte;
    s.single_faces += c.single;
    s.slim_reverted += c.reverted;
    s.mirrored_charts += c.mirrored;
    s.slim_iterations += c.iterations;
    if (!c.single && std::isfinite(c.energy_start)) {
      s.energy_start += c.area3 * c.energy_start;
      s.energy_end += c.area3 * c.energy_end;
      area3 += c.area3;
    }
  }
  if (area3 > 0) s.energy_start /= area3, s.energy_end /= area3;
  if (o.pack_charts) {
    report("pack", 0);
    std::vector<Block<double>> uvs;
    std::vector<double> areas;
    // Packed charts keep their 3D scale (one texel density everywhere): psi's
    // placement is given up by packing anyway, and psi's local scale need not be uniform.
    for (ChartOut& c : charts) {
      uvs.push_back(std::move(c.uv3));
      areas.push_back(uv_area(c.local, uvs.back()));
    }
    const PackResult p = pack_charts(uvs, areas, o.pack);
    for (size_t i = 0; i < charts.size(); ++i) charts[i].uv = std::move(uvs[i]);
    s.packing_efficiency = p.efficiency;
    s.padding_texels = p.padding;
    for (const auto& w : p.warnings) s.warnings.push_back(w);
    report("pack", 1);
  }
  // Assemble: the charts' UVs in order, then three collapsed corners per skipped face.
  Index U = 0;
  for (const ChartOut& c : charts) U += c.uv.rows();
  out.uv.resize(U + 3 * Index(cut.skipped_faces.size()), 2);
  out.uv_faces.resize(faces.rows(), 3);
  out.face_chart.assign(size_t(faces.rows()), -1);
  Index offset = 0;
  for (size_t k = 0; k < charts.size(); ++k) {
    const ChartOut& c = charts[k];
    out.uv.middleRows(offset, c.uv.rows()) = c.uv;
    for (size_t i = 0; i < c.faces.size(); ++i) {
      out.uv_faces.row(c.faces[i]) = c.local.row(Index(i)).array() + int(offset);
      out.face_chart[size_t(c.faces[i])] = int(k);
    }
    offset += c.uv.rows();
  }
  for (int f : cut.skipped_faces) {
    for (int k = 0; k < 3; ++k) out.uv.row(offset + k).setZero();
    out.uv_faces.row(f) << int(offset), int(offset + 1), int(offset + 2);
    offset += 3;
  }
  for (const auto& w : cut.warnings) s.warnings.push_back(w);
  if (s.single_faces > 0)
    s.warnings.push_back(std::to_string(s.single_faces) +
                         " face(s) laid out alone (their chart had no injective embedding)");
  cut.charts.clear();
  s.cut = std::move(cut);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace jsa
