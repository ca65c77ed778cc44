// SPDX-License-Identifier: BSD-3-Clause
// Approximator: MLS shape functions for a neighbour list chosen by the caller (VTK's interpolation-kernel
// protocol: ComputeBasis picks the points, ComputeWeights weighs them).
#include "Approximation/Approximation.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{

bool Approximator::ShapeFunctionsFor(
  const double x[3], const Index* ids, int n, std::vector<double>& phi, FitScratch& s) const
{
  phi.assign(static_cast<size_t>(std::max(n, 0)), 0.0);
  const Index total = static_cast<Index>(this->Coordinates.size() / 3);
  if (n <= 0 || !std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
  {
    return false;
  }
  const double* coords = this->Coordinates.data();
  // The support: SupportRadius, or 1.1 x the farthest point given (so that all of them carry weight).
  double far2 = 0.0;
  for (int j = 0; j < n; ++j)
  {
    if (ids[j] < 0 || ids[j] >= total || !std::isfinite(coords[3 * ids[j]]))
    {
      continue;
    }
    const double* p = coords + 3 * ids[j];
    far2 = std::max(far2, (p[0] - x[0]) * (p[0] - x[0]) + (p[1] - x[1]) * (p[1] - x[1]) + (p[2] - x[2]) * (p[2] - x[2]));
  }
  double h = this->Opts.SupportRadius > 0.0 ? this->Opts.SupportRadius : this->Opts.SupportFactor * std::sqrt(far2);
  if (!(h > 0.0))
  {
    h = 1.0; // every given point sits at x: they share the weight W(0)
  }
  const double invH = 1.0 / h;
  const int D = this->Frame.Dimension;
  s.Reserve(static_cast<size_t>(n));
  if (s.Ids.size() < static_cast<size_t>(n))
  {
    s.Ids.resize(n);
  }
  int m = 0;
  for (int j = 0; j < n; ++j)
  {
    if (ids[j] < 0 || ids[j] >= total || !std::isfinite(coords[3 * ids[j]]))
    {
      continue;
    }
    const double* p = coords + 3 * ids[j];
    const double dx[3] = { p[0] - x[0], p[1] - x[1], p[2] - x[2] };
    const double w = this->UnitKernel.ValueSquared((dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]) * invH * invH);
    if (!(w > 0.0) || !std::isfinite(w))
    {
      continue;
    }
    double* xi = &s.Xi[3 * m];
    xi[0] = xi[1] = xi[2] = 0.0;
    this->Frame.Project<3>(dx, invH, xi);
    for (int a = D; a < 3; ++a)
    {
      xi[a] = 0.0;
    }
    s.Ids[m] = j; // position in the caller's list
    s.Weights[m] = w;
    ++m;
  }
  for (int degree = this->Opts.Degree; m > 0 && degree >= 0; --degree)
  {
    double condition = 0.0;
    if (ComputeMLSShapeFunctions(D, degree, s.Xi.data(), s.Weights.data(), nullptr, m, false, false,
          s.Rows.data(), s.Phi.data(), s.DPhi.data(), condition))
    {
      for (int q = 0; q < m; ++q)
      {
        if (!std::isfinite(s.Phi[q]))
        {
          std::fill(phi.begin(), phi.end(), 0.0);
          return false;
        }
        phi[s.Ids[q]] = s.Phi[q];
      }
      return true;
    }
  }
  return false;
}

} // namespace meshfree
