#include "io/geometry/functional_map.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/check.h"
#include "engine/rng.h"
#include "io/geometry/sparse_spd.h"

namespace jsa {

namespace {

// W (the cotangent Laplacian, positive semi-definite: W 1 = 0) and the lumped
// vertex areas. For the corner i of a triangle opposite the edge (j, k),
// cot(angle_i) / 2 joins j and k; summed over the edge's two triangles this
// is the classic (cot alpha + cot beta) / 2.
void cotangent_laplacian(const Mesh& mesh, Eigen::SparseMatrix<double>& W, Eigen::VectorXd& mass) {
  const Index V = mesh.vertices.rows();
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(size_t(mesh.faces.rows()) * 12);
  mass = Eigen::VectorXd::Zero(V);
  for (Index f = 0; f < mesh.faces.rows(); ++f) {
    const int v[3] = {mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)};
    const Eigen::Vector3d p[3] = {mesh.vertices.row(v[0]).transpose(),
                                  mesh.vertices.row(v[1]).transpose(),
                                  mesh.vertices.row(v[2]).transpose()};
    const double twice_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (!(twice_area > 0)) continue;  // a degenerate triangle carries nothing
    for (int c = 0; c < 3; ++c) mass(v[c]) += twice_area / 6;
    for (int c = 0; c < 3; ++c) {
      const int j = (c + 1) % 3, k = (c + 2) % 3;
      const Eigen::Vector3d a = p[j] - p[c], b = p[k] - p[c];
      // cot = a.b / |a x b|; |a x b| is twice the area for every corner.
      const double w = 0.5 * a.dot(b) / twice_area;
      t.emplace_back(v[j], v[j], w);
      t.emplace_back(v[k], v[k], w);
      t.emplace_back(v[j], v[k], -w);
      t.emplace_back(v[k], v[j], -w);
    }
  }
  W.resize(V, V);
  W.setFromTriplets(t.begin(), t.end());
}

}  // namespace

LaplaceBasis laplace_basis(const Mesh& mesh, int k, uint64_t seed) {
  if (mesh.is_point_cloud())
    throw InputError("functional maps need a triangle mesh, not a point cloud");
  const Index V = mesh.vertices.rows();
  JSA_CHECK(k >= 1, "laplace_basis: k must be >= 1");
  if (Index(k) > V) throw InputError("functional maps: more eigenfunctions than vertices");
  Eigen::SparseMatrix<double> W;
  Eigen::VectorXd mass;
  cotangent_laplacian(mesh, W, mass);
  const double area = mass.sum();
  if (!(area > 0) || !std::isfinite(area))
    throw InputError("functional maps: the mesh has no area");
  mass /= area;
  // A vertex no triangle holds would make M singular: give it a trace of
  // area, so its eigenfunctions stay finite (it is joined to nothing).
  const double floor = 1e-9 / double(V);
  for (Index i = 0; i < V; ++i) mass(i) = std::max(mass(i), floor);

  // Shift-invert: the largest eigenvalues of (W + sigma M)^-1 M are the
  // smallest of W phi = lambda M phi. With unit area, lambda_1 of a sphere is
  // 8 pi, so sigma = 1e-2 keeps the shifted matrix positive definite without
  // slowing the low eigenvalues' convergence.
  const double sigma = 1e-2;
  Eigen::SparseMatrix<double> A = W;
  for (Index i = 0; i < V; ++i) A.coeffRef(i, i) += sigma * mass(i);
  SpdSolver solver(SpdSolver::Use::once);
  if (!solver.compute(A))
    throw InputError("functional maps: the Laplacian could not be factorised");

  const Index p = std::min<Index>(V, Index(k) + Index(k) / 2 + 8);
  Rng rng(seed, 7);
  Eigen::MatrixXd X(V, p);
  for (Index j = 0; j < p; ++j)
    for (Index i = 0; i < V; ++i) X(i, j) = rng.normal();
  Eigen::VectorXd previous = Eigen::VectorXd::Constant(k, std::numeric_limits<double>::max());
  Eigen::VectorXd values;
  for (int sweep = 0; sweep < 60; ++sweep) {
    Eigen::MatrixXd MX = X;
    MX.array().colwise() *= mass.array();
    X = solver.solve(MX);
    // Rayleigh-Ritz on span(X): an orthonormal basis first (Householder, so
    // nearly dependent columns do not cost accuracy), then the projected
    // pencil (Q^T W Q, Q^T M Q), whose eigenvectors come out M-orthonormal.
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(X);
    const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(V, p);
    const Eigen::MatrixXd WQ = W * Q;
    Eigen::MatrixXd MQ = Q;
    MQ.array().colwise() *= mass.array();
    Eigen::MatrixXd Ar = Q.transpose() * WQ;
    Eigen::MatrixXd Br = Q.transpose() * MQ;
    Ar = 0.5 * (Ar + Ar.transpose()).eval();
    Br = 0.5 * (Br + Br.transpose()).eval();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(Ar, Br);
    if (ges.info() != Eigen::Success)
      throw InputError("functional maps: the eigenproblem did not converge");
    X = Q * ges.eigenvectors();  // ascending eigenvalues
    values = ges.eigenvalues().head(k);
    const double change =
        ((values - previous).array().abs() / (values.array().abs() + 1.0)).maxCoeff();
    previous = values;
    if (change < 1e-7) break;
  }
  LaplaceBasis b;
  b.eigenvalues = values.cwiseMax(0.0);
  b.functions = X.leftCols(k);
  b.mass = mass;
  // Each eigenfunction's sign is arbitrary; fix it (largest entry positive)
  // so that a basis does not depend on the solver's start beyond rounding.
  for (int j = 0; j < k; ++j) {
    Index at = 0;
    b.functions.col(j).cwiseAbs().maxCoeff(&at);
    if (b.functions(at, j) < 0) b.functions.col(j) *= -1;
  }
  return b;
}

