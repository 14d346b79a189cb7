#include "engine/second_order.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <array>
#include <map>

#include "engine/homotopy.h"
#include "engine/model.h"
#include "engine/random.h"

namespace flexure::engine {

std::vector<Matrix> stressEnergyForms(const ConstraintSystem& sys, const Vector& x, const Matrix& B,
                                      const Matrix& S, double* scale_out) {
  const int k = static_cast<int>(B.cols()), s = static_cast<int>(S.cols());
  std::vector<Matrix> M(static_cast<size_t>(s), Matrix::Zero(k, k));
  for (int a = 0; a < k; ++a)
    for (int b = a; b < k; ++b) {
      const Vector h = sys.secondDerivative(x, B.col(a), B.col(b));
      for (int j = 0; j < s; ++j) M[static_cast<size_t>(j)](a, b) = M[static_cast<size_t>(j)](b, a) = S.col(j).dot(h);
    }
  // The scale: the largest |w^T R(u) u| a unit stress w could give on any unit displacement u,
  // sum_i |w_i| |H_i| with |H_i| the spectral norm of equation i's Hessian. It depends on
  // neither the flexes nor the configuration's special position: a flex along which every
  // constraint stays exactly satisfied (a rectangle of fixed angles stretched, a linear motion)
  // has zero second derivatives, and a scale taken from them (as before) made rounding noise of
  // 1e-17 into a "positive definite" form. For orthonormal flexes, |M_j(a, b)| <= scale.
  double scale = 0.0;
  if (s > 0 && k > 0) {
    std::vector<char> support(static_cast<size_t>(S.rows()), 0);
    const double largest = S.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < S.rows(); ++i) support[static_cast<size_t>(i)] = S.row(i).cwiseAbs().maxCoeff() > 1e-14 * largest;
    const Vector norms = sys.hessianNorms(x, &support);
    for (int j = 0; j < s; ++j) scale = std::max(scale, S.col(j).cwiseAbs().dot(norms));
  }
  if (scale > 0)
    for (Matrix& m : M) m /= scale;
  if (scale_out) *scale_out = scale;
  return M;
}

