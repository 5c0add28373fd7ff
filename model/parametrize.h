// phi: R^2 -> R^3, the surface parametrization, and phi6 = [phi, n] (Eqs. 1-3).
//
// The Jacobian J = [dphi/du, dphi/dv] (Eq. 1) comes from running the MLP on
// stacked tangent rows (engine/tangents.h), so J is a tape value like any other
// and the normal n = alpha (J_u x J_v) / |J_u x J_v| (Eq. 2) and the isometry
// term (Eq. 10) are differentiated exactly by backward().
#pragma once
#include <string>

#include "model/mlp.h"

namespace jsa {

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
  void initialize(Parameters<T>& params, Rng& rng) const { mlp_.initialize(params, rng); }
  // x: M x 2 domain points. with_jacobian = false evaluates phi(x) alone.
  // code: the shape's latent code f_phi,i (1 x D) in a collection, else none.
  SurfacePoints evaluate(Tape<T>& t, Parameters<T>& params, Var x, bool with_jacobian,
                         Var code = {}) const;
  const Mlp<T>& mlp() const { return mlp_; }
  T alpha() const { return alpha_; }

 private:
  Mlp<T> mlp_;
  T alpha_ = T(0.01);
};

}  // namespace jsa
