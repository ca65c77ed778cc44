// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the small weighted least-squares fits behind LS, WLS, MLS and PU-WLS (thesis ch. 3).
//
// Every fit is done in local coordinates xi_j = A (x_j - x_c) / h: shifted to the fit's centre x_c, rotated
// onto the cloud's intrinsic axes A (rows; 1, 2 or 3 of them) and scaled by the support radius h, so that
// |xi| <= 1 and every basis entry is O(1) (thesis 3.19-3.20; research/mls.md §4.1).
//
// Moment matrix (3.9, 3.24): M = sum_j w_j b(xi_j) b(xi_j)^T. It is Jacobi-equilibrated, M~ = S M S with
// S = diag(M)^(-1/2) (this also tames interpolating weights such as 1/(d^2 + eps^2) at a data point), and
// solved by a pivoted LDLT whose pivot ratio is a cheap lower bound of the condition number. When that ratio
// exceeds kFastPathRatio (or an exact condition number is asked for), a symmetric eigen-decomposition gives
// the exact condition number kappa(M~); a fit with kappa(M~) > kMaxCondition is declared degenerate and the
// caller falls back (wider support, lower degree, Shepard, mask), never solving an ill-conditioned system
// silently.
//
// MLS shape functions (2.20, 3.26): phi_j(x) = w_j b(xi_j)^T M^-1 b(0); with b(0) = e_1 one solve per point.
// Diffuse derivatives (GMLS; Mirzaei et al. 2012): d f / d xi_a ~ c_{1+a}, i.e. the gradient shape functions
// w_j b(xi_j)^T M^-1 e_{2+a} / h. They are exact for polynomials of degree <= m (the fit reproduces them) and
// converge like h^m; they are not the derivative of the moving fit (which would add dM^-1/dx terms).
#ifndef meshfree_LocalFit_h
#define meshfree_LocalFit_h