namespace {

// An orthonormal basis (Frobenius inner product) of the span of the forms, keeping directions
// with singular value above `tol`; `to_basis` (s x r) maps basis coefficients back to
// combinations of the given forms: basis_j = sum_i to_basis(i, j) forms_i.
struct FormSpan {
  std::vector<Matrix> basis;
  Matrix to_basis;
  double largest = 0;  // the largest singular value
};

FormSpan orthonormalSpan(const std::vector<Matrix>& forms, double tol) {
  FormSpan out;
  const int s = static_cast<int>(forms.size());
  if (s == 0) return out;
  const int k = static_cast<int>(forms[0].rows());
  Matrix F(s, k * k);
  for (int i = 0; i < s; ++i) F.row(i) = Eigen::Map<const Eigen::RowVectorXd>(forms[static_cast<size_t>(i)].data(), k * k);
  Eigen::JacobiSVD<Matrix> svd(F, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Vector& sv = svd.singularValues();
  out.largest = sv.size() ? sv[0] : 0.0;
  int r = 0;
  while (r < sv.size() && sv[r] > tol) ++r;
  out.to_basis = svd.matrixU().leftCols(r) * sv.head(r).cwiseInverse().asDiagonal();
  for (int j = 0; j < r; ++j) {
    Matrix m = Eigen::Map<const Matrix>(svd.matrixV().col(j).data(), k, k);
    out.basis.push_back(0.5 * (m + m.transpose()));
  }
  return out;
}

double smallestEigenvalue(const Matrix& M) {
  return Eigen::SelfAdjointEigenSolver<Matrix>(M, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

Matrix combination(const std::vector<Matrix>& forms, const Vector& c) {
  Matrix C = Matrix::Zero(forms[0].rows(), forms[0].cols());
  for (size_t i = 0; i < forms.size(); ++i) C += c[static_cast<Eigen::Index>(i)] * forms[i];
  return C;
}

// A unit vector l with l^T M l = 0 (M symmetric), the one closest to `target` up to sign, or
// an empty vector when M is definite beyond tol.
Vector nullConeDirection(const Matrix& M, const Vector& target, double tol) {
  Eigen::SelfAdjointEigenSolver<Matrix> eig(M);
  const Vector& mu = eig.eigenvalues();
  const Matrix& E = eig.eigenvectors();
  const int k = static_cast<int>(M.rows());
  // In eigen-coordinates y: sum mu_i y_i^2 = 0. Null eigenvalues give null directions; else
  // combine a positive and a negative one: y = sqrt(|mu_n|) e_p +- sqrt(mu_p) e_n.
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
        const double a = std::sqrt(-mu[j]), b = std::sqrt(mu[i]);
        consider(a * E.col(i) + b * E.col(j));
        consider(a * E.col(i) - b * E.col(j));
      }
  }
  return best;
}

double maxForm(const std::vector<Matrix>& forms, const Vector& l) {
  double r = 0;
  for (const Matrix& m : forms) r = std::max(r, std::abs(l.dot(m * l)));
  return r;
}

// Gauss-Newton (minimum-norm steps) on Q_j(l) = 0, |l|^2 = 1 from l.
Vector projectOntoZeros(const std::vector<Matrix>& forms, Vector l) {
  const int k = static_cast<int>(l.size()), r = static_cast<int>(forms.size());
  Matrix J(r + 1, k);
  Vector G(r + 1);
  for (int it = 0; it < 200; ++it) {
    for (int j = 0; j < r; ++j) {
      const Vector ml = forms[static_cast<size_t>(j)] * l;
      G[j] = l.dot(ml);
      J.row(j) = 2.0 * ml.transpose();
    }
    G[r] = l.squaredNorm() - 1.0;
    J.row(r) = 2.0 * l.transpose();
    if (G.cwiseAbs().maxCoeff() < 1e-17) break;
    const Vector step = J.completeOrthogonalDecomposition().solve(G);
    if (!step.allFinite()) break;
    l -= step;
    if (step.norm() < 1e-16) break;
  }
  return l.normalized();
}

// The critical points of f(l) = sum_j (l^T C_j l)^2 on the unit sphere, as the eigenvectors of
// its gradient: grad f(l) = l, i.e. 4 sum_j (l^T C_j l) C_j l - l = 0 (k cubics in k unknowns).
// By homogeneity (l . grad f = 4 f) a real critical direction t with f(t) > 0 gives the
// solutions l = +-t / (2 sqrt f(t)); l = 0 is one more. For a generic quartic f all 3^k paths
// end at finite nonsingular solutions (Cartwright-Sturmfels: (3^k - 1) / 2 eigenvector pairs).
PolynomialSystem eigenvectorSystem(const std::vector<Matrix>& C) {
  const int k = static_cast<int>(C[0].rows());
  PolynomialSystem sys(k);
  for (int a = 0; a < k; ++a) {
    std::map<std::vector<int>, double> terms;
    for (const Matrix& m : C)
      for (int b = 0; b < k; ++b)
        for (int c = 0; c < k; ++c) {
          if (m(b, c) == 0) continue;
          for (int d = 0; d < k; ++d) {
            if (m(a, d) == 0) continue;
            std::vector<int> e(static_cast<size_t>(k), 0);
            ++e[static_cast<size_t>(b)], ++e[static_cast<size_t>(c)], ++e[static_cast<size_t>(d)];
            terms[e] += 4.0 * m(b, c) * m(a, d);
          }
        }
    std::vector<int> e(static_cast<size_t>(k), 0);
    e[static_cast<size_t>(a)] = 1;
    terms[e] -= 1.0;
    std::vector<Monomial> poly;
    for (const auto& [ex, v] : terms)
      if (v != 0) poly.push_back({Complex(v, 0), ex});
    sys.add(std::move(poly));
  }
  return sys;
}

double sumOfSquares(const std::vector<Matrix>& B, const Vector& l) {
  double f = 0;
  for (const Matrix& m : B) f += std::pow(l.dot(m * l), 2);
  return f;
}

}  // namespace

namespace {

// maximise t subject to S(y, t) = A0 + sum y_i A_i - t I > 0 and |y| < radius, by the
// log-barrier method: Newton on tau t + log det S + log(radius^2 - |y|^2) with tau growing.
// t is always a lower bound of the optimum; on the central path the optimum is at most
// t + nu / tau (nu = dim + 1). Stops as soon as t > stop_above (a certificate), or when the
// optimum is proved to be at most stop_above.
struct LmiResult {
  Vector y;
  double t = 0;
  double upper = 0;
  int newton_steps = 0;
};

LmiResult maximizeLmi(const Matrix& A0, const std::vector<Matrix>& A, double radius, double stop_above) {
  const int n = static_cast<int>(A0.rows()), r = static_cast<int>(A.size());
  const double R2 = radius * radius;
  LmiResult out;
  Vector y = Vector::Zero(r);
  // A strictly feasible start: t below the smallest eigenvalue of A0.
  double t = smallestEigenvalue(A0) - 1.0;
  double tau = 1.0;
  const double nu = n + 1.0;
  auto barrier = [&](const Vector& yy, double tt, double* value, Eigen::LLT<Matrix>* chol) -> bool {
    const double rr = yy.squaredNorm();
    if (rr >= R2) return false;
    Matrix S = A0;
    for (int i = 0; i < r; ++i) S += yy[i] * A[static_cast<size_t>(i)];
    S.diagonal().array() -= tt;
    Eigen::LLT<Matrix> llt(S);
    if (llt.info() != Eigen::Success) return false;
    double logdet = 0;
    for (int i = 0; i < n; ++i) {
      const double d = llt.matrixL()(i, i);
      if (!(d > 0)) return false;
      logdet += 2.0 * std::log(d);
    }
    *value = tau * tt + logdet + std::log(R2 - rr);
    if (chol) *chol = std::move(llt);
    return true;
  };
  for (int outer = 0; outer < 80; ++outer) {
    for (int inner = 0; inner < 100; ++inner) {
      double phi;
      Eigen::LLT<Matrix> llt;
      if (!barrier(y, t, &phi, &llt)) break;  // cannot happen: the iterates stay feasible
      const Matrix Sinv = llt.solve(Matrix::Identity(n, n));
      std::vector<Matrix> W(static_cast<size_t>(r + 1));
      for (int j = 0; j < r; ++j) W[static_cast<size_t>(j)] = Sinv * A[static_cast<size_t>(j)];
      W[static_cast<size_t>(r)] = -Sinv;
      const double rr = y.squaredNorm();
      Vector g(r + 1);
      Matrix H(r + 1, r + 1);
      for (int a = 0; a <= r; ++a) {
        g[a] = W[static_cast<size_t>(a)].trace();
        for (int b = a; b <= r; ++b)
          H(a, b) = H(b, a) = -(W[static_cast<size_t>(a)].array() * W[static_cast<size_t>(b)].transpose().array()).sum();
      }
      g[r] += tau;
      g.head(r) -= 2.0 * y / (R2 - rr);
      H.topLeftCorner(r, r) -= 2.0 / (R2 - rr) * Matrix::Identity(r, r) + 4.0 / std::pow(R2 - rr, 2) * y * y.transpose();
      const Vector step = (-H).ldlt().solve(g);
      const double decrement = g.dot(step);
      ++out.newton_steps;
      if (!step.allFinite() || decrement < 1e-12) break;
      double alpha = 1.0, phi_new;
      int halvings = 0;
      while (!barrier(y + alpha * step.head(r), t + alpha * step[r], &phi_new, nullptr) ||
             phi_new < phi + 0.25 * alpha * decrement) {
        alpha *= 0.5;
        if (++halvings > 60) break;
      }
      if (halvings > 60) break;
      y += alpha * step.head(r);
      t += alpha * step[r];
      if (t > stop_above) break;
    }
    if (t > stop_above || t + nu / tau <= stop_above) break;
    tau *= 8.0;
  }
  out.y = y;
  out.t = t;
  out.upper = t + nu / tau;
  return out;
}

// A lower bound of min over |l| = 1 of f(l) = sum_j (l^T B_j l)^2, by sums of squares: the
// largest g such that f(l) - g |l|^4 is a sum of squares of quadratic forms, i.e. equals
// m^T S m with S positive semidefinite, m = (l_a^2, sqrt 2 l_a l_b (a < b)). Every S with
// m^T S m = f - g |l|^4 is G_f - g I + L with L in the space of Gram matrices of the zero form.
// Returns a value > stop_above as soon as one is certified.
double sumOfSquaresBound(const std::vector<Matrix>& B, double stop_above) {
  const int k = static_cast<int>(B[0].rows());
  const int N = k * (k + 1) / 2;
  // Monomials m_p = c_p l_a l_b.
  std::vector<std::pair<int, int>> mono;
  std::vector<double> coef;
  for (int a = 0; a < k; ++a) mono.push_back({a, a}), coef.push_back(1.0);
  for (int a = 0; a < k; ++a)
    for (int b = a + 1; b < k; ++b) mono.push_back({a, b}), coef.push_back(std::sqrt(2.0));
  // G_f = sum_j b_j b_j^T with l^T B_j l = b_j . m.
  Matrix G = Matrix::Zero(N, N);
  for (const Matrix& m : B) {
    Vector bj(N);
    for (int p = 0; p < N; ++p) {
      const auto [a, b] = mono[static_cast<size_t>(p)];
      bj[p] = a == b ? m(a, a) : 2.0 * m(a, b) / std::sqrt(2.0);
    }
    G += bj * bj.transpose();
  }
  // The map from symmetric S (entries p <= q) to the coefficients of the quartic m^T S m.
  std::map<std::array<int, 4>, int> quartic;
  std::vector<std::pair<int, int>> entries;
  std::vector<std::pair<int, double>> image;  // per entry: quartic index, coefficient
  for (int p = 0; p < N; ++p)
    for (int q = p; q < N; ++q) {
      std::array<int, 4> e{mono[static_cast<size_t>(p)].first, mono[static_cast<size_t>(p)].second,
                           mono[static_cast<size_t>(q)].first, mono[static_cast<size_t>(q)].second};
      std::sort(e.begin(), e.end());
      const auto it = quartic.emplace(e, static_cast<int>(quartic.size())).first;
      entries.push_back({p, q});
      image.push_back({it->second, (p == q ? 1.0 : 2.0) * coef[static_cast<size_t>(p)] * coef[static_cast<size_t>(q)]});
    }
  Matrix M = Matrix::Zero(static_cast<Eigen::Index>(quartic.size()), static_cast<Eigen::Index>(entries.size()));
  for (size_t e = 0; e < entries.size(); ++e) M(image[e].first, static_cast<Eigen::Index>(e)) = image[e].second;
  Eigen::JacobiSVD<Matrix> svd(M, Eigen::ComputeFullV);
  const int rank = static_cast<int>(svd.rank());
  std::vector<Matrix> L;
  for (int c = rank; c < M.cols(); ++c) {
    Matrix Z = Matrix::Zero(N, N);
    for (size_t e = 0; e < entries.size(); ++e) {
      const auto [p, q] = entries[e];
      Z(p, q) = Z(q, p) = svd.matrixV()(static_cast<Eigen::Index>(e), c);
    }
    L.push_back(std::move(Z));
  }
  return maximizeLmi(G, L, 100.0, stop_above).t;
}

}  // namespace

PrestressResult maximizeStressMargin(const std::vector<Matrix>& forms, double tolerance) {
  PrestressResult out;
  const int s = static_cast<int>(forms.size());
  if (s == 0) return out;
  const int k = static_cast<int>(forms[0].rows());
  out.coefficients = Vector::Zero(s);
  const FormSpan span = orthonormalSpan(forms, 1e-3 * tolerance);
  const int r = static_cast<int>(span.basis.size());
  if (r == 0 || k == 0) return out;
  // In the orthonormal basis: maximise t with sum c_j B_j - t I > 0, |c| < 1. A unit combination
  // of the given forms has |c| <= span.largest in basis coordinates, so the threshold scales.
  const double tol = tolerance / span.largest;
  const LmiResult lmi = maximizeLmi(Matrix::Zero(k, k), span.basis, 1.0, tol);
  out.newton_steps = lmi.newton_steps;
  Vector w = span.to_basis * lmi.y;
  if (w.norm() > 0) w.normalize();
  out.coefficients = w;
  out.margin = w.norm() > 0 ? smallestEigenvalue(combination(forms, w)) : 0.0;
  out.stable = out.margin > tolerance;
  out.upper_bound = out.stable ? std::numeric_limits<double>::quiet_NaN() : lmi.upper * span.largest;
  return out;
}

BlockedFlexResult findUnblockedFlex(const std::vector<Matrix>& forms, const Vector& target,
                                    const BlockedFlexOptions& opt) {
  BlockedFlexResult out;
  const int k = static_cast<int>(target.size());
  const Vector unit_target = target.normalized();
  auto accept = [&](Vector l, const std::string& note) {
    if (l.dot(unit_target) < 0) l = -l;
    out.outcome = BlockedFlexResult::Outcome::Unblocked;
    out.flex = l;
    out.residual = maxForm(forms, l);
    out.note = note;
    return out;
  };
  // Forms below the tolerance vanish on every unit flex: only the rest can block.
  const FormSpan span = orthonormalSpan(forms, opt.zero_tolerance);
  const int r = static_cast<int>(span.basis.size());
  if (r == 0) return accept(unit_target, "no stress energy form is nonzero: no flex is blocked");
  if (k == 1) {
    out.outcome = BlockedFlexResult::Outcome::AllBlocked;
    out.lower_bound = 1.0;
    out.note = "one flex, and a stress energy form is nonzero on it";
    return out;
  }
  if (r == 1) {
    // One form (up to scale): a real zero on the sphere exists iff it is not definite.
    const Matrix m = combination(forms, span.to_basis.col(0).normalized());
    const Vector l = nullConeDirection(m, unit_target, opt.zero_tolerance);
    if (l.size() == k) return accept(l, "the stress energy forms span one form, which is indefinite or singular");
    out.outcome = BlockedFlexResult::Outcome::AllBlocked;
    const Vector ev = Eigen::SelfAdjointEigenSolver<Matrix>(span.basis[0], Eigen::EigenvaluesOnly).eigenvalues();
    out.lower_bound = std::pow(std::min(std::abs(ev[0]), std::abs(ev[k - 1])), 2);
    out.note = "the stress energy forms span one form, which is definite";
    return out;
  }
  // A certificate that every flex is blocked: sum_j Q_j^2 - g |l|^4 is a sum of squares, g > 0.
  if (k <= opt.max_sos_flexes) {
    const double g = sumOfSquaresBound(span.basis, 1e-9);
    if (g > 1e-9) {
      out.outcome = BlockedFlexResult::Outcome::AllBlocked;
      out.lower_bound = g;
      out.note = "sum-of-squares certificate: the sum of squares of the stress energy forms minus " + shortNumber(g) +
                 " |l|^4 is a sum of squares";
      return out;
    }
  }
  if (k > opt.max_flexes) {
    out.note = std::to_string(k) + " flexes: no sum-of-squares certificate, and the critical-point homotopy "
               "(3^k paths) is limited to " + std::to_string(opt.max_flexes) + " flexes";
    return out;
  }
  // f_eps = f + eps g with g = sum_j (l^T R_j l)^2 for k random forms R_j (spectral norm 1):
  // a generic perturbation, positive on the sphere, so every critical point of f_eps is isolated,
  // nonsingular and real-scaled; min f >= min f_eps - eps k on the unit sphere.
  Random rng(opt.seed);
  double eps = 1e-3;
  for (int attempt = 0; attempt < 3; ++attempt, eps *= 1e-3) {
    std::vector<Matrix> perturbation;
    for (int j = 0; j < k; ++j) {
      Matrix R(k, k);
      for (int p = 0; p < k; ++p)
        for (int q = 0; q <= p; ++q) R(p, q) = R(q, p) = rng.gaussian();
      const double norm = Eigen::SelfAdjointEigenSolver<Matrix>(R, Eigen::EigenvaluesOnly).eigenvalues().cwiseAbs().maxCoeff();
      perturbation.push_back(std::sqrt(eps) * R / norm);
    }
    HomotopyOptions hopt;
    hopt.seed = opt.seed + 7919u * static_cast<std::uint64_t>(attempt + 1);
    std::vector<Matrix> C = span.basis;
    C.insert(C.end(), perturbation.begin(), perturbation.end());
    const HomotopyResult h = solveTotalDegree(eigenvectorSystem(C), hopt);
    out.paths += h.paths;
    out.failed_paths += h.failed;
    // Real critical directions (near-real ones too: more candidates only lower the bound).
    std::vector<std::pair<double, Vector>> critical;
    double lowest = std::numeric_limits<double>::infinity();
    for (const auto* list : {&h.solutions, &h.singular})
      for (const Solution& sol : *list) {
        const CVector& x = sol.x;
        if (x.norm() < 1e-8 || x.imag().norm() > 1e-6 * x.norm()) continue;  // l = 0, or not real
        const Vector l = x.real().normalized();
        const double f = sumOfSquares(span.basis, l);
        critical.emplace_back(f, l);
        lowest = std::min(lowest, f + sumOfSquares(perturbation, l));
      }
    out.real_critical_points = static_cast<int>(critical.size());
    std::sort(critical.begin(), critical.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    // The lowest critical points, refined onto Q = 0.
    Vector best;
    for (size_t i = 0; i < critical.size() && i < 8; ++i) {
      Vector l = projectOntoZeros(span.basis, critical[i].second);
      if (!(maxForm(forms, l) <= opt.zero_tolerance)) continue;
      if (l.dot(unit_target) < 0) l = -l;
      if (best.size() == 0 || l.dot(unit_target) > best.dot(unit_target) + 1e-12) best = l;
    }
    if (best.size() == k)
      return accept(best, "a real zero of the stress energy forms on the unit sphere, refined from a "
                          "critical point of their sum of squares (" + std::to_string(h.paths) + " homotopy paths)");
    if (h.failed == 0 && !critical.empty() && lowest - eps * k > 0) {
      out.outcome = BlockedFlexResult::Outcome::AllBlocked;
      out.lower_bound = lowest - eps * k;
      out.note = "every homotopy path tracked (" + std::to_string(h.paths) + "): the sum of squares of the "
                 "stress energy forms is positive on the unit sphere";
      return out;
    }
  }
  out.note = "the critical-point homotopy neither found an unblocked flex nor bounded the forms away from zero";
  return out;
}

}  // namespace flexure::engine
