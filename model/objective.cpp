#include "model/objective.h"

#include <cmath>
#include <limits>

#include "engine/ops.h"
#include "losses/chamfer.h"
#include "losses/cycle.h"
#include "losses/evenness.h"
#include "losses/isometry.h"
#include "losses/repulsion.h"
#include "losses/transport.h"

namespace jsa {

Components Components::table_row(int row) {
  JSA_CHECK(row >= 6 && row <= 11, "Table 1 rows 6-11 only, got " << row);
  Components c;
  c.normals = row >= 7;
  c.repulsion = row >= 8;
  c.distribution = row >= 9;
  c.chart = row >= 10;
  c.isometry = row >= 11;
  return c;
}

namespace {

// A constant copy of node v (no gradient flows back through it). The node is
// made first and filled after: appending it may move the block v names.
template <class T>
Var held_constant(Tape<T>& t, Var v) {
  const Var c = t.constant(Block<T>::Zero(t.rows(v), t.cols(v)));
  t.value(c) = t.value(v);
  return c;
}

// phi_t(x_P) of the reference shape t, on the values alone (x_P and t's code
// held constant): the key of a look-up (L_6D^h's h_t, L_map's T_i) that is a
// constant of the step, so backward never reaches this pass. The block is the
// tape's: read it before the next node is made.
// A shape's node displacements as constants of the step (held_constant).
template <class T>
NodeFields held_nodes(Tape<T>& t, NodeFields nodes) {
  for (Var& v : nodes)
    if (v.valid()) v = held_constant(t, v);
  return nodes;
}

template <class T>
const Block<T>& reference_points(Tape<T>& t, Atlas<T>& atlas, Var x_p, int reference) {
  const Var x_fixed = held_constant(t, x_p);
  const Var code_t = atlas.has_codes() ? held_constant(t, atlas.phi_code(t, reference)) : Var{};
  return t.value(atlas.phi
                     .evaluate(t, atlas.params, x_fixed, false, code_t,
                               held_nodes(t, atlas.phi_nodes(t, reference)))
                     .points);
}

// The weighted terms of L_single (Eq. 5), at most one of each kind: a fixed
// array, not a vector (nothing in a step may allocate).
struct WeightedTerms {
  std::pair<double, Var> term[12];
  int count = 0;
  void push_back(std::pair<double, Var> t) {
    JSA_CHECK(count < 12, "more loss terms than WeightedTerms holds");
    term[count++] = t;
  }
};

}  // namespace

template <class T>
Var single_shape_objective(Tape<T>& t, Atlas<T>& atlas, int shape, const Block<T>& targets, Index m,
                           Rng& rng, const ObjectiveOptions& o, LossTerms* terms,
                           const NearestIndex<T>* dense, const IntrinsicField<T>* intrinsic,
                           const MapField<T>* map) {
  const LossWeights& w = o.weights;
  const Components& c = o.components;
  JSA_CHECK(targets.cols() == (intrinsic ? 9 : 6),
            (intrinsic ? "targets must be M x 9 [x_S, alpha n_S, beta h_S]"
                       : "targets must be M x 6 [x_S, alpha n_S]"));
  JSA_CHECK(!intrinsic || c.normals, "L_6D^h needs the normals in the loss");
  Parameters<T>& p = atlas.params;
  LossTerms out;
  WeightedTerms weighted;  // (lambda, term)

  // {x_P} ~ P by the reparameterization trick (Eq. 4).
  const Var x_p = atlas.domain.sample(t, p, m, rng);  // M x 2
  const Var s6 = intrinsic ? t.constant(targets.leftCols(6)) : t.constant(targets);
  const Var f_phi = atlas.phi_code(t, shape), f_psi = atlas.psi_code(t, shape);
  const bool jacobian = c.normals || c.isometry || c.chart;

  // psi({x_S, n_S}) first: the 6D cycle evaluates phi at these 2D points, and
  // batching them with x_P makes phi one pass over 2M points.
  Var u_s;
  if (c.chart) u_s = atlas.psi.evaluate(t, p, s6, f_psi);
  const Var phi_in = c.chart ? concat_rows(t, {x_p, u_s}) : x_p;
  SurfacePoints all = atlas.phi.evaluate(t, p, phi_in, jacobian, f_phi, atlas.phi_nodes(t, shape));
  // Diverged networks: report NaN (the trainer recovers) rather than search
  // nearest neighbours among non-finite points.
  if (!t.value(phi_in).allFinite() || !t.value(all.points).allFinite() ||
      (jacobian && !t.value(all.phi6).allFinite())) {
    out.total = std::numeric_limits<double>::quiet_NaN();
    if (terms) *terms = out;
    return t.constant(Block<T>::Constant(1, 1, std::numeric_limits<T>::quiet_NaN()));
  }
  auto first_m = [&](Var v) { return c.chart ? slice_rows(t, v, 0, m) : v; };
  auto last_m = [&](Var v) { return slice_rows(t, v, m, targets.rows()); };

  // L_6D = Chamfer(phi6({x_P}), {x_S, n_S})   (Eq. 7); row 6: 3D points only.
  // With `dense`, phi6(x_P) finds its match in the whole pool (losses/chamfer.h).
  Var generated = c.normals ? first_m(all.phi6) : first_m(all.points);
  Var sampled = c.normals ? s6 : slice_cols(t, s6, 0, 3);
  if (intrinsic) {
    // L_6D^h (objective.h): beta h_t(phi_t(x_P)), the reference's descriptor
    // where its surface puts x_P, a constant of the step. phi_t runs on the
    // values alone: nothing downstream reaches the loss, so backward skips it.
    std::vector<int>& near = t.template workspace<std::vector<int>>();
    intrinsic->surface->query(reference_points(t, atlas, x_p, intrinsic->reference), near);
    const Var h = t.constant(Block<T>::Zero(m, intrinsic->descriptors->cols()));
    for (Index i = 0; i < m; ++i) t.value(h).row(i) = intrinsic->descriptors->row(near[size_t(i)]);
    generated = concat_cols(t, {generated, h});
    sampled = t.constant(targets);
  }
  ChamferMatches<T>* const no_matches = nullptr;
  const Var surface = dense ? chamfer(t, generated, sampled, *dense, no_matches, w.coverage)
                            : chamfer(t, generated, sampled, no_matches, w.coverage);
  weighted.push_back({w.surface, surface});
  out.surface = double(t.scalar(surface));

  if (c.chart) {
    // L_2D = Chamfer(psi({x_S, n_S}), {x_P})   (Eq. 8)
    const Var chart = chamfer(t, u_s, x_p);
    weighted.push_back({w.chart, chart});
    out.chart = double(t.scalar(chart));
    // L_cycle (Eq. 9): 2D -> 6D -> 2D on {x_P}, and 6D -> 2D -> 6D on {x_S, n_S}.
    const Var back_2d = atlas.psi.evaluate(t, p, first_m(all.phi6), f_psi);
    const Var cycle_2d = mean_squared_distance(t, x_p, back_2d);
    const Var cycle_6d = mean_squared_distance(t, s6, last_m(all.phi6));
    weighted.push_back({w.cycle, cycle_2d});
    weighted.push_back({w.cycle, cycle_6d});
    out.cycle_2d = double(t.scalar(cycle_2d));
    out.cycle_6d = double(t.scalar(cycle_6d));
  }
  if (c.isometry) {
    // L_iso on the Jacobian at {x_P}   (Eq. 10)
    const Var iso = isometry_loss(t, first_m(all.du), first_m(all.dv));
    weighted.push_back({w.isometry, iso});
    out.isometry = double(t.scalar(iso));
  }
  if (w.evenness > 0 && jacobian) {
    // L_even on the Jacobian at {x_P} (beyond the paper; losses/evenness.h):
    // P's density over the area element, as even as it can be.
    const Var even = evenness_loss(t, x_p, p.on(t, atlas.domain.means()), atlas.domain.sigma(),
                                   first_m(all.du), first_m(all.dv));
    weighted.push_back({w.evenness, even});
    out.evenness = double(t.scalar(even));
  }
  if (w.transport > 0) {
    // L_EMD on the first n samples and targets, 3D points (beyond the paper;
    // losses/transport.h): every target gets a sample of its own.
    const Index n = std::min<Index>(o.transport_points, m);
    const Var emd = transport_loss(t, slice_rows(t, first_m(all.points), 0, n),
                                   t.constant(targets.topLeftCorner(n, 3)));
    weighted.push_back({w.transport, emd});
  }
  if (w.metric > 0 && jacobian && o.metric_reference >= 0 && shape != o.metric_reference) {
    // L_metric (collections, beyond the paper; losses/isometry.h): the
    // reference shape's phi at this shape's {x_P}, its metric against ours.
    // The reference's code is held constant here: it is a target for the
    // others, moved only by its own shape's terms (which also keeps a
    // data-parallel step exact: a code's gradient stays on its shape's rank).
    const Var ref_code = held_constant(t, atlas.phi_code(t, o.metric_reference));
    const SurfacePoints ref = atlas.phi.evaluate(
        t, p, x_p, true, ref_code, held_nodes(t, atlas.phi_nodes(t, o.metric_reference)));
    const Var metric =
        o.metric_conformal
            ? conformal_metric_mismatch(t, first_m(all.du), first_m(all.dv), ref.du, ref.dv)
            : metric_mismatch(t, first_m(all.du), first_m(all.dv), ref.du, ref.dv);
    weighted.push_back({w.metric, metric});
  }
  if (w.map > 0 && map && shape != map->reference) {
    // L_map (objective.h): T_i(phi_t(x_P)) a constant of the step, phi_t on
    // the values alone (as L_6D^h's h_t above).
    std::vector<int>& near = t.template workspace<std::vector<int>>();
    map->surface->query(reference_points(t, atlas, x_p, map->reference), near);
    const Block<T>& image = (*map->images)[size_t(shape)];
    const Var y = t.constant(Block<T>::Zero(m, 3));
    for (Index i = 0; i < m; ++i) t.value(y).row(i) = image.row(near[size_t(i)]);
    const Var pull = mean_squared_distance(t, first_m(all.points), y);
    weighted.push_back({w.map, pull});
    out.map = double(t.scalar(pull));
  }
  if (c.repulsion) {
    // L_rep on the means   (Eq. 11)
    const Var rep = repulsion(t, p.on(t, atlas.domain.means()), atlas.domain.sigma(),
                              RepulsionOptions{o.repulsion_tolerance});
    weighted.push_back({w.repulsion, rep});
    out.repulsion = double(t.scalar(rep));
  }

  // L_single = sum of lambda * L   (Eq. 5)
  Var total = scale(t, weighted.term[0].second, T(weighted.term[0].first));
  for (int k = 1; k < weighted.count; ++k)
    total = add(t, total, scale(t, weighted.term[k].second, T(weighted.term[k].first)));
  out.total = double(t.scalar(total));
  if (terms) *terms = out;
  return total;
}

template <class T>
Var objective_share(Tape<T>& t, Atlas<T>& atlas, const std::vector<Block<T>>& targets, Index m,
                    const ObjectiveOptions& o, const ObjectiveShare<T>& share, LossTerms* terms) {
  const int n = atlas.shapes();
  const int b = int(targets.size());
  JSA_CHECK(int(share.shapes.size()) == b && int(share.rngs.size()) == b,
            targets.size() << " target sets for " << share.shapes.size() << " shapes");
  JSA_CHECK(share.batch >= b && share.batch <= n,
            "a batch of " << share.batch << " of " << n << " shapes");
  JSA_CHECK(share.surfaces.empty() || int(share.surfaces.size()) == b,
            "one surface index per target set");
  JSA_CHECK(share.code_begin >= 0 && share.code_end <= n,
            "codes [" << share.code_begin << ", " << share.code_end << ")");
  ObjectiveOptions per_shape = o;
  per_shape.components.repulsion = false;
  LossTerms sum_terms, one;
  Var total;
  for (int k = 0; k < b; ++k) {
    const int shape = share.shapes[size_t(k)];
    JSA_CHECK(shape >= 0 && shape < n, "shape " << shape << " of " << n);
    const NearestIndex<T>* dense = share.surfaces.empty() ? nullptr : share.surfaces[size_t(k)];
    const Var l =
        single_shape_objective(t, atlas, shape, targets[size_t(k)], m, *share.rngs[size_t(k)],
                               per_shape, &one, dense, share.intrinsic, share.map);
    total = k == 0 ? l : add(t, total, l);
    sum_terms.surface += one.surface;
    sum_terms.chart += one.chart;
    sum_terms.cycle_2d += one.cycle_2d;
    sum_terms.cycle_6d += one.cycle_6d;
    sum_terms.isometry += one.isometry;
    sum_terms.evenness += one.evenness;
    sum_terms.map += one.map;
  }
  // A subset of B shapes stands for all N: its sum is scaled by N / B (see collection_objective).
  if (b > 0 && share.batch < n) total = scale(t, total, T(double(n) / double(share.batch)));
  if (!std::isfinite(sum_terms.surface) || !atlas.params.value(atlas.domain.means()).allFinite()) {
    // A diverged step (see single_shape_objective): NaN for the trainer to catch.
    sum_terms.total = std::numeric_limits<double>::quiet_NaN();
    if (terms) *terms = sum_terms;
    return t.constant(Block<T>::Constant(1, 1, std::numeric_limits<T>::quiet_NaN()));
  }
  auto plus = [&](Var v) { total = total.valid() ? add(t, total, v) : v; };
  if (o.components.repulsion && share.repulsion) {
    const Var rep = repulsion(t, atlas.params.on(t, atlas.domain.means()), atlas.domain.sigma(),
                              RepulsionOptions{o.repulsion_tolerance});
    sum_terms.repulsion = double(t.scalar(rep));
    plus(scale(t, rep, T(n * o.weights.repulsion)));
  }
  if (atlas.has_codes() && o.weights.code > 0 && share.code_begin < share.code_end) {
    // (1/N) sum_i (|f_phi,i|^2 + |f_psi,i|^2), over this share's codes
    Var norms;
    for (int i = share.code_begin; i < share.code_end; ++i) {
      const Var phi_i = sum(t, square(t, atlas.phi_code(t, i)));
      norms = norms.valid() ? add(t, norms, phi_i) : phi_i;
    }
    for (int i = share.code_begin; i < share.code_end; ++i)
      norms = add(t, norms, sum(t, square(t, atlas.psi_code(t, i))));
    plus(scale(t, norms, T(o.weights.code / n)));
  }
  if (!total.valid())
    total = t.constant(Block<T>::Zero(1, 1));  // a share with nothing in it this step
  sum_terms.total = double(t.scalar(total));
  if (terms) *terms = sum_terms;
  return total;
}

template <class T>
Var collection_objective(Tape<T>& t, Atlas<T>& atlas, const std::vector<Block<T>>& targets, Index m,
                         Rng& rng, const ObjectiveOptions& o, LossTerms* terms,
                         const std::vector<int>& batch,
                         const std::vector<NearestIndex<T>>& surfaces) {
  const int n = atlas.shapes();
  const int b = int(targets.size());
  if (batch.empty())
    JSA_CHECK(b == n, targets.size() << " target sets for " << n << " shapes");
  else
    JSA_CHECK(b == int(batch.size()) && b > 0 && b <= n,
              targets.size() << " target sets for a batch of " << batch.size());
  JSA_CHECK(surfaces.empty() || int(surfaces.size()) == n,
            surfaces.size() << " surface indexes for " << n << " shapes");
  // The whole of L_full in one share; every shape draws from the one generator, in turn.
  ObjectiveShare<T> share;
  share.batch = b;
  share.code_end = n;
  for (int k = 0; k < b; ++k) {
    const int shape = batch.empty() ? k : batch[size_t(k)];
    share.shapes.push_back(shape);
    share.rngs.push_back(&rng);
    if (!surfaces.empty() && shape >= 0 && shape < n)
      share.surfaces.push_back(&surfaces[size_t(shape)]);
  }
  LossTerms sums;
  const Var total = objective_share(t, atlas, targets, m, o, share, &sums);
  if (terms) {
    *terms = sums;
    for (double* v : {&terms->surface, &terms->chart, &terms->cycle_2d, &terms->cycle_6d,
                      &terms->isometry, &terms->evenness, &terms->map})
      *v /= b;
  }
  return total;
}

#define JSA_INSTANTIATE(T)                                                                         \
  template Var single_shape_objective<T>(                                                          \
      Tape<T>&, Atlas<T>&, int, const Block<T>&, Index, Rng&, const ObjectiveOptions&, LossTerms*, \
      const NearestIndex<T>*, const IntrinsicField<T>*, const MapField<T>*);                       \
  template Var collection_objective<T>(                                                            \
      Tape<T>&, Atlas<T>&, const std::vector<Block<T>>&, Index, Rng&, const ObjectiveOptions&,     \
      LossTerms*, const std::vector<int>&, const std::vector<NearestIndex<T>>&);                   \
  template Var objective_share<T>(Tape<T>&, Atlas<T>&, const std::vector<Block<T>>&, Index,        \
                                  const ObjectiveOptions&, const ObjectiveShare<T>&, LossTerms*);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
