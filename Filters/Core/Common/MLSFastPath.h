// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the fast path of the MLS moment solve (LocalFit.h) as MESHFREE_HD code, the one source of its
// arithmetic for the CPU (SolveMomentIdentity, MLSShapeFunctions) and the CUDA kernels (cuda/ApproximationDevice.cu).
//
// Pieces, on raw pointers with compile-time sizes (loops unrolled: register arrays see constant indices only,
// which keeps device code off the stack):
// - EvaluateBasis<D, M>: the monomials b(xi) in PolynomialBasis' order and with its products (p_i = p_parent xi_v).
// - AccumulateMoment<Q>: M += w b b^T (upper triangle, row-major Q x Q).
// - EquilibrateMoment<Q>: Jacobi equilibration M~ = S M S, S = diag(M)^(-1/2) (both triangles written); false
//   when the fit is degenerate (M_00 not positive and finite, or a monomial vanishing on every neighbour).
// - CholeskyIdentitySolve<Q, R>: the unpivoted, unrolled Cholesky of M~ with the pivot-ratio test (its pivots d_i
//   lie in [lambda_min, lambda_max], so max d / min d is a lower bound of kappa(M~)), then y_c = S M~^-1 S e_c
//   for the first r <= R columns. False ("needs the robust path") when a pivot is not positive or the ratio
//   reaches kFastPathRatio: the caller then runs the eigen-decomposition (CPU only, LocalFit.h).
// - ShapeDot<Q>: b^T y, the shape function of one neighbour before its weight (phi_j = w_j b_j^T y_0).
// The arithmetic is +, -, *, / and sqrt only, in a fixed order: with FMA contraction off on both sides (nvcc
// --fmad=false; the host build has no FMA) the CPU and a device give the same bits.
#ifndef meshfree_MLSFastPath_h
#define meshfree_MLSFastPath_h

#include "Common/HostDevice.h"
#include "Common/PolynomialBasis.h"

#include <cmath>

