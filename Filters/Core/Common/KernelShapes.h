// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the weight functions' shapes f(q) that are plain arithmetic (no exp, no pow), as MESHFREE_HD
// functions: Kernel (Kernels.h) evaluates them on the CPU and the CUDA kernels call the very same code, so a
// weight is the same double on both sides (+, -, *, / and sqrt are correctly rounded on both; no FMA, see
// HostDevice.h). Formulas and thesis equation numbers: Kernels.h. The transcendental ones (Gaussian, W2) stay
// in Kernels.h: glibc's and CUDA's exp differ by ulps, so they could not give the same bits anyway.
#ifndef meshfree_KernelShapes_h
#define meshfree_KernelShapes_h

#include "Common/HostDevice.h"

#include <cmath>

namespace meshfree
{

/// Wendland [3.11]: (1-q)^4 (4q+1), 0 <= q < 1.
MESHFREE_HD inline double WendlandShape(double q)
{
  const double u = 1.0 - q;
  return u * u * u * u * (4.0 * q + 1.0);
}

/// Poly6 [4.16]: (1-q^2)^3 from q^2, times the prefactor (the order of Kernel::ValueSquared).
MESHFREE_HD inline double Poly6ValueSquared(double normalization, double q2)
{
  const double s = 1.0 - q2;
  return normalization * s * s * s;
}

/// M4(2q) (W3, W5, CubicSpline [4.18, 4.20]): 1 - 6q^2 + 6q^3 (q <= 1/2), 2(1-q)^3 (1/2 < q < 1).
MESHFREE_HD inline double CubicSplineShape(double q)
{
  const double u = 1.0 - q;
  return q <= 0.5 ? 1.0 - 6.0 * q * q * u : 2.0 * u * u * u;
}

/// Lucy = W4 [2.7, 4.19]: (1+3q)(1-q)^3.
MESHFREE_HD inline double LucyShape(double q)
{
  const double u = 1.0 - q;
  return (1.0 + 3.0 * q) * u * u * u;
}

/// Spiky [5.41]: (1-q)^3.
MESHFREE_HD inline double SpikyShape(double q)
{
  const double u = 1.0 - q;
  return u * u * u;
}

/// The plain-arithmetic weights by KernelType value (Kernels.h numbering), for code that cannot see the
/// Kernel class (device code).
enum PlainWeight : int
{
  kPlainWendland = 1,
  kPlainPoly6 = 3,
  kPlainW3 = 5,
  kPlainW4 = 6,
  kPlainW5 = 7,
  kPlainLucy = 8,
  kPlainSpiky = 9,
  kPlainCubicSpline = 11
};

/// Whether KernelType value `kind` has a plain-arithmetic shape (one of PlainWeight).
MESHFREE_HD inline bool IsPlainWeight(int kind)
{
  return kind == kPlainWendland || kind == kPlainPoly6 || kind == kPlainW3 || kind == kPlainW4 || kind == kPlainW5 ||
    kind == kPlainLucy || kind == kPlainSpiky || kind == kPlainCubicSpline;
}

/// W from q^2 = r^2 / h^2 for a plain weight `kind` with prefactor `normalization` (sigma_d / h^d): exactly
/// Kernel::ValueSquared's arithmetic (0 for q^2 >= 1 or NaN).
MESHFREE_HD inline double PlainWeightSquared(int kind, double normalization, double q2)
{
  if (!(q2 < 1.0))
  {
    return 0.0;
  }
  if (kind == kPlainPoly6)
  {
    return Poly6ValueSquared(normalization, q2);
  }
  const double q = sqrt(q2);
  switch (kind)
  {
    case kPlainWendland:
      return normalization * WendlandShape(q);
    case kPlainW3:
    case kPlainW5:
    case kPlainCubicSpline:
      return normalization * CubicSplineShape(q);
    case kPlainW4:
    case kPlainLucy:
      return normalization * LucyShape(q);
    case kPlainSpiky:
      return normalization * SpikyShape(q);
    default:
      return 0.0;
  }
}

} // namespace meshfree

#endif
