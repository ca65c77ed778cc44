// SPDX-License-Identifier: BSD-3-Clause
// Private to the Approximator: the partition-of-unity centres of PU-WLS (see Approximation.h).
#ifndef meshfree_ApproximationPU_h
#define meshfree_ApproximationPU_h

#include "Approximation/Approximation.h"

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
} // namespace meshfree

#endif