std::vector<int> nearest_by_products(const Eigen::MatrixXd& queries,
                                     const Eigen::MatrixXd& points) {
  JSA_CHECK(queries.cols() == points.cols() && points.rows() > 0,
            "nearest_by_products: shapes do not match");
  using MatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const MatF P = points.cast<float>();
  const Eigen::VectorXf p2 = P.rowwise().squaredNorm();
  const MatF Qall = queries.cast<float>();
  std::vector<int> index(size_t(queries.rows()), 0);
  const Index block = 256;
  const Index blocks = (queries.rows() + block - 1) / block;
  // |q - p|^2 = |q|^2 - 2 q.p + |p|^2; |q|^2 does not change the argmin.
  // Each block of queries writes only its own slots: the result does not
  // depend on the thread count.
#pragma omp parallel for schedule(dynamic, 1)
  for (Index b = 0; b < blocks; ++b) {
    const Index first = b * block, rows = std::min(block, queries.rows() - first);
    MatF d = (-2.0f) * (Qall.middleRows(first, rows) * P.transpose());
    d.rowwise() += p2.transpose();
    for (Index r = 0; r < rows; ++r) {
      Index at = 0;
      d.row(r).minCoeff(&at);
      index[size_t(first + r)] = int(at);
    }
  }
  return index;
}

