// phi: R^2 -> R^3, the surface parametrization, and phi6 = [phi, n] (Eqs. 1-3).
//
// The Jacobian J = [dphi/du, dphi/dv] (Eq. 1) comes from running the MLP on
// stacked tangent rows (engine/tangents.h), so J is a tape value like any other
// and the normal n = alpha (J_u x J_v) / |J_u x J_v| (Eq. 2) and the isometry
// term (Eq. 10) are differentiated exactly by backward().
#pragma once
#include <array>
#include <string>

#include "model/mlp.h"

namespace jsa {

// A shape's node displacements t_k,i, one n x 3 block per field of nodes
// (Atlas::phi_nodes); an invalid Var where a field is absent.
using NodeFields = std::array<Var, 2>;

struct SurfacePoints {
  Var points;   // phi(x), M x 3
  Var du, dv;   // J_u, J_v (Eq. 1), M x 3 each; invalid without Jacobians
  Var normals;  // alpha-scaled unit normals n (Eq. 2), M x 3; invalid without Jacobians
  Var phi6;     // [phi(x), n] (Eq. 3), M x 6; invalid without Jacobians
};

template <class T>
class Parametrization {
 public:
  Parametrization() = default;
  // in = 2, out = 3 (code_size: the latent code width in a collection). name:
  // the prefix of its parameters; a model with several (AtlasNet's patches,
  // model/baselines/atlasnet.h) gives each its own.
  Parametrization(Parameters<T>& params, const MlpShape& shape, T alpha,
                  const std::string& name = "phi")
      : mlp_(params, name, shape), alpha_(alpha) {}
  // A collection's phi as deformations of one surface (AtlasOptions::deform_layers):
  //   phi_i(x) = p + D(p, f_i),  p = phi(x),
  // `shape` phi's (no code), `deform` D's (in = out = 3, with the code). D is
  // a function of the point in 3D, so the shapes share phi's layout of the
  // domain and differ by a deformation that moves neighbours together; the
  // tangents follow by the chain rule, J_i = (I + dD/dp) J, since D runs on
  // the stacked rows [p; J_u; J_v] like any layer (engine/tangents.h).
  // deform.in = 5: D(p, x, f_i) also reads the domain point; its stacked rows
  // are [p, x; J_u, e_u; J_v, e_v], so J_i = (I + dD/dp) J + dD/dx still holds
  // row by row.
  Parametrization(Parameters<T>& params, const MlpShape& shape, T alpha, const MlpShape& deform)
      : mlp_(params, "phi", shape),
        deform_(params, "phi.deform", deform),
        alpha_(alpha),
        deforms_(true) {
    JSA_CHECK(deform.in == 3 || deform.in == 5,
              "D reads the 3D point, or the 3D point and the domain point: in = 3 or 5");
  }
  // MLPs as PyTorch's default; D's output layer then scaled by 1e-2, so every
  // shape starts as phi's surface, nearly undeformed.
  void initialize(Parameters<T>& params, Rng& rng) const {
    mlp_.initialize(params, rng);
    if (deforms_) {
      deform_.initialize(params, rng);
      deform_.scale_output_layer(params, T(1e-2));
    }
  }
  // x: M x 2 domain points. with_jacobian = false evaluates phi(x) alone.
  // code: the shape's latent code f_phi,i (1 x D) in a collection, else none.
  // nodes: the shape's node displacements t_k,i (Atlas::phi_nodes), or none.
  SurfacePoints evaluate(Tape<T>& t, Parameters<T>& params, Var x, bool with_jacobian,
                         Var code = {}, const NodeFields& nodes = {}) const;
  // The node displacement of a collection (AtlasOptions::deform_nodes):
  //   phi_i(x) <- phi_i(x) + sum_k w_k(x) t_k,i,  w_k = g_k / sum_j g_j,
  //   g_k(x) = exp(-|x - c_k|^2 / (2 sigma^2)),
  // normalised kernels centred at c_k in the domain, so a node moves what the domain puts
  // near c_k and nothing that is merely near it in 3D. `centres` (n x 2) and
  // `sigma` (1 x 1) are parameter blocks read as constants; sigma = 0 (not
  // yet placed) turns the term off. Up to two fields (field 0: deform_nodes,
  // field 1: fine_nodes), each with its own kernels, normalised apart and summed.
  void set_nodes(int field, int centres, int sigma) {
    fields_.at(size_t(field)) = {centres, sigma};
  }
  bool has_nodes(int field = 0) const { return fields_.at(size_t(field)).centres >= 0; }
  int node_centres(int field = 0) const { return fields_.at(size_t(field)).centres; }
  int node_sigma(int field = 0) const { return fields_.at(size_t(field)).sigma; }
  const Mlp<T>& mlp() const { return mlp_; }
  T alpha() const { return alpha_; }
  bool deforms() const { return deforms_; }

 private:
  Mlp<T> mlp_;
  Mlp<T> deform_;  // D (deforms_ only)
  T alpha_ = T(0.01);
  bool deforms_ = false;
  struct Field {
    int centres = -1, sigma = -1;  // parameter blocks of the node kernels (set_nodes)
  };
  std::array<Field, 2> fields_;
};

}  // namespace jsa
