// SPDX-License-Identifier: BSD-3-Clause
// SPH interpolation (thesis 2.3, 5.10): A(x) = sum_j A_j V_j W(|x - x_j|, h), optionally Shepard-normalised.
#include "Approximation/Approximation.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{

bool Approximator::PrepareSPHVolumes()
{
  const Index n = static_cast<Index>(this->Coordinates.size() / 3);
  const int dim = std::max(1, this->Frame.Dimension);
  // Volumes are kept relative to a unit volume SphUnitLength^d of the cloud's own scale: with a support of
  // 1e200 (or a cloud scaled by 1e-200) h^d and 1/h^d leave double's range, their ratios do not.
  if (this->Volumes.size() == static_cast<size_t>(n))
  {
    double largest = 0.0;
    for (double v : this->Volumes)
    {
      largest = std::isfinite(v) ? std::max(largest, v) : largest;
    }
    if (this->Partitioned)
    {
      largest = this->PartitionLargestVolume; // over every part (SetCloud)
    }
    this->SphUnitLength = largest > 0.0 ? std::pow(largest, 1.0 / dim) : 1.0;
    this->SphVolumes.resize(this->Volumes.size());
    for (size_t i = 0; i < this->Volumes.size(); ++i)
    {
      this->SphVolumes[i] = largest > 0.0 ? this->Volumes[i] / largest : this->Volumes[i];
    }
    return true;
  }
  double extent = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    extent = std::max(extent, this->Bounds[2 * a + 1] - this->Bounds[2 * a]);
  }
  double unit = this->Opts.SupportRadius > 0.0 ? this->Opts.SupportRadius : extent;
  this->SphUnitLength = unit > 0.0 && std::isfinite(unit) ? unit : 1.0;
  // No Mass/Density: V_j = 1 / sum_k W(|x_j - x_k|, h_j), the inverse number density, with h_j from the
  // same support rule as the evaluation (the point itself is included, so the sum is >= W(0) > 0).
  this->SphVolumes.assign(static_cast<size_t>(n), 0.0);
  const double unitLength = this->SphUnitLength;
  const std::vector<Index>& order = this->Points.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  // Fixed blocks of points, each starting without the previous query's neighbour radius (the warm start may
  // list the same neighbours in another order): the sums do not depend on which thread ran which block before.
  constexpr Index block = 256;
  PerThread<FitScratch> scratch;
  ParallelFor((nv + block - 1) / block, 1, [&](Index b0, Index b1) {
    FitScratch& s = scratch.Local();
    for (Index p = b0 * block; p < std::min(nv, b1 * block); ++p)
    {
      if (p % block == 0)
      {
        s.RadiusGuess = 0.0;
      }
      const Index id = order[p];
      const double* x = &this->Coordinates[3 * id];
      double h = 1.0;
      const int found = this->Neighbors(x, this->Opts.NeighborCount, this->Opts.SupportRadius, s, h);
      const double invH2 = 1.0 / (h * h);
      double sum = 0.0;
      for (int j = 0; j < found; ++j)
      {
        sum += this->UnitKernel.ValueSquared(s.Dist2[j] * invH2);
      }
      const double hd = std::pow(h / unitLength, dim);
      this->SphVolumes[id] = sum > 0.0 ? hd / sum : 0.0;
    }
  });
  return true;
}

Approximator::PointResult Approximator::SPHPoint(
  const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const
{
  PointResult result{ false, 0, 1.0, false, false };
  const int D = this->Frame.Dimension;
  const int dim = std::max(1, D);
  const int C = this->NumberOfComponents;
  const bool gradient = out.Gradients != nullptr;
  const bool shepard = this->Opts.ShepardNormalization;
  int k = this->Opts.NeighborCount;
  double radius = this->Opts.SupportRadius;
  for (int attempt = 0; attempt < 2; ++attempt, k *= 2, radius *= 2.0)
  {
    double h = 1.0;
    const int n = this->Neighbors(x, k, radius, s, h);
    s.Reserve(static_cast<size_t>(std::max(n, 1)));
    const double invH = 1.0 / h;
    // (unit / h)^d: the volumes are in units of unit^d. Shepard normalisation divides out any factor common
    // to every neighbour, so it is left out there (no underflow for a support far larger than the cloud).
    const double invHd = shepard ? 1.0 : std::pow(this->SphUnitLength / h, dim);
    int m = 0;
    double sum = 0.0;
    double sumGrad[3] = { 0, 0, 0 };
    for (int j = 0; j < n; ++j)
    {
      const double W = this->UnitKernel.ValueSquared(s.Dist2[j] * invH * invH) * invHd;
      const Index id = s.Ids[j];
      const double vw = this->SphVolumes[id] * W;
      if (!(vw > 0.0) || !std::isfinite(vw))
      {
        continue;
      }
      s.Ids[m] = id;
      s.Weights[m] = vw;
      sum += vw;
      if (gradient)
      {
        // grad_x W(|x - x_j|, h) in local axes: W_1'(r / h) / h^(d+1).
        const double dx[3] = { x[0] - this->Coordinates[3 * id], x[1] - this->Coordinates[3 * id + 1],
          x[2] - this->Coordinates[3 * id + 2] };
        double r[3] = { 0, 0, 0 };
        this->Frame.Project<3>(dx, invH, r);
        for (int a = D; a < 3; ++a)
        {
          r[a] = 0.0;
        }
        double* g = &s.WeightDerivatives[3 * m];
        this->UnitKernel.Gradient(r, g);
        for (int a = 0; a < 3; ++a)
        {
          g[a] *= this->SphVolumes[id] * invHd * invH;
          sumGrad[a] += g[a];
        }
      }
      ++m;
    }
    if (m == 0 || !(sum > 0.0))
    {
      continue;
    }
    s.Work.resize(4 * static_cast<size_t>(C) + 4);
    double* v = out.Values ? out.Values + i * C : s.Work.data();
    std::fill(v, v + C, 0.0);
    for (int j = 0; j < m; ++j)
    {
      const double* f = &this->Values[static_cast<size_t>(s.Ids[j]) * C];
      for (int c = 0; c < C; ++c)
      {
        v[c] += s.Weights[j] * f[c];
      }
    }
    bool finite = true;
    for (int c = 0; c < C; ++c)
    {
      if (shepard)
      {
        v[c] /= sum;
      }
      finite = finite && std::isfinite(v[c]);
    }
    if (gradient)
    {
      for (int c = 0; c < C; ++c)
      {
        double l[3] = { 0, 0, 0 };
        for (int j = 0; j < m; ++j)
        {
          const double f = this->Values[static_cast<size_t>(s.Ids[j]) * C + c];
          for (int a = 0; a < D; ++a)
          {
            l[a] += s.WeightDerivatives[3 * j + a] * f;
          }
        }
        if (shepard)
        {
          // Derivative of the Shepard ratio at fixed h.
          for (int a = 0; a < D; ++a)
          {
            l[a] = (l[a] - v[c] * sumGrad[a]) / sum;
          }
        }
        double* g = out.Gradients + 3 * (i * C + c);
        this->Frame.Unproject(l, g);
        finite = finite && std::isfinite(g[0]) && std::isfinite(g[1]) && std::isfinite(g[2]);
      }
    }
    result.Valid = finite;
    result.Neighbors = m;
    result.Widened = attempt > 0;
    return result;
  }
  return result;
}

} // namespace meshfree
