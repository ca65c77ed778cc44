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
template <class Local, class Info>
Approximator::PointResult Approximator::BlendCentres(const double x[3], const NeighborGrid& grid, const double* xyz,
  double R, FitScratch& s, const ApproximationOutput& out, Index i, const Local& local, const Info& info) const
{
  PointResult result{ false, 0, 0.0, false, false };
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const bool gradient = out.Gradients != nullptr;
  grid.FindWithinRadius(x, R, s.Ids, &s.Dist2);
  SortById(s, s.Ids.size()); // centres in lattice order, whichever were fitted
  // Work: blended values (C), blended local gradients (3C), one centre's values (C) and gradients (3C).
  if (s.Work.size() < 8 * static_cast<size_t>(C) + 8)
  {
    s.Work.resize(8 * static_cast<size_t>(C) + 8);
  }
  double* sumValues = s.Work.data();
  double* sumGrad = sumValues + C;
  double* values = sumGrad + 3 * C;
  double* gradients = values + C;
  std::fill(sumValues, sumValues + 4 * C, 0.0);
  double sumTheta = 0.0;
  double sumDTheta[3] = { 0, 0, 0 };
  double best = 0.0;
  for (size_t j = 0; j < s.Ids.size(); ++j)
  {
    const double theta = this->UnitKernel.ValueSquared(s.Dist2[j] / (R * R));
    if (!(theta > 0.0))
    {
      continue;
    }
    const Index c = s.Ids[j];
    const double* xc = xyz + 3 * c;
    const double dx[3] = { x[0] - xc[0], x[1] - xc[1], x[2] - xc[2] };
    local(c, dx, values, gradient ? gradients : nullptr);
    sumTheta += theta;
    for (int q = 0; q < C; ++q)
    {
      sumValues[q] += theta * values[q];
    }
    if (gradient)
    {
      double r[3] = { 0, 0, 0 }, dTheta[3];
      this->Frame.Project<3>(dx, 1.0 / R, r);
      for (int a = D; a < 3; ++a)
      {
        r[a] = 0.0;
      }
      this->UnitKernel.Gradient(r, dTheta); // per unit r / R
      for (int a = 0; a < D; ++a)
      {
        dTheta[a] /= R;
        sumDTheta[a] += dTheta[a];
        for (int q = 0; q < C; ++q)
        {
          sumGrad[a * C + q] += dTheta[a] * values[q] + theta * gradients[a * C + q];
        }
      }
    }
    if (theta > best)
    {
      best = theta;
      info(c, result);
    }
  }
  if (!(sumTheta > 0.0))
  {
    return result;
  }
  result.Valid = this->WriteBlend(i, sumValues, sumGrad, sumDTheta, sumTheta, out);
  return result;
}

} // namespace meshfree

#endif
