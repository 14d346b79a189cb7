#include "engine/rigidity.h"

#include "engine/factorization.h"

#include <Eigen/Dense>
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

// A unit vector l with l^T M l = 0 (M symmetric k x k), the one closest to `target`
// (unit), or an empty vector when M is definite.
Vector nullConeDirection(const Matrix& M, const Vector& target, double tol) {
  Eigen::SelfAdjointEigenSolver<Matrix> eig(M);
  const Vector& mu = eig.eigenvalues();
  const Matrix& E = eig.eigenvectors();
  const int k = static_cast<int>(M.rows());
  // In eigen-coordinates y: sum mu_i y_i^2 = 0. Null eigenvalues give null directions; else
  // combine a positive and a negative one: y = sqrt(|mu_n|) e_p + sqrt(mu_p) e_n.
  Vector best;
  double best_dot = -2.0;
  auto consider = [&](Vector l) {
    l.normalize();
    if (l.dot(target) < 0) l = -l;
    if (l.dot(target) > best_dot + 1e-12) best_dot = l.dot(target), best = l;
  };
  for (int i = 0; i < k; ++i) {
    if (std::abs(mu[i]) <= tol) {
      consider(E.col(i));
      continue;
    }
    for (int j = 0; j < k; ++j)
      if (mu[i] > tol && mu[j] < -tol) {
        // both null vectors of this pair
        const double a = std::sqrt(-mu[j]), b = std::sqrt(mu[i]);
        consider(a * E.col(i) + b * E.col(j));
        consider(a * E.col(i) - b * E.col(j));
      }
  }
  return best;
}

void autoFlex(const Model& model, const Vector& x, RigidityReport& rep, const std::vector<Matrix>* forms,
              double scale) {
  const int k = rep.nontrivial;
  if (k == 0) return;
  const Vector equal = Vector::Constant(k, 1.0 / std::sqrt(static_cast<double>(k)));
  rep.auto_flex = equal;
  if (rep.stresses == 0) {
    rep.auto_flex_note = "equal coefficients (no stress: every flex extends to a motion)";
    return;
  }
  if (forms && forms->size() == 1) {
    const Vector l = nullConeDirection((*forms)[0], equal, 1e-8 * std::max(scale, 1e-300));
    if (l.size() == k) {
      rep.auto_flex = l;
      rep.auto_flex_note = "a flex that the single stress does not block (null cone of the stress "
                           "energy), the one closest to equal coefficients";
    } else {
      rep.auto_flex_note = "equal coefficients; the single stress blocks every flex";
    }
    return;
  }
  rep.auto_flex_note = "equal coefficients in the canonical basis, as the reference package does "
                       "(not checked for blocking: with several stresses that needs the "
                       "second-order solver)";
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
    autoFlex(model, x, rep, nullptr, 0.0);
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
    autoFlex(model, x, rep, nullptr, 0.0);
    rep.reason = "flexes and stresses present; the second-order theory needs quadratic constraints";
    return;
  }
  const bool exact_case = (k == 1 || s == 1);
  if (!exact_case || k > opt.max_second_order_size || s > opt.max_second_order_size ||
      !rep.flex_basis_computed || !rep.stress_basis_computed) {
    autoFlex(model, x, rep, nullptr, 0.0);
    rep.reason = std::to_string(k) + " nontrivial flexes and " + std::to_string(s) +
                 " stresses: deciding second-order rigidity needs the polynomial solver "
                 "(not in this version); `flexure track` shows whether it moves";
    return;
  }
  double scale = 0.0;
  const std::vector<Matrix> M = stressForms(model.system(), x, rep.flex_basis, rep.stress_basis, scale);
  autoFlex(model, x, rep, &M, scale);
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
    rep.reason = "not prestress stable and not second-order rigid; `flexure track` shows "
                 "whether it moves (the analysis does not track yet)";
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

Matrix nontrivialPart(const Matrix& kernel, const Matrix& trivial) {
  const Matrix K = kernel - trivial * (trivial.transpose() * kernel);
  if (K.cols() == 0) return Matrix(K.rows(), 0);
  // Singular values are ~1 on the nontrivial part and ~0 on the trivial one.
  Vector s;
  Matrix U;
  denseSvd(K, s, &U, nullptr, false);
  int c = 0;
  while (c < s.size() && s[c] > 0.5) ++c;
  return U.leftCols(c);
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
  const JacobianFactorization fac(J, {opt.rank_tolerance, opt.dense_limit});
  rep.method = fac.method();
  rep.tolerance = fac.threshold();
  rep.rank = fac.rank();
  rep.inf_flexes = rep.variables - rep.rank;
  rep.stresses = rep.equations - rep.rank;
  rep.sigma_max = fac.sigmaMax();
  rep.sigma_smallest_kept = fac.sigmaSmallestKept();
  Matrix kernel, cokernel;
  const bool kernel_formed =
      static_cast<double>(rep.variables) * rep.inf_flexes <= static_cast<double>(opt.max_basis_entries);
  if (kernel_formed) kernel = fac.kernel();
  rep.sigma_largest_dropped = fac.sigmaLargestDropped();
  bool cokernel_formed =
      static_cast<double>(rep.equations) * rep.stresses <= static_cast<double>(opt.max_basis_entries) &&
      (fac.dense() || rep.stresses <= opt.max_sparse_stress_basis);
  if (cokernel_formed) {
    cokernel = fac.cokernel();
    if (cokernel.cols() != rep.stresses) {
      cokernel_formed = false;
      rep.warnings.push_back("the stress basis was not formed: the two sparse QRs disagree on the rank");
    }
  }

  rep.trivial_basis = trivialFlexes(model, x, opt.rank_tolerance);
  rep.trivial = static_cast<int>(rep.trivial_basis.cols());
  rep.nontrivial = rep.inf_flexes - rep.trivial;
  if (rep.nontrivial < 0) {
    rep.warnings.push_back("the rank decision left fewer flexes than trivial motions; "
                           "the realization is close to a rank change (see the singular values)");
    rep.nontrivial = 0;
  }
  rep.inf_rigid = rep.nontrivial == 0;

  if (kernel_formed) {
    // Nontrivial flexes: the part of ker J orthogonal to the trivial flexes.
    const Matrix Bn = nontrivialPart(kernel, rep.trivial_basis);
    if (Bn.cols() != rep.nontrivial)
      rep.warnings.push_back("the trivial flexes are not all in the numerical kernel");
    rep.flex_basis = canonicalWork(Bn) <= opt.max_canonical_work ? canonicalBasis(Bn) : Bn;
    if (canonicalWork(Bn) > opt.max_canonical_work)
      rep.warnings.push_back("the flex basis is too large to put in canonical form");
    rep.flex_basis_computed = true;
  }
  if (cokernel_formed && canonicalWork(cokernel) <= opt.max_canonical_work) {
    rep.stress_basis = canonicalBasis(cokernel);
    rep.stress_basis_computed = true;
  }
  secondOrderCertificates(model, x, opt, rep);
  return rep;
}

}  // namespace flexure::engine
