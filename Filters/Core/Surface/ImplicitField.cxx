// SPDX-License-Identifier: BSD-3-Clause
#include "Surface/ImplicitField.h"

#include <cmath>

namespace meshfree
{

bool ImplicitField::Project(
  double x[3], double normal[3], double maxStep, int iterations, FieldScratch& scratch) const
{
  double p[3] = { x[0], x[1], x[2] };
  double g[3] = { 0.0, 0.0, 0.0 };
  double f = 0.0;
  double g2 = 0.0;
  const double maxStep2 = maxStep * maxStep;
  for (int it = 0; it < iterations; ++it)
  {
    if (!this->Evaluate(p, f, g, scratch))
    {
      return false;
    }
    g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (!(g2 > 0.0) || !std::isfinite(g2))
    {
      return false;
    }
    const double step = f / g2;
    for (int a = 0; a < 3; ++a)
    {
      p[a] -= step * g[a];
    }
    const double d2 = (p[0] - x[0]) * (p[0] - x[0]) + (p[1] - x[1]) * (p[1] - x[1]) + (p[2] - x[2]) * (p[2] - x[2]);
    if (!(d2 <= maxStep2))
    {
      return false;
    }
  }
  if (iterations < 1)
  {
    return false;
  }
  // The normal is the gradient of the last evaluation (a step of f/|grad f| away, where it differs from the
  // gradient at the projected point only at second order).
  const double norm = std::sqrt(g2);
  for (int a = 0; a < 3; ++a)
  {
    x[a] = p[a];
    normal[a] = g[a] / norm;
  }
  return true;
}

} // namespace meshfree