namespace meshfree
{

/// Below this Cholesky pivot ratio the fast path is trusted; above it the eigen-decomposition decides.
constexpr double kFastPathRatio = 1e6;

namespace mls
{

/// Parent and variable of monomial I of PolynomialBasis<D, M>, as compile-time scalars (usable in device code).
template <int D, int M, int I>
struct BasisEntry
{
  static constexpr int Parent = MakeBasisTable(D, M).Parent[I];
  static constexpr int Variable = MakeBasisTable(D, M).Variable[I];
};

/// BasisSize(D, M) as a compile-time scalar (device code may not call the host constexpr function).
template <int D, int M>
struct BasisSizeOf
{
  static constexpr int Value = BasisSize(D, M);
};

template <int D, int M, int I = 1>
MESHFREE_HD inline void FillBasis(const double* xi, double* p)
{
  if constexpr (I < BasisSizeOf<D, M>::Value)
  {
    p[I] = p[BasisEntry<D, M, I>::Parent] * xi[BasisEntry<D, M, I>::Variable];
    FillBasis<D, M, I + 1>(xi, p);
  }
}

/// p[BasisSize(D, M)] = b(xi), bit for bit PolynomialBasis<D, M>::Evaluate.
template <int D, int M>
MESHFREE_HD inline void EvaluateBasis(const double* xi, double* p)
{
  p[0] = 1.0;
  FillBasis<D, M>(xi, p);
}

/// moment (Q x Q, row-major, upper triangle) += w p p^T, as (w p_a) p_b.
template <int Q>
MESHFREE_HD inline void AccumulateMoment(const double* p, double w, double* moment)
{
  MESHFREE_UNROLL
  for (int a = 0; a < Q; ++a)
  {
    const double wp = w * p[a];
    MESHFREE_UNROLL
    for (int b = a; b < Q; ++b)
    {
      moment[a * Q + b] += wp * p[b];
    }
  }
}

/// Equilibrates M (upper triangle read; both triangles written): s_i = 1 / sqrt(M_ii), M <- S M S. False, M
/// untouched, when M_00 is not positive and finite or some M_ii <= 1e-28 M_00 (degenerate fit).
template <int Q>
MESHFREE_HD inline bool EquilibrateMoment(double* M, double* s)
{
  const double m00 = M[0];
  if (!(m00 > 0.0) || !(m00 <= 1.7976931348623157e308)) // positive and finite (DBL_MAX)
  {
    return false;
  }
  MESHFREE_UNROLL
  for (int i = 0; i < Q; ++i)
  {
    const double d = M[i * Q + i];
    if (!(d > 1e-28 * m00))
    {
      return false;
    }
    s[i] = 1.0 / sqrt(d);
  }
  MESHFREE_UNROLL
  for (int i = 0; i < Q; ++i)
  {
    MESHFREE_UNROLL
    for (int j = i; j < Q; ++j)
    {
      M[i * Q + j] *= s[i] * s[j];
      M[j * Q + i] = M[i * Q + j];
    }
  }
  return true;
}

/**
 * The fast path on the equilibrated M~ (lower triangle read) with scales s: Cholesky M~ = L L^T, pivots
 * d_j = L_jj^2. When every pivot is positive and max d < kFastPathRatio min d, condition = max d / min d and
 * Y[c * Q + i] = (S M~^-1 S e_c)_i = (M^-1 e_c)_i for c < r (r <= R); returns true. Otherwise false, Y and
 * condition untouched: the caller needs the robust path.
 */
template <int Q, int R>
MESHFREE_HD inline bool CholeskyIdentitySolve(const double* M, const double* s, int r, double* Y, double& condition)
{
  double L[Q * Q];
  double dmin = 0.0, dmax = 0.0;
  MESHFREE_UNROLL
  for (int j = 0; j < Q; ++j)
  {
    double d = M[j * Q + j];
    MESHFREE_UNROLL
    for (int k = 0; k < j; ++k)
    {
      d -= L[j * Q + k] * L[j * Q + k];
    }
    if (!(d > 0.0))
    {
      return false;
    }
    dmin = (j == 0 || d < dmin) ? d : dmin;
    dmax = (j == 0 || dmax < d) ? d : dmax;
    const double ljj = sqrt(d);
    L[j * Q + j] = ljj;
    const double inv = 1.0 / ljj;
    MESHFREE_UNROLL
    for (int i = j + 1; i < Q; ++i)
    {
      double v = M[i * Q + j];
      MESHFREE_UNROLL
      for (int k = 0; k < j; ++k)
      {
        v -= L[i * Q + k] * L[j * Q + k];
      }
      L[i * Q + j] = v * inv;
    }
  }
  if (!(dmax < kFastPathRatio * dmin))
  {
    return false;
  }
  condition = dmax / dmin;
  MESHFREE_UNROLL
  for (int c = 0; c < R; ++c)
  {
    if (c < r)
    {
      // Solve L L^T z = S e_c, then y = S z.
      double z[Q];
      MESHFREE_UNROLL
      for (int i = 0; i < Q; ++i)
      {
        double v = (i == c) ? s[c] : 0.0;
        MESHFREE_UNROLL
        for (int k = 0; k < i; ++k)
        {
          v -= L[i * Q + k] * z[k];
        }
        z[i] = v / L[i * Q + i];
      }
      MESHFREE_UNROLL
      for (int i = Q - 1; i >= 0; --i)
      {
        double v = z[i];
        MESHFREE_UNROLL
        for (int k = i + 1; k < Q; ++k)
        {
          v -= L[k * Q + i] * z[k];
        }
        z[i] = v / L[i * Q + i];
      }
      MESHFREE_UNROLL
      for (int i = 0; i < Q; ++i)
      {
        Y[c * Q + i] = s[i] * z[i];
      }
    }
  }
  return true;
}

/// p^T y (summed from 0 in index order).
template <int Q>
MESHFREE_HD inline double ShapeDot(const double* p, const double* y)
{
  double v = 0.0;
  MESHFREE_UNROLL
  for (int a = 0; a < Q; ++a)
  {
    v += p[a] * y[a];
  }
  return v;
}

/// Right-hand sides of the MLS solve: 1 (values) or, with gradients and degree >= 1, 1 + D (e_1 .. e_{1+D}).
template <int D, int M>
struct MLSColumns
{
  static constexpr int Value = M > 0 ? D + 1 : 1;
};

} // namespace mls
} // namespace meshfree

#endif
