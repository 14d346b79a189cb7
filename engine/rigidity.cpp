#include "engine/rigidity.h"

#include <Eigen/Dense>
#include <Eigen/SPQRSupport>
#include <algorithm>
#include <cmath>

namespace flexure::engine {

const char* toString(Verdict v) {
  switch (v) {
    case Verdict::Rigid: return "rigid";
    case Verdict::Flexible: return "flexible";
    case Verdict::Unknown: return "unknown";
  }
  return "unknown";
}

namespace {

// Orthonormal basis of the column space of M, keeping singular values > rel * sigma_max(M).
Matrix orthonormalColumnSpace(const Matrix& M, double rel) {
  if (M.cols() == 0 || M.rows() == 0) return Matrix(M.rows(), 0);
  Eigen::JacobiSVD<Matrix> svd(M, Eigen::ComputeThinU);
  const auto& s = svd.singularValues();
  int r = 0;
  while (r < s.size() && s[r] > rel * std::max(s[0], 1e-300)) ++r;
  if (s.size() == 0 || s[0] == 0.0) r = 0;
  return svd.matrixU().leftCols(r);
}

struct Spaces {
  int rank = 0;
  Matrix kernel;    // N x (N - rank), or empty when not formed
  Matrix cokernel;  // m x (m - rank), or empty when not formed
  bool kernel_formed = false;
  bool cokernel_formed = false;
};

void denseSpaces(const SparseMatrix& J, const RigidityOptions& opt, RigidityReport& rep,
                 Spaces& out) {
  const int m = static_cast<int>(J.rows()), N = static_cast<int>(J.cols());
  rep.method = "dense SVD";
  if (m == 0 || N == 0) {
    out.rank = 0;
    out.kernel = Matrix::Identity(N, N);
    out.cokernel = Matrix::Identity(m, m);
    out.kernel_formed = out.cokernel_formed = true;
    return;
  }
  const Matrix Jd(J);
  Eigen::BDCSVD<Matrix> svd(Jd, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vector& s = svd.singularValues();
  rep.sigma_max = s[0];
  rep.tolerance = opt.rank_tolerance * s[0];
  int r = 0;
  while (r < s.size() && s[r] > rep.tolerance) ++r;
  out.rank = r;
  rep.sigma_smallest_kept = r > 0 ? s[r - 1] : 0.0;
  rep.sigma_largest_dropped = r < s.size() ? s[r] : 0.0;
  out.kernel = svd.matrixV().rightCols(N - r);
  out.cokernel = svd.matrixU().rightCols(m - r);
  out.kernel_formed = out.cokernel_formed = true;
}

void sparseSpaces(const SparseMatrix& J, const RigidityOptions& opt, RigidityReport& rep,
                  Spaces& out) {
  const int m = static_cast<int>(J.rows()), N = static_cast<int>(J.cols());
  rep.method = "sparse QR";
  // SuiteSparseQR of J^T (N x m): J^T P = Q R. The first `rank` columns of Q span the row
  // space of J, the remaining N - rank columns span ker J. Columns whose remaining norm is at
  // most the threshold count as dependent (Heath's rank detection).
  SparseMatrix Jt = J.transpose();
  Jt.makeCompressed();
  double max_col = 0.0;
  for (int c = 0; c < Jt.outerSize(); ++c) {
    double s = 0.0;
    for (SparseMatrix::InnerIterator it(Jt, c); it; ++it) s += it.value() * it.value();
    max_col = std::max(max_col, std::sqrt(s));
  }
  Eigen::SPQR<SparseMatrix> qr;
  rep.tolerance = opt.rank_tolerance * max_col;
  qr.setPivotThreshold(rep.tolerance);
  qr.compute(Jt);
  if (qr.info() != Eigen::Success) {
    rep.warnings.push_back("sparse QR failed; falling back to dense SVD");
    denseSpaces(J, opt, rep, out);
    return;
  }
  const int r = static_cast<int>(qr.rank());
  out.rank = r;
  const SparseMatrix R = qr.matrixR();
  double dmax = 0.0, dmin = INFINITY;
  const Vector diag = R.diagonal();
  for (int i = 0; i < r; ++i) {
    const double v = std::abs(diag[i]);
    dmax = std::max(dmax, v);
    dmin = std::min(dmin, v);
  }
  rep.sigma_max = dmax;
  rep.sigma_smallest_kept = r > 0 ? dmin : 0.0;
  const long kernel_entries = static_cast<long>(N) * (N - r);
  if (kernel_entries <= opt.max_basis_entries) {
    Matrix E = Matrix::Zero(N, N - r);
    for (int i = 0; i < N - r; ++i) E(r + i, i) = 1.0;
    out.kernel = qr.matrixQ() * E;
    out.kernel_formed = true;
    // The largest singular value of J on the computed kernel bounds what was dropped.
    rep.sigma_largest_dropped = N - r > 0 ? (J * out.kernel).colwise().norm().maxCoeff() : 0.0;
  }
  const long cokernel_entries = static_cast<long>(m) * (m - r);
  if (m - r > 0 && cokernel_entries <= opt.max_basis_entries && m - r <= opt.max_sparse_stress_basis) {
    Eigen::SPQR<SparseMatrix> qr2;
    qr2.setPivotThreshold(rep.tolerance);
    SparseMatrix Jc = J;
    Jc.makeCompressed();
    qr2.compute(Jc);
    if (qr2.info() == Eigen::Success && qr2.rank() == r) {
      Matrix E = Matrix::Zero(m, m - r);
      for (int i = 0; i < m - r; ++i) E(r + i, i) = 1.0;
      out.cokernel = qr2.matrixQ() * E;
      out.cokernel_formed = true;
    } else {
      rep.warnings.push_back("the stress basis was not formed: the two sparse QRs disagree on the rank");
    }
  } else if (m - r == 0) {
    out.cokernel = Matrix(m, 0);
    out.cokernel_formed = true;
  }
}

// The stress-energy quadratic forms on the nontrivial flexes: for stress j, the k x k matrix
// M_j(a, b) = sum_i omega_j[i] * (B_a^T H_i B_b). Also returns the scale of the forms.
std::vector<Matrix> stressForms(const ConstraintSystem& sys, const Vector& x, const Matrix& B,
                                const Matrix& S, double& scale) {
  const int k = static_cast<int>(B.cols()), s = static_cast<int>(S.cols());
  std::vector<Matrix> M(static_cast<size_t>(s), Matrix::Zero(k, k));
  scale = 0.0;
  for (int a = 0; a < k; ++a)
    for (int b = a; b < k; ++b) {
      const Vector h = sys.secondDerivative(x, B.col(a), B.col(b));
      if (a == b) scale = std::max(scale, h.norm());
      for (int j = 0; j < s; ++j) M[j](a, b) = M[j](b, a) = S.col(j).dot(h);
    }
  return M;
}

void secondOrderCertificates(const Model& model, const Vector& x, const RigidityOptions& opt,
                             RigidityReport& rep) {
  const int k = rep.nontrivial, s = rep.stresses;
  if (k == 0) {
    rep.prestress_stable = rep.second_order_rigid = true;
    rep.rigid = Verdict::Rigid;
    rep.reason = "infinitesimally rigid";
    return;
  }
  if (s == 0) {
    // J has full row rank: near x the realization space is a manifold of dimension
    // N - m = dim ker J, larger than the orbit of x under the symmetries (dimension `trivial`),
    // so it holds realizations that are not congruent to x.
    rep.prestress_stable = rep.second_order_rigid = false;
    rep.rigid = Verdict::Flexible;
    rep.reason = "regular point (no stress) with " + std::to_string(k) +
                 " nontrivial flex(es): the realization space is locally a manifold of "
                 "dimension larger than the orbit of the symmetries";
    return;
  }
  if (!model.quadraticConstraints()) {
    rep.reason = "flexes and stresses present; the second-order theory needs quadratic constraints";
    return;
  }
  const bool exact_case = (k == 1 || s == 1);
  if (!exact_case || k > opt.max_second_order_size || s > opt.max_second_order_size ||
      !rep.flex_basis_computed || !rep.stress_basis_computed) {
    rep.reason = std::to_string(k) + " nontrivial flexes and " + std::to_string(s) +
                 " stresses: deciding second-order rigidity needs the polynomial solver "
                 "(not in this version)";
    return;
  }
  double scale = 0.0;
  const std::vector<Matrix> M = stressForms(model.system(), x, rep.flex_basis, rep.stress_basis, scale);
  const double tol = 1e-8 * std::max(scale, 1e-300);
  bool certified = false;
  if (s == 1) {
    // One stress: prestress stable <=> second-order rigid <=> the form is definite.
    Eigen::SelfAdjointEigenSolver<Matrix> eig(M[0]);
    const Vector& ev = eig.eigenvalues();
    certified = (ev.minCoeff() > tol) || (ev.maxCoeff() < -tol);
  } else {
    // One flex v: blocked <=> some stress has omega^T R(v) v != 0; then a combination of the
    // stresses is positive on it, so prestress stable <=> second-order rigid <=> blocked.
    for (const Matrix& m : M) certified |= std::abs(m(0, 0)) > tol;
  }
  rep.prestress_stable = rep.second_order_rigid = certified;
  if (certified) {
    rep.rigid = Verdict::Rigid;
    rep.reason = "prestress stable (a stress blocks every nontrivial flex)";
  } else {
    rep.reason = "not prestress stable and not second-order rigid; whether it moves needs "
                 "the motion tracker (not in this version)";
  }
}

// Floating-point work of canonicalBasis(B): about 4 N k^2.
double canonicalWork(const Matrix& B) {
  return 4.0 * static_cast<double>(B.rows()) * static_cast<double>(B.cols()) * static_cast<double>(B.cols());
}

}  // namespace

Matrix trivialFlexes(const Model& model, const Vector& x, double tolerance) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension();
  const Matrix G = model.symmetryGenerators(sys.positions(x));
  const int g = static_cast<int>(G.cols());
  const int N = sys.numVariables();
  Matrix free_rows(N, g);
  int pinned_rows = 0;
  for (int b = 0; b < sys.numBlocks(); ++b) pinned_rows += sys.isPinned(b) ? d : 0;
  Matrix A(pinned_rows, g);
  int a = 0;
  for (int b = 0; b < sys.numBlocks(); ++b)
    for (int k = 0; k < d; ++k) {
      const int v = sys.variableIndex(b, k);
      if (v >= 0) free_rows.row(v) = G.row(b * d + k);
      else A.row(a++) = G.row(b * d + k);
    }
  Matrix stabiliser = Matrix::Identity(g, g);
  if (pinned_rows > 0 && g > 0) {
    Eigen::JacobiSVD<Matrix> svd(A, Eigen::ComputeFullV);
    const Vector& s = svd.singularValues();
    int r = 0;
    while (r < s.size() && s[r] > tolerance) ++r;  // G's columns have unit norm
    stabiliser = svd.matrixV().rightCols(g - r);
  }
  return orthonormalColumnSpace(free_rows * stabiliser, tolerance);
}

Matrix canonicalBasis(const Matrix& B) {
  const int N = static_cast<int>(B.rows()), k = static_cast<int>(B.cols());
  Matrix A = B.transpose();  // k x N; reflections from the left act as B -> B H
  for (int i = 0; i < k; ++i) {
    auto rest = A.bottomRows(k - i);
    const Eigen::RowVectorXd norms = rest.colwise().squaredNorm();
    const double best = norms.maxCoeff();
    int j = 0;
    while (j < N && norms[j] < (1.0 - 2e-9) * best) ++j;
    // Householder reflection taking column j of the remaining rows to alpha * e_0.
    Vector v = rest.col(j);
    const double alpha = v[0] >= 0 ? -v.norm() : v.norm();
    v[0] -= alpha;
    const double vn = v.norm();
    if (vn > 0) {
      v /= vn;
      const Eigen::RowVectorXd w = v.transpose() * rest;
      rest.noalias() -= (2.0 * v) * w;
    }
    if (A(i, j) < 0) A.row(i) *= -1.0;
    // Exact zeros where the echelon structure says so.
    A.bottomRows(k - i - 1).col(j).setZero();
  }
  return A.transpose();
}

RigidityReport analyzeRigidity(const Model& model, const Vector& x, const RigidityOptions& opt) {
  const ConstraintSystem& sys = model.system();
  RigidityReport rep;
  rep.variables = sys.numVariables();
  rep.equations = sys.numEquations();
  const SparseMatrix J = sys.jacobian(x);
  Spaces sp;
  if (std::max(rep.variables, rep.equations) <= opt.dense_limit) denseSpaces(J, opt, rep, sp);
  else sparseSpaces(J, opt, rep, sp);
  rep.rank = sp.rank;
  rep.inf_flexes = rep.variables - rep.rank;
  rep.stresses = rep.equations - rep.rank;

  rep.trivial_basis = trivialFlexes(model, x, opt.rank_tolerance);
  rep.trivial = static_cast<int>(rep.trivial_basis.cols());
  rep.nontrivial = rep.inf_flexes - rep.trivial;
  if (rep.nontrivial < 0) {
    rep.warnings.push_back("the rank decision left fewer flexes than trivial motions; "
                           "the realization is close to a rank change (see the singular values)");
    rep.nontrivial = 0;
  }
  rep.inf_rigid = rep.nontrivial == 0;

  if (sp.kernel_formed) {
    // Nontrivial flexes: the part of ker J orthogonal to the trivial flexes.
    const Matrix& T = rep.trivial_basis;
    const Matrix K = sp.kernel - T * (T.transpose() * sp.kernel);
    Matrix Bn(K.rows(), 0);
    if (K.cols() > 0) {
      Eigen::BDCSVD<Matrix> svd(K, Eigen::ComputeThinU);
      int c = 0;
      while (c < svd.singularValues().size() && svd.singularValues()[c] > 0.5) ++c;
      Bn = svd.matrixU().leftCols(c);
    }
    if (Bn.cols() != rep.nontrivial)
      rep.warnings.push_back("the trivial flexes are not all in the numerical kernel");
    rep.flex_basis = canonicalWork(Bn) <= opt.max_canonical_work ? canonicalBasis(Bn) : Bn;
    if (canonicalWork(Bn) > opt.max_canonical_work)
      rep.warnings.push_back("the flex basis is too large to put in canonical form");
    rep.flex_basis_computed = true;
  }
  if (sp.cokernel_formed && canonicalWork(sp.cokernel) <= opt.max_canonical_work) {
    rep.stress_basis = canonicalBasis(sp.cokernel);
    rep.stress_basis_computed = true;
  }
  secondOrderCertificates(model, x, opt, rep);
  return rep;
}

}  // namespace flexure::engine
