// The per-particle passes of the CUDA SPH integrator (cuda/SPHDevice.cu), one call per thread: the shared sums
// of SPH/SPHPhysics.h and SPH/SPHDensity.h fed by a walk over the grid's cells (GridForEachCandidate) instead of
// CSR rows, the neighbours in the same order as the CPU's rows. MESHFREE_HD, so that a CPU test can run them
// (TestSPHGridPasses) and check them against SPHFluid's own loops without a GPU.
#ifndef MeshFree_SPH_SPHGridPasses_h
#define MeshFree_SPH_SPHGridPasses_h

#include "Common/GridCell.h"
#include "SPH/SPHPhysics.h"

#include <cstdint>

namespace meshfree
{

/// Density, pressure, p / rho^2 and 1 / rho of the particle at sorted position s of `fluid` (written at its
/// index fluid.Order[s]); `wall`: the wall dummies' grid (Count 0 without walls).
MESHFREE_HD inline void SPHGridDensity(std::int64_t s, const GridCells& fluid, const GridCells& wall,
  const SPHConstants& c, double* rho, double* pressure, double* pressureTerm, double* inverseDensity)
{
  const std::int64_t i = fluid.Order[s];
  const double* xi = fluid.Sorted + 3 * s;
  const SPHDensityConstants dc = SPHDensityConstantsOf(c);
  SPHDensitySum sum(dc);
  GridForEachCandidate(fluid, xi, c.H, [&](std::int32_t t) {
    if (t != s)
    {
      const double* xj = fluid.Sorted + 3 * static_cast<std::int64_t>(t);
      const double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
      sum.Add(dx * dx + dy * dy + dz * dz, dc);
    }
  });
  if (SPHNearBoundary(xi, c))
  {
    GridForEachCandidate(wall, xi, c.H, [&](std::int32_t t) {
      const double* xb = wall.Sorted + 3 * static_cast<std::int64_t>(t);
      const double dx = xi[0] - xb[0], dy = xi[1] - xb[1], dz = xi[2] - xb[2];
      sum.Add(dx * dx + dy * dy + dz * dz, dc);
    });
  }
  rho[i] = sum.Density(dc);
  SPHParticleTerms(rho[i], c, pressure + i, pressureTerm + i, inverseDensity + i);
}

/// p_b / rho_b^2 of the wall dummy at xb, extrapolated from the fluid within h (SPHWallPressure).
MESHFREE_HD inline double SPHGridWallTerm(
  const double* xb, const GridCells& fluid, const double* pressure, const double* rho, const SPHConstants& c)
{
  SPHWallPressure w;
  GridForEachCandidate(fluid, xb, c.H, [&](std::int32_t t) {
    const double* xf = fluid.Sorted + 3 * static_cast<std::int64_t>(t);
    const std::int64_t f = fluid.Order[t];
    const double r[3] = { xb[0] - xf[0], xb[1] - xf[1], xb[2] - xf[2] };
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    w.Add(r, r2, pressure[f], rho[f], c);
  });
  return w.Term(c);
}

/// The acceleration of the particle at sorted position s (SPHAcceleration: fluid neighbours, then wall dummies),
/// written at its index fluid.Order[s].
MESHFREE_HD inline void SPHGridAcceleration(std::int64_t s, const GridCells& fluid, const GridCells& wall,
  const double* v, const double* rho, const double* inverseDensity, const double* pressureTerm, const double* wallTerm,
  const SPHConstants& c, double* acc)
{
  const std::int64_t i = fluid.Order[s];
  const double* xi = fluid.Sorted + 3 * s;
  SPHAcceleration a(xi, v + 3 * i, rho[i], inverseDensity[i], pressureTerm[i]);
  GridForEachCandidate(fluid, xi, c.H, [&](std::int32_t t) {
    if (t != s)
    {
      const std::int64_t j = fluid.Order[t];
      a.Fluid(
        fluid.Sorted + 3 * static_cast<std::int64_t>(t), v + 3 * j, rho[j], inverseDensity[j], pressureTerm[j], c);
    }
  });
  if (SPHNearBoundary(xi, c))
  {
    GridForEachCandidate(wall, xi, c.H,
      [&](std::int32_t t) { a.Wall(wall.Sorted + 3 * static_cast<std::int64_t>(t), wallTerm[wall.Order[t]], c); });
  }
  a.Finish(acc + 3 * i, c);
}

} // namespace meshfree

#endif