std::vector<int> zoomout(const LaplaceBasis& source, const LaplaceBasis& target,
                         std::vector<int> map, const ZoomOutOptions& o) {
  const Index Vt = target.functions.rows(), Vs = source.functions.rows();
  JSA_CHECK(Index(map.size()) == Vt, "zoomout: one source vertex per target vertex");
  const int k_max = int(std::min(source.functions.cols(), target.functions.cols()));
  const int k_end = std::min(o.k_end, k_max);
  JSA_CHECK(o.k_start >= 1 && o.k_step >= 1, "zoomout: bad k schedule");
  // Every size but the last works on `samples` vertices of each shape (drawn
  // uniformly, without replacement): C is an integral over the target, which
  // a sample estimates (its areas rescaled to sum to 1), and the map's
  // intermediate values are only read by the next C. The last size maps
  // every target vertex to the nearest of every source vertex.
  auto every = [](Index count) {
    std::vector<int> all(static_cast<size_t>(count));
    for (Index i = 0; i < count; ++i) all[size_t(i)] = int(i);
    return all;
  };
  auto draw = [&](Index count, uint64_t stream) {
    std::vector<int> all = every(count);
    if (o.samples <= 0 || o.samples >= count) return all;
    Rng rng(o.seed, stream);
    for (Index i = 0; i < Index(o.samples); ++i)  // a partial Fisher-Yates shuffle
      std::swap(all[size_t(i)], all[size_t(i + Index(rng.below(uint64_t(count - i))))]);
    all.resize(size_t(o.samples));
    std::sort(all.begin(), all.end());
    return all;
  };
  const bool with_prior = o.prior_weight > 0;
  if (with_prior)
    JSA_CHECK(o.prior_on_target.rows() == Vt && o.prior_on_target.cols() == 3 &&
                  o.prior_on_source.rows() == Vs && o.prior_on_source.cols() == 3,
              "zoomout: the spatial prior needs V_t x 3 and V_s x 3 positions");
  const std::vector<int> at_t = draw(Vt, 1), at_s = draw(Vs, 2);
  const std::vector<int> all_t = every(Vt), all_s = every(Vs);
  for (int k = std::min(o.k_start, k_end); k <= k_end; k += o.k_step) {
    const bool last = k + o.k_step > k_end;
    const std::vector<int>& rows_t = last ? all_t : at_t;
    const std::vector<int>& cols_s = last ? all_s : at_s;
    // C = Phi_t^T M_t Pi Phi_s (k x k): the source's functions pulled back by
    // the current map, expressed in the target's basis (over the sample).
    const Index n = Index(at_t.size());
    Eigen::MatrixXd pulled(n, k), phi_t(n, k);
    double area = 0;
    for (Index r = 0; r < n; ++r) area += target.mass(at_t[size_t(r)]);
    for (Index r = 0; r < n; ++r) {
      const int y = at_t[size_t(r)];
      phi_t.row(r) = target.functions.row(y).head(k);
      pulled.row(r) = source.functions.row(map[size_t(y)]).head(k) * (target.mass(y) / area);
    }
    Eigen::MatrixXd C = phi_t.transpose() * pulled;
    if (o.orthogonal) {
      // The nearest orthogonal C (Procrustes): a map that preserves area
      // carries an orthonormal basis onto an orthonormal one. Without it, a
      // start that sends a part of the target onto a line of the source (a
      // folded arm onto the chest) stays squashed (test/geometry_functional_map_test.cpp).
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
      C = svd.matrixU() * svd.matrixV().transpose();
    }
    // The new map: y -> the source vertex whose spectral coordinates are
    // nearest to Phi_t[y] C.
    const bool prior = with_prior && k < o.prior_until;
    const Index extra = prior ? 3 : 0;
    const double w = prior ? o.prior_weight * std::sqrt(target.eigenvalues.head(k).sum()) : 0;
    Eigen::MatrixXd queries(Index(rows_t.size()), k + extra);
    for (Index r = 0; r < queries.rows(); ++r) {
      queries.row(r).head(k) = target.functions.row(rows_t[size_t(r)]).head(k) * C;
      if (prior) queries.row(r).tail(3) = w * o.prior_on_target.row(rows_t[size_t(r)]);
    }
    Eigen::MatrixXd database(Index(cols_s.size()), k + extra);
    for (Index r = 0; r < database.rows(); ++r) {
      database.row(r).head(k) = source.functions.row(cols_s[size_t(r)]).head(k);
      if (prior) database.row(r).tail(3) = w * o.prior_on_source.row(cols_s[size_t(r)]);
    }
    const std::vector<int> near = nearest_by_products(queries, database);
    for (size_t r = 0; r < near.size(); ++r) map[size_t(rows_t[r])] = cols_s[size_t(near[r])];
    if (last) break;
  }
  return map;
}

}  // namespace jsa
