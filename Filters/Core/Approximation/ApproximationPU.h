// SPDX-License-Identifier: BSD-3-Clause
// Private to the Approximator: the partition-of-unity centres of PU-WLS (see Approximation.h).
#ifndef meshfree_ApproximationPU_h
#define meshfree_ApproximationPU_h

#include "Approximation/Approximation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace meshfree
{
struct Approximator::PUData
{
  double CoverRadius = 0.0;         // R: a centre's blending weight vanishes beyond it
  std::vector<double> Centers;      // 3 per kept centre
  std::vector<double> Supports;     // support radius of each centre's fit
  std::vector<int> Degrees;         // degree of each centre's fit (after fallbacks)
  std::vector<int> Counts;          // points in each centre's fit
  std::vector<double> Conditions;   // condition number of each centre's fit
  std::vector<double> Coefficients; // kMaxBasisSize * C per centre
  NeighborGrid CenterGrid;
};
/// Bounds of the finite positions among m interleaved x, y, z (min > max when none is).
inline void FiniteBox(const double* xyz, Index m, double box[6])
{
  for (int a = 0; a < 3; ++a)
  {
    box[2 * a] = std::numeric_limits<double>::infinity();
    box[2 * a + 1] = -std::numeric_limits<double>::infinity();
  }
  for (Index i = 0; i < m; ++i)
  {
    const double* x = xyz + 3 * i;
    if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]))
    {
      for (int a = 0; a < 3; ++a)
      {
        box[2 * a] = std::min(box[2 * a], x[a]);
        box[2 * a + 1] = std::max(box[2 * a + 1], x[a]);
      }
    }
  }
}

/// Squared distance from x to a box (+inf for an empty box).
inline double BoxDistance2(const double box[6], const double x[3])
{
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    if (!(box[2 * a] <= box[2 * a + 1]))
    {
      return std::numeric_limits<double>::infinity();
    }
    const double d = x[a] < box[2 * a] ? box[2 * a] - x[a] : (x[a] > box[2 * a + 1] ? x[a] - box[2 * a + 1] : 0.0);
    d2 += d * d;
  }
  return d2;
}
} // namespace meshfree

#endif
