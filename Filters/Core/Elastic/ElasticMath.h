// SPDX-License-Identifier: BSD-3-Clause
// Small 3x3 helpers of the meshless elastic solid (row-major matrices, symmetric tensors as 6-vectors
// xx, yy, zz, xy, yz, xz). Internal to ElasticSolid / ElasticForces / ElasticIntegrators.
#ifndef meshfree_ElasticMath_h
#define meshfree_ElasticMath_h

#include <cmath>

namespace meshfree
{
namespace elastic
{
inline void SymToMat(const double s[6], double m[9])
{
  m[0] = s[0];
  m[4] = s[1];
  m[8] = s[2];
  m[1] = m[3] = s[3];
  m[5] = m[7] = s[4];
  m[2] = m[6] = s[5];
}

inline double Det3(const double F[9])
{
  return F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
    F[2] * (F[3] * F[7] - F[4] * F[6]);
}

/// cof(F) = d det F / dF; column c of cof is the cross product of the other two columns of F [4.25].
inline void Cofactor(const double F[9], double C[9])
{
  C[0] = F[4] * F[8] - F[5] * F[7];
  C[1] = F[5] * F[6] - F[3] * F[8];
  C[2] = F[3] * F[7] - F[4] * F[6];
  C[3] = F[2] * F[7] - F[1] * F[8];
  C[4] = F[0] * F[8] - F[2] * F[6];
  C[5] = F[1] * F[6] - F[0] * F[7];
  C[6] = F[1] * F[5] - F[2] * F[4];
  C[7] = F[2] * F[3] - F[0] * F[5];
  C[8] = F[0] * F[4] - F[1] * F[3];
}

/// Green-Saint-Venant strain E = (F^T F - I)/2 [4.4, with the factor 1/2 that makes E the physical modulus].
inline void GreenStrain(const double F[9], double E[6])
{
  double C[9];
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      C[a * 3 + b] = F[a] * F[b] + F[3 + a] * F[3 + b] + F[6 + a] * F[6 + b];
    }
  }
  E[0] = 0.5 * (C[0] - 1.0);
  E[1] = 0.5 * (C[4] - 1.0);
  E[2] = 0.5 * (C[8] - 1.0);
  E[3] = 0.5 * C[1];
  E[4] = 0.5 * C[5];
  E[5] = 0.5 * C[2];
}

/// Frobenius norm of a symmetric tensor given as a 6-vector.
inline double Norm6(const double e[6])
{
  return std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + 2.0 * (e[3] * e[3] + e[4] * e[4] + e[5] * e[5]));
}

/// The fit's basis at a scaled offset q: x, y, z, then x^2, xy, xz, y^2, yz, z^2 (only the first 3 when linear).
inline void Basis(const double q[3], double p[9])
{
  p[0] = q[0];
  p[1] = q[1];
  p[2] = q[2];
  p[3] = q[0] * q[0];
  p[4] = q[0] * q[1];
  p[5] = q[0] * q[2];
  p[6] = q[1] * q[1];
  p[7] = q[1] * q[2];
  p[8] = q[2] * q[2];
}
} // namespace elastic
} // namespace meshfree

#endif
