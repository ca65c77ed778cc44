// The SPH density function shared by the CPU loop and the CUDA kernel (SPH/SPHDensity.h) against the SPH sum
// rho_i = sum_j m W(|x_i - x_j|, h) written out here with the textbook kernels (poly6 and spiky, 3D), for a lone
// particle, a pair, a lattice block and a random cloud with wall dummies and neighbour rows reaching beyond h.
#include "SPH/SPHDensity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace
{
const double Pi = 3.14159265358979323846;

// W(r, h), 3D, zero at r >= h.
double Poly6(double r, double h)
{
  return r < h ? 315.0 / (64.0 * Pi * std::pow(h, 9)) * std::pow(h * h - r * r, 3) : 0.0;
}
double Spiky(double r, double h)
{
  return r < h ? 15.0 / (Pi * std::pow(h, 6)) * std::pow(h - r, 3) : 0.0;
}

struct Cloud
{
  std::vector<double> X, Walls;
  std::vector<std::int64_t> FluidStart, WallStart;
  std::vector<std::int32_t> Fluid, Wall;
  std::int64_t Size() const { return static_cast<std::int64_t>(this->X.size() / 3); }
};

double Distance(const double* a, const double* b)
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// Rows listing every other particle (and every wall dummy) within `reach`, which may exceed h.
void ListNeighbors(Cloud& c, double reach)
{
  const std::int64_t n = c.Size(), nb = static_cast<std::int64_t>(c.Walls.size() / 3);
  c.FluidStart.assign(1, 0);
  c.WallStart.assign(1, 0);
  c.Fluid.clear();
  c.Wall.clear();
  for (std::int64_t i = 0; i < n; ++i)
  {
    for (std::int64_t j = 0; j < n; ++j)
    {
      if (j != i && Distance(&c.X[3 * i], &c.X[3 * j]) < reach)
      {
        c.Fluid.push_back(static_cast<std::int32_t>(j));
      }
    }
    for (std::int64_t b = 0; b < nb; ++b)
    {
      if (Distance(&c.X[3 * i], &c.Walls[3 * b]) < reach)
      {
        c.Wall.push_back(static_cast<std::int32_t>(b));
      }
    }
    c.FluidStart.push_back(static_cast<std::int64_t>(c.Fluid.size()));
    c.WallStart.push_back(static_cast<std::int64_t>(c.Wall.size()));
  }
}

// The reference: every particle and every dummy, not only the listed ones (the lists must hold all within h).
double Reference(const Cloud& c, std::int64_t i, double h, double m, bool spiky)
{
  double rho = 0.0;
  for (std::int64_t j = 0; j < c.Size(); ++j)
  {
    const double r = Distance(&c.X[3 * i], &c.X[3 * j]);
    rho += m * (spiky ? Spiky(r, h) : Poly6(r, h));
  }
  for (std::size_t b = 0; b < c.Walls.size() / 3; ++b)
  {
    const double r = Distance(&c.X[3 * i], &c.Walls[3 * b]);
    rho += m * (spiky ? Spiky(r, h) : Poly6(r, h));
  }
  return rho;
}

void Compare(const Cloud& c, double h, double m)
{
  for (int spiky = 0; spiky < 2; ++spiky)
  {
    meshfree::SPHDensityConstants k;
    k.H = h;
    k.H2 = h * h;
    k.Mass = m;
    k.DensityNorm = spiky ? 15.0 / (Pi * std::pow(h, 6)) : 315.0 / (64.0 * Pi * std::pow(h, 9));
    k.SpikyDensity = spiky;
    for (std::int64_t i = 0; i < c.Size(); ++i)
    {
      const double expected = Reference(c, i, h, m, spiky != 0);
      const double rho = meshfree::SPHParticleDensity(
        i, c.X.data(), c.FluidStart.data(), c.Fluid.data(), c.Walls.data(), c.WallStart.data(), c.Wall.data(), k);
      EXPECT_NEAR(rho, expected, 1e-12 * expected) << (spiky ? "spiky" : "poly6") << ", particle " << i;
    }
  }
}
}

TEST(SPHDensityKernel, LoneParticleIsItsOwnKernelPeak)
{
  Cloud c;
  c.X = { 0.3, -0.2, 0.7 };
  ListNeighbors(c, 1.0);
  Compare(c, 0.05, 0.125);
  meshfree::SPHDensityConstants k;
  k.H = 0.05;
  k.H2 = 0.05 * 0.05;
  k.Mass = 0.125;
  k.DensityNorm = 315.0 / (64.0 * Pi * std::pow(0.05, 9));
  const double rho = meshfree::SPHParticleDensity(
    0, c.X.data(), c.FluidStart.data(), c.Fluid.data(), nullptr, c.WallStart.data(), nullptr, k);
  EXPECT_NEAR(rho, 0.125 * 315.0 / (64.0 * Pi * std::pow(0.05, 3)), 1e-12 * rho);
}

TEST(SPHDensityKernel, PairInsideAndOutsideTheSupport)
{
  for (double d : { 0.0, 0.01, 0.049, 0.05, 0.07 })
  {
    Cloud c;
    c.X = { 0.0, 0.0, 0.0, d * 0.6, 0.0, d * 0.8 };
    ListNeighbors(c, 1.0); // listed even beyond h: the function must skip r >= h
    Compare(c, 0.05, 2.0);
  }
}

TEST(SPHDensityKernel, LatticeBlock)
{
  Cloud c;
  const double dx = 0.01;
  for (int i = 0; i < 6; ++i)
  {
    for (int j = 0; j < 5; ++j)
    {
      for (int k = 0; k < 4; ++k)
      {
        c.X.insert(c.X.end(), { i * dx, j * dx, k * dx });
      }
    }
  }
  ListNeighbors(c, 0.02); // exactly the lists within h of the solver
  Compare(c, 0.02, 0.001);
}

TEST(SPHDensityKernel, RandomCloudWithWallDummies)
{
  std::mt19937_64 random(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Cloud c;
  for (int i = 0; i < 300; ++i)
  {
    c.X.insert(c.X.end(), { 0.3 * unit(random), 0.3 * unit(random), 0.3 * unit(random) });
  }
  for (int b = 0; b < 200; ++b)
  {
    c.Walls.insert(c.Walls.end(), { 0.3 * unit(random), 0.3 * unit(random), -0.03 * unit(random) });
  }
  ListNeighbors(c, 0.08); // rows reach beyond h = 0.06
  Compare(c, 0.06, 0.0005);
}
