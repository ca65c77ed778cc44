// SPH density of one particle (Kelager 2006, eq. 5.32: rho_i = sum_j m W(x_i - x_j, h), itself included, wall
// dummies weighing like fluid particles), shared by the CPU loop of SPHFluid and the CUDA launcher
// (cuda/SPHDensity.h): one source for the arithmetic, so that both give the same bits.
#ifndef MeshFree_SPH_SPHDensity_h
#define MeshFree_SPH_SPHDensity_h

#include "Common/HostDevice.h"

#include <cmath>
#include <cstdint>

namespace meshfree
{

/// What the density of a particle needs besides the positions and neighbour lists (plain data, copied to the
/// device by value).
struct SPHDensityConstants
{
  double H = 0.0;           ///< support radius h
  double H2 = 0.0;          ///< h * h
  double Mass = 0.0;        ///< particle mass m
  double DensityNorm = 0.0; ///< W(r) = DensityNorm * SPHDensityShape(r^2)
  int SpikyDensity = 0;     ///< 1: spiky (h - r)^3, 0: poly6 (h^2 - r^2)^3
};

/// The shape of the density kernel at squared distance r2 < h2, without its normalisation.
MESHFREE_HD inline double SPHDensityShape(double r2, double h, double h2, int spiky)
{
  if (spiky)
  {
    const double u = h - sqrt(r2);
    return u * u * u;
  }
  const double q = h2 - r2;
  return q * q * q;
}

/// The density sum of one particle: starts with the particle itself; Add() every neighbour (fluid particle or
/// wall dummy, itself excluded) at squared distance r2 (ignored unless r2 < h^2), in the caller's order.
struct SPHDensitySum
{
  double Sum;

  MESHFREE_HD explicit SPHDensitySum(const SPHDensityConstants& c)
    : Sum(SPHDensityShape(0.0, c.H, c.H2, c.SpikyDensity))
  {
  }
  MESHFREE_HD void Add(double r2, const SPHDensityConstants& c)
  {
    if (r2 < c.H2)
    {
      this->Sum += SPHDensityShape(r2, c.H, c.H2, c.SpikyDensity);
    }
  }
  MESHFREE_HD double Density(const SPHDensityConstants& c) const { return c.DensityNorm * c.Mass * this->Sum; }
};

/// Density of particle i. x: fluid positions (xyz triplets); fluidStart / fluidNeighbors: CSR neighbour rows
/// (the particle itself not listed; entries at r >= h are skipped); boundaryX / boundaryStart /
/// boundaryNeighbors: the same for the wall dummies (boundaryStart all zero without walls).
MESHFREE_HD inline double SPHParticleDensity(std::int64_t i, const double* x, const std::int64_t* fluidStart,
  const std::int32_t* fluidNeighbors, const double* boundaryX, const std::int64_t* boundaryStart,
  const std::int32_t* boundaryNeighbors, const SPHDensityConstants& c)
{
  const double* xi = x + 3 * i;
  SPHDensitySum sum(c);
  for (std::int64_t s = fluidStart[i]; s < fluidStart[i + 1]; ++s)
  {
    const double* xj = x + 3 * static_cast<std::int64_t>(fluidNeighbors[s]);
    const double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
    sum.Add(dx * dx + dy * dy + dz * dz, c);
  }
  for (std::int64_t s = boundaryStart[i]; s < boundaryStart[i + 1]; ++s)
  {
    const double* xb = boundaryX + 3 * static_cast<std::int64_t>(boundaryNeighbors[s]);
    const double dx = xi[0] - xb[0], dy = xi[1] - xb[1], dz = xi[2] - xb[2];
    sum.Add(dx * dx + dy * dy + dz * dz, c); // dummies weigh like fluid particles
  }
  return sum.Density(c);
}

} // namespace meshfree

#endif