#include "Common/Kernels.h"
#include "Common/MLSFastPath.h"
#include "Common/NeighborGrid.h"
#include "Common/PolynomialBasis.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace meshfree
{

/// A fit whose equilibrated moment matrix has a larger condition number is degenerate.
constexpr double kMaxCondition = 1e10;
/// MLS: the moving fit uses at least this many neighbours per basis term (see Approximation.h).
constexpr int kMinimumNeighborsPerTerm = 2;
// kFastPathRatio (below this pivot ratio the fast path is trusted) is in MLSFastPath.h.

/// Orthonormal intrinsic axes of a cloud: the first Dimension rows of Axes span it.
struct LocalFrame
{
  int Dimension = 3;
  double Axes[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };

  template <int D>
  inline void Project(const double dx[3], double invH, double* xi) const
  {
    for (int a = 0; a < D; ++a)
    {
      xi[a] = (this->Axes[a][0] * dx[0] + this->Axes[a][1] * dx[1] + this->Axes[a][2] * dx[2]) * invH;
    }
  }
  /// Global vector from local components (g = A^T l).
  inline void Unproject(const double* local, double g[3]) const
  {
    g[0] = g[1] = g[2] = 0.0;
    for (int a = 0; a < this->Dimension; ++a)
    {
      for (int i = 0; i < 3; ++i)
      {
        g[i] += this->Axes[a][i] * local[a];
      }
    }
  }
};

/**
 * The equilibrating scales s_i = 1 / sqrt(M_ii) of a moment matrix (S M S has a unit diagonal); `diagonal(i)`
 * gives M_ii. False, with an infinite condition, when M_00 is not positive and finite or a monomial
 * (numerically) vanishes on every neighbour - the points lie on its zero set (M_ii <= 1e-28 M_00).
 */
template <int Q, class Diagonal>
bool EquilibrationScales(const Diagonal& diagonal, double* s, double& condition)
{
  const double m00 = diagonal(0);
  if (!(m00 > 0.0) || !std::isfinite(m00))
  {
    condition = std::numeric_limits<double>::infinity();
    return false;
  }
  for (int i = 0; i < Q; ++i)
  {
    const double d = diagonal(i);
    if (!(d > 1e-28 * m00))
    {
      condition = std::numeric_limits<double>::infinity();
      return false;
    }
    s[i] = 1.0 / std::sqrt(d);
  }
  return true;
}

/**
 * The robust path of the moment solves: the eigen-decomposition of the equilibrated matrix M. False when it
 * fails or kappa(M) >= kMaxCondition; `condition` receives kappa(M) (infinite when not positive definite).
 */
template <int Q>
bool RobustDecomposition(
  const Eigen::Matrix<double, Q, Q>& M, Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Q, Q>>& eig, double& condition)
{
  eig.compute(M);
  if (eig.info() != Eigen::Success)
  {
    condition = std::numeric_limits<double>::infinity();
    return false;
  }
  const double lmax = eig.eigenvalues()(Q - 1); // ascending
  const double lmin = eig.eigenvalues()(0);
  if (!(lmin > 0.0) || !(lmax < kMaxCondition * lmin))
  {
    condition = lmin > 0.0 ? lmax / lmin : std::numeric_limits<double>::infinity();
    return false;
  }
  condition = lmax / lmin;
  return true;
}

namespace detail
{
/// The robust path of SolveMoment on the equilibrated M (scales s): Y = S V diag(1 / lambda) V^T S B.
template <int Q, class MatB, class MatY>
bool SolveMomentRobust(const Eigen::Matrix<double, Q, Q>& M, const Eigen::Matrix<double, Q, 1>& s, const MatB& B,
  MatY& Y, double& condition)
{
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Q, Q>> eig;
  if (!RobustDecomposition<Q>(M, eig, condition))
  {
    return false;
  }
  const Eigen::Matrix<double, Q, 1> lambda = eig.eigenvalues();
  const auto& V = eig.eigenvectors();
  Y = s.asDiagonal() * (V * (lambda.cwiseInverse().asDiagonal() * (V.transpose() * (s.asDiagonal() * B))));
  return true;
}
} // namespace detail

/**
 * Solves M Y = B for the symmetric positive semi-definite moment matrix M (overwritten), see the file
 * comment. Returns false when M is degenerate (Y untouched). `condition` receives kappa(S M S): exact when
 * exactCondition is set or the robust path ran, else the LDLT pivot ratio (a lower bound).
 */
template <int Q, class MatB, class MatY>
bool SolveMoment(Eigen::Matrix<double, Q, Q>& M, const MatB& B, MatY& Y, bool exactCondition, double& condition)
{
  using Vector = Eigen::Matrix<double, Q, 1>;
  Vector s;
  if (!EquilibrationScales<Q>([&M](int i) { return M(i, i); }, s.data(), condition))
  {
    return false;
  }
  M = s.asDiagonal() * M * s.asDiagonal();
  if (!exactCondition)
  {
    Eigen::LDLT<Eigen::Matrix<double, Q, Q>> ldlt(M);
    if (ldlt.info() == Eigen::Success)
    {
      const Vector d = ldlt.vectorD();
      const double dmax = d.maxCoeff();
      const double dmin = d.minCoeff();
      if (dmin > 0.0 && dmax < kFastPathRatio * dmin)
      {
        condition = dmax / dmin;
        Y = s.asDiagonal() * ldlt.solve(s.asDiagonal() * B);
        return true;
      }
    }
  }
  return detail::SolveMomentRobust<Q>(M, s, B, Y, condition);
}

/**
 * The fast path of SolveMomentFast on the equilibrated M~ (Q x Q, symmetric, column-major) with scales s: the
 * unpivoted LDL^T of M~ (no square roots; one reciprocal per column, so the dependency chain is about half the
 * Cholesky's), then y = S M~^-1 S b. Its pivots d_j are the Cholesky's L_jj^2 and lie in [lambda_min, lambda_max], so
 * max d / min d is again a lower bound of kappa(M~). True, with condition = max d / min d, when every pivot is
 * positive and max d < kFastPathRatio min d; otherwise false, y and condition untouched.
 */
template <int Q>
bool LdltSolve(const double* M, const double* s, const double* b, double* y, double& condition)
{
  double L[Q][Q], pivot[Q], inverse[Q];
  double dmin = 0.0, dmax = 0.0;
  MESHFREE_UNROLL
  for (int j = 0; j < Q; ++j)
  {
    double w[Q]; // L_jk d_k
    double d = M[j * Q + j];
    MESHFREE_UNROLL
    for (int k = 0; k < j; ++k)
    {
      w[k] = L[j][k] * pivot[k];
      d -= L[j][k] * w[k];
    }
    if (!(d > 0.0))
    {
      return false;
    }
    dmin = (j == 0 || d < dmin) ? d : dmin;
    dmax = (j == 0 || dmax < d) ? d : dmax;
    pivot[j] = d;
    inverse[j] = 1.0 / d;
    MESHFREE_UNROLL
    for (int i = j + 1; i < Q; ++i)
    {
      double v = M[j * Q + i];
      MESHFREE_UNROLL
      for (int k = 0; k < j; ++k)
      {
        v -= L[i][k] * w[k];
      }
      L[i][j] = v * inverse[j];
    }
  }
  if (!(dmax < kFastPathRatio * dmin))
  {
    return false;
  }
  condition = dmax / dmin;
  double z[Q];
  MESHFREE_UNROLL
  for (int i = 0; i < Q; ++i)
  {
    double v = s[i] * b[i];
    MESHFREE_UNROLL
    for (int k = 0; k < i; ++k)
    {
      v -= L[i][k] * z[k];
    }
    z[i] = v;
  }
  MESHFREE_UNROLL
  for (int i = Q - 1; i >= 0; --i)
  {
    double v = z[i] * inverse[i];
    MESHFREE_UNROLL
    for (int k = i + 1; k < Q; ++k)
    {
      v -= L[k][i] * z[k];
    }
    z[i] = v;
  }
  MESHFREE_UNROLL
  for (int i = 0; i < Q; ++i)
  {
    y[i] = s[i] * z[i];
  }
  return true;
}

/**
 * SolveMoment (exactCondition off) for one right-hand side with an unpivoted LDL^T (LdltSolve) as the fast path
 * instead of Eigen's pivoted LDLT: the same equilibration, pivot-ratio test and robust path, the solution equal up to
 * rounding, in about a third of the time (the normals' 6 x 6 jets: two or three solves per point).
 */
template <int Q>
bool SolveMomentFast(Eigen::Matrix<double, Q, Q>& M, const Eigen::Matrix<double, Q, 1>& B,
  Eigen::Matrix<double, Q, 1>& Y, double& condition)
{
  Eigen::Matrix<double, Q, 1> s;
  if (!EquilibrationScales<Q>([&M](int i) { return M(i, i); }, s.data(), condition))
  {
    return false;
  }
  M = s.asDiagonal() * M * s.asDiagonal();
  if (LdltSolve<Q>(M.data(), s.data(), B.data(), Y.data(), condition))
  {
    return true;
  }
  return detail::SolveMomentRobust<Q>(M, s, B, Y, condition);
}

/**
 * SolveMoment for the MLS hot loop: M (Q x Q, row-major, upper triangle filled) is equilibrated and
 * factored by a hand-unrolled Cholesky (its pivots d_i satisfy lambda_min <= d_i <= lambda_max, so
 * max d / min d is again a lower bound of the condition number); the first r <= R columns of the identity
 * are solved for, Y[c * Q + a]. The eigen-decomposition path of SolveMoment decides when the pivots are not
 * clearly fine or an exact condition number is asked for. The equilibration and the Cholesky are the shared
 * MESHFREE_HD code of MLSFastPath.h (the CUDA kernels run the same).
 */
template <int Q, int R = Q>
bool SolveMomentIdentity(double* M, int r, bool exactCondition, double* Y, double& condition)
{
  double s[Q];
  if (!mls::EquilibrateMoment<Q>(M, s))
  {
    condition = std::numeric_limits<double>::infinity();
    return false;
  }
  if (!exactCondition && mls::CholeskyIdentitySolve<Q, R>(M, s, r, Y, condition))
  {
    return true;
  }
  Eigen::Matrix<double, Q, Q> m = Eigen::Map<const Eigen::Matrix<double, Q, Q, Eigen::RowMajor>>(M);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Q, Q>> eig;
  if (!RobustDecomposition<Q>(m, eig, condition))
  {
    return false;
  }
  const auto& lambda = eig.eigenvalues();
  const auto& V = eig.eigenvectors();
  for (int c = 0; c < r; ++c)
  {
    // y = S V diag(1/lambda) V^T S e_c
    Eigen::Matrix<double, Q, 1> t = V.row(c).transpose() * s[c];
    t = t.cwiseQuotient(lambda);
    const Eigen::Matrix<double, Q, 1> y = V * t;
    for (int i = 0; i < Q; ++i)
    {
      Y[c * Q + i] = s[i] * y(i);
    }
  }
  return true;
}

/// Per-thread buffers of the local fits (grown once, reused for every evaluation point).
struct FitScratch
{
  std::vector<Index> Ids;
  std::vector<double> Dist2;
  std::vector<double> Xi;      // n * 3 local coordinates
  std::vector<double> Weights; // n
  std::vector<double> WeightDerivatives; // n * 3
  std::vector<double> Rows;    // n * Q basis rows
  std::vector<double> Phi;     // n shape functions
  std::vector<double> DPhi;    // 3 * n gradient shape functions (local axes, per unit xi)
  std::vector<double> Work;    // per-component accumulators of PU-WLS and SPH
  std::vector<std::pair<double, Index>> Candidates; // k-nearest selection
  double RadiusGuess = 0.0;    // distance to the k-th neighbour of the previous query
  double LastQuery[3] = { 0.0, 0.0, 0.0 }; // position of the previous query

  void Reserve(size_t n)
  {
    if (this->Weights.size() < n)
    {
      this->Xi.resize(3 * n);
      this->Weights.resize(n);
      this->WeightDerivatives.resize(3 * n);
      this->Rows.resize(kMaxBasisSize * n);
      this->Phi.resize(n);
      this->DPhi.resize(3 * n);
    }
  }
};

/**
 * MLS shape functions at the centre of the local coordinates (xi = 0) from n neighbours with local
 * coordinates xi (stride 3) and weights w (all > 0). Fills phi[n] and, when gradient, dphi[a * n + j] (per
 * unit xi_a: divide by h for physical units). Returns false when the fit is degenerate.
 */
template <int D, int M>
bool MLSShapeFunctions(const double* xi, const double* w, const double* dw, int n, bool gradient,
  bool exactCondition, double* rows, double* phi, double* dphi, double& condition)
{
  using Basis = PolynomialBasis<D, M>;
  constexpr int Q = Basis::Size;
  if (n < Q)
  {
    condition = std::numeric_limits<double>::infinity();
    return false;
  }
  double moment[Q * Q] = {};
  for (int j = 0; j < n; ++j)
  {
    double* p = rows + static_cast<size_t>(j) * Q;
    mls::EvaluateBasis<D, M>(xi + 3 * j, p);
    mls::AccumulateMoment<Q>(p, w[j], moment);
  }
  constexpr int R = mls::MLSColumns<D, M>::Value;
  const int r = gradient ? R : 1;
  double y[Q * R];
  if (!SolveMomentIdentity<Q, R>(moment, r, exactCondition, y, condition))
  {
    return false;
  }
  for (int j = 0; j < n; ++j)
  {
    phi[j] = w[j] * mls::ShapeDot<Q>(rows + static_cast<size_t>(j) * Q, y);
  }
  if (gradient && M > 0)
  {
    for (int c = 1; c < R; ++c)
    {
      const double* yc = y + c * Q;
      double* out = dphi + static_cast<size_t>(c - 1) * n;
      for (int j = 0; j < n; ++j)
      {
        out[j] = w[j] * mls::ShapeDot<Q>(rows + static_cast<size_t>(j) * Q, yc);
      }
    }
  }
  if (gradient && M == 0)
  {
    // Shepard: the diffuse derivative vanishes, so take the true one at fixed h,
    // d phi_j = (d w_j - phi_j sum_k d w_k) / sum_k w_k, with dw the weights' derivatives.
    const double invSum = y[0]; // M^-1 = 1 / sum w
    for (int a = 0; a < D; ++a)
    {
      double sum = 0.0;
      for (int j = 0; j < n; ++j)
      {
        sum += dw[3 * j + a];
      }
      for (int j = 0; j < n; ++j)
      {
        dphi[a * n + j] = (dw[3 * j + a] - phi[j] * sum) * invSum;
      }
    }
  }
  return true;
}

/// Run-time dispatch of MLSShapeFunctions on (dimension 0..3, degree 0..3). dw (stride 3, derivative of
/// w_j with respect to the evaluation point, per unit xi) is read only for degree 0 with gradient.
bool ComputeMLSShapeFunctions(int dimension, int degree, const double* xi, const double* w,
  const double* dw, int n, bool gradient, bool exactCondition, double* rows, double* phi, double* dphi,
  double& condition);

/**
 * Coefficients of one weighted fit (LS with w = 1, WLS, a PU-WLS centre): K (Q x C, row-major) solves
 * M K = sum_j w_j b(xi_j) f_j^T, with f_j = values[ids[j] * C .. + C) (ids == nullptr: j itself).
 * xi has stride 3. Returns false when degenerate.
 */
bool ComputeFitCoefficients(int dimension, int degree, const double* xi, const double* w, int n,
  const Index* ids, const double* values, int components, bool exactCondition, double* coefficients,
  double& condition);

/// Accumulates a fit's moment matrix and right-hand side (for fits over many points done in parallel):
/// moment (Q x Q) += sum w b b^T, rhs (Q x C) += sum w b f^T, both row-major.
void AccumulateFit(int dimension, int degree, const double* xi, const double* w, int n, const Index* ids,
  const double* values, int components, double* moment, double* rhs);

/// Solves an accumulated fit (see AccumulateFit); moment is overwritten.
bool SolveAccumulatedFit(int dimension, int degree, double* moment, const double* rhs, int components,
  bool exactCondition, double* coefficients, double& condition);

/// Evaluates a fitted polynomial b(xi)^T K at xi (stride-free, `dimension` entries): out[C] and, when
/// gradient != nullptr, gradient[a * C + c] = d/dxi_a (per unit xi).
void EvaluateFit(int dimension, int degree, const double* xi, const double* coefficients, int components,
  double* out, double* gradient);

} // namespace meshfree

#endif
