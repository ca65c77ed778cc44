// The shared per-particle SPH arithmetic (SPH/SPHPhysics.h, the code both the CPU loops and the CUDA kernels
// run), its CPU path checked against reference formulas written out here: the equations of state and the
// inverse, a pair force with artificial viscosity, viscosity and surface tension by hand, the wall pair, the
// Adami dummy pressure of a hydrostatic column, kick-drift with the wall clamp, and the CFL step.
#include "Common/GridCell.h"
#include "SPH/SPHPhysics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace
{
using meshfree::SPHConstants;

constexpr double Pi = 3.14159265358979323846;

/// Constants of a 3D water-like fluid (the lattice corrections left at 1: the formulas do not depend on them).
SPHConstants Water(bool tait)
{
  SPHConstants c;
  c.Dimension = 3;
  c.Tait = tait ? 1 : 0;
  c.SpikyDensity = 1;
  c.SpikyGradient = 1;
  c.Walls = 1;
  c.H = 0.02;
  c.H2 = c.H * c.H;
  c.Mass = 1000.0 * 1e-6;
  c.RestDensity = 1000.0;
  c.K = 400.0;
  c.C0 = 20.0;
  c.TaitB = c.RestDensity * c.K / 7.0;
  c.Nu = 1e-6;
  c.DensityNorm = 15.0 / (Pi * std::pow(c.H, 6));
  c.GradientNorm = 3.0 * c.DensityNorm;
  c.Poly6 = 315.0 / (64.0 * Pi * std::pow(c.H, 9));
  c.ViscLap = 45.0 / (Pi * std::pow(c.H, 6));
  c.Gravity[2] = -9.81;
  const double domain[6] = { 0.0, 0.4, 0.0, 0.1, 0.0, 0.25 };
  for (int a = 0; a < 6; ++a)
  {
    c.DomainBounds[a] = domain[a];
  }
  c.WallMargin = 0.001;
  return c;
}

void Near(const double* got, const double* want, double tolerance, const char* what)
{
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_NEAR(got[a], want[a], tolerance) << what << ", component " << a;
  }
}
} // namespace

TEST(SPHPhysics, EquationsOfStateAndInverse)
{
  const SPHConstants ideal = Water(false), tait = Water(true);
  for (double rho : { 1000.0, 1003.5, 1012.25, 1100.0 })
  {
    const double pIdeal = ideal.K * (rho - 1000.0);
    EXPECT_NEAR(meshfree::SPHPressureOf(rho, ideal), pIdeal, 1e-12 * (1.0 + pIdeal)) << rho;
    const double pTait = tait.TaitB * (std::pow(rho / 1000.0, 7.0) - 1.0);
    EXPECT_NEAR(meshfree::SPHPressureOf(rho, tait), pTait, 1e-12 * (1.0 + pTait)) << rho;
    // The inverse for p >= 0 gives the density back.
    EXPECT_NEAR(meshfree::SPHDensityOf(meshfree::SPHPressureOf(rho, ideal), ideal), rho, 1e-12 * rho) << rho;
    EXPECT_NEAR(meshfree::SPHDensityOf(meshfree::SPHPressureOf(rho, tait), tait), rho, 1e-12 * rho) << rho;
  }
  // Below the rest density the pressure is clamped to 0 (no tensile attraction), and the inverse of 0 is rho0.
  EXPECT_EQ(meshfree::SPHPressureOf(990.0, ideal), 0.0);
  EXPECT_EQ(meshfree::SPHPressureOf(990.0, tait), 0.0);
  EXPECT_EQ(meshfree::SPHDensityOf(0.0, ideal), 1000.0);
  EXPECT_EQ(meshfree::SPHDensityOf(0.0, tait), 1000.0);
  double p, term, inverse;
  meshfree::SPHParticleTerms(1010.0, ideal, &p, &term, &inverse);
  EXPECT_NEAR(p, 4000.0, 1e-9);
  EXPECT_NEAR(term, 4000.0 / (1010.0 * 1010.0), 1e-15);
  EXPECT_NEAR(inverse, 1.0 / 1010.0, 1e-18);
}

TEST(SPHPhysics, SeventhRoot)
{
  // The Tait inverse's root (Newton on +, *, /): within 2 ulp of pow, exact where the root is.
  EXPECT_EQ(meshfree::SPHSeventhRoot(1.0), 1.0);
  EXPECT_EQ(meshfree::SPHSeventhRoot(128.0), 2.0);
  EXPECT_EQ(meshfree::SPHSeventhRoot(2187.0), 3.0);
  for (double z = 1.0; z < 300.0; z = z * 1.0137 + 1e-3)
  {
    const double want = std::pow(z, 1.0 / 7.0);
    EXPECT_NEAR(meshfree::SPHSeventhRoot(z), want, 4.5e-16 * want) << z;
  }
  EXPECT_NEAR(meshfree::SPHSeventhRoot(1e12), std::pow(1e12, 1.0 / 7.0), 1e-15 * std::pow(1e12, 1.0 / 7.0));
}

TEST(SPHPhysics, PairForceByHand)
{
  SPHConstants c = Water(false);
  c.Viscous = 1;
  c.ViscousFactor = 1e-3 * c.Mass * c.ViscLap;
  c.Artificial = 1;
  c.ArtificialFactor = 0.02 * c.C0 * 0.5 * c.H;
  c.ArtificialEpsilon = 0.01 * 0.25 * c.H2;
  c.PressureFactor = c.Mass * c.GradientNorm;
  c.Gravity[2] = 0.0;
  const double xi[3] = { 0.1, 0.05, 0.1 }, xj[3] = { 0.1 + 0.006, 0.05 - 0.003, 0.1 + 0.009 };
  const double vi[3] = { 0.3, 0.0, -0.1 }, vj[3] = { -0.2, 0.1, 0.0 }; // approaching: (vi - vj) . (xi - xj) < 0
  const double rhoI = 1004.0, rhoJ = 998.0, pI = 1600.0, pJ = 0.0;
  meshfree::SPHAcceleration a(xi, vi, rhoI, 1.0 / rhoI, pI / (rhoI * rhoI));
  a.Fluid(xj, vj, rhoJ, 1.0 / rhoJ, pJ / (rhoJ * rhoJ), c);
  double got[3];
  a.Finish(got, c);

  // By hand: a_i = -m (p_i/rho_i^2 + p_j/rho_j^2 + Pi_ij) grad_i W + mu m (v_j - v_i) / (rho_i rho_j) lap W.
  double r[3], vr = 0.0, r2 = 0.0;
  for (int k = 0; k < 3; ++k)
  {
    r[k] = xi[k] - xj[k];
    r2 += r[k] * r[k];
    vr += (vi[k] - vj[k]) * r[k];
  }
  ASSERT_LT(vr, 0.0);
  const double dist = std::sqrt(r2);
  const double hs = 0.5 * c.H;
  const double artificial = -0.02 * c.C0 * hs * vr / (0.5 * (rhoI + rhoJ) * (r2 + 0.01 * hs * hs));
  const double pair = pI / (rhoI * rhoI) + pJ / (rhoJ * rhoJ) + artificial;
  const double spikyGradient = -3.0 * c.DensityNorm * (c.H - dist) * (c.H - dist) / dist; // times r_vec
  const double lap = c.ViscLap * (c.H - dist);
  double want[3];
  for (int k = 0; k < 3; ++k)
  {
    want[k] = -c.Mass * pair * spikyGradient * r[k] + 1e-3 * c.Mass * (vj[k] - vi[k]) / (rhoI * rhoJ) * lap;
  }
  const double scale = std::fabs(want[0]) + std::fabs(want[1]) + std::fabs(want[2]);
  ASSERT_GT(scale, 1.0);
  Near(got, want, 1e-12 * scale, "fluid pair");

  // The pressure pair (viscosity off) is antisymmetric, exactly: momentum is conserved.
  c.Viscous = 0;
  meshfree::SPHAcceleration forward(xi, vi, rhoI, 1.0 / rhoI, pI / (rhoI * rhoI));
  forward.Fluid(xj, vj, rhoJ, 1.0 / rhoJ, pJ / (rhoJ * rhoJ), c);
  meshfree::SPHAcceleration backward(xj, vj, rhoJ, 1.0 / rhoJ, pJ / (rhoJ * rhoJ));
  backward.Fluid(xi, vi, rhoI, 1.0 / rhoI, pI / (rhoI * rhoI), c);
  for (int k = 0; k < 3; ++k)
  {
    EXPECT_EQ(forward.Ap[k], -backward.Ap[k]) << k;
  }

  // Receding pairs get no artificial viscosity; pairs at r >= h and the particle itself (r = 0) no pressure force.
  meshfree::SPHAcceleration receding(xi, vj, rhoI, 1.0 / rhoI, pI / (rhoI * rhoI));
  receding.Fluid(xj, vi, rhoJ, 1.0 / rhoJ, pJ / (rhoJ * rhoJ), c);
  const double plain = -c.Mass * (pI / (rhoI * rhoI)) * spikyGradient;
  const double recedingWant[3] = { plain * r[0], plain * r[1], plain * r[2] };
  Near(receding.Ap, recedingWant, 1e-12 * scale, "receding pair");
  const double far[3] = { xi[0] + c.H, xi[1], xi[2] };
  meshfree::SPHAcceleration none(xi, vi, rhoI, 1.0 / rhoI, pI / (rhoI * rhoI));
  none.Fluid(far, vj, rhoJ, 1.0 / rhoJ, 1.0, c);
  none.Fluid(xi, vj, rhoJ, 1.0 / rhoJ, 1.0, c);
  EXPECT_EQ(none.Ap[0], 0.0);
  EXPECT_EQ(none.Ap[1], 0.0);
  EXPECT_EQ(none.Ap[2], 0.0);
}

TEST(SPHPhysics, WallPairSurfaceTensionGravityAnd2D)
{
  SPHConstants c = Water(false);
  c.PressureFactor = c.Mass * c.GradientNorm;
  c.Artificial = 1; // must not act against walls
  c.ArtificialFactor = 1.0;
  c.Tension = 1;
  c.SurfaceTension = 0.07;
  const double xi[3] = { 0.1, 0.05, 0.005 }, xb[3] = { 0.1, 0.05, -0.005 };
  const double vi[3] = { 0.0, 0.0, -1.0 };
  const double rhoI = 1000.0, termI = 0.002, termB = 0.003;
  meshfree::SPHAcceleration a(xi, vi, rhoI, 1.0 / rhoI, termI);
  a.Wall(xb, termB, c);
  double got[3];
  a.Finish(got, c);
  // Pressure: -m (termI + termB) grad W along +z (r = 0.01); colour: one neighbour of volume m / rho0.
  const double dist = 0.01;
  const double pressure = c.Mass * (termI + termB) * 3.0 * c.DensityNorm * (c.H - dist) * (c.H - dist) / dist * dist;
  const double q = c.H2 - dist * dist;
  const double volume = c.Mass / c.RestDensity;
  const double normalZ = volume * -6.0 * c.Poly6 * q * q * dist; // grad c = sum V grad W, grad W = -6 poly6 q^2 r
  const double laplacian = volume * -6.0 * c.Poly6 * q * (3.0 * q - 4.0 * dist * dist);
  ASSERT_GT(std::fabs(normalZ) * c.H, 0.25); // a surface particle
  const double tension = -c.SurfaceTension * laplacian / rhoI * (normalZ / std::fabs(normalZ));
  const double want[3] = { 0.0, 0.0, pressure - 9.81 + tension };
  Near(got, want, 1e-12 * (std::fabs(pressure) + std::fabs(tension) + 9.81), "wall pair");

  // Gravity alone in 2D: y is zeroed whatever the gravity.
  SPHConstants flat = Water(false);
  flat.Dimension = 2;
  flat.Gravity[1] = 3.0;
  meshfree::SPHAcceleration lone(xi, vi, rhoI, 1.0 / rhoI, 0.0);
  lone.Finish(got, flat);
  EXPECT_EQ(got[0], 0.0);
  EXPECT_EQ(got[1], 0.0);
  EXPECT_EQ(got[2], -9.81);
}

TEST(SPHPhysics, AdamiDummyPressureOfAHydrostaticColumn)
{
  // A column at rest of height H: p_f = rho0 g (H - z_f). The extrapolation (Adami et al. 2012, eq. 27) gives a
  // dummy below the floor the column's pressure continued linearly, p_b = rho0 g (H - z_b), whatever its
  // neighbours' positions and weights.
  const SPHConstants c = Water(false);
  const double g = 9.81, top = 0.2, dx = 0.005;
  const double xb[3] = { 0.1, 0.05, -0.0025 };
  meshfree::SPHWallPressure wall;
  int neighbours = 0;
  for (int i = -4; i <= 4; ++i)
  {
    for (int j = -4; j <= 4; ++j)
    {
      for (int k = 0; k <= 4; ++k)
      {
        const double xf[3] = { xb[0] + i * dx + 0.0003 * j, xb[1] + j * dx, 0.0025 + k * dx + 0.0001 * i };
        const double r[3] = { xb[0] - xf[0], xb[1] - xf[1], xb[2] - xf[2] };
        const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        neighbours += r2 < c.H2 ? 1 : 0;
        wall.Add(r, r2, 1000.0 * g * (top - xf[2]), 1000.0, c);
      }
    }
  }
  ASSERT_GT(neighbours, 20);
  const double want = 1000.0 * g * (top - xb[2]);
  EXPECT_NEAR(wall.Pressure(), want, 1e-11 * want);
  const double rhoB = 1000.0 + want / c.K;
  EXPECT_NEAR(wall.Term(c), want / (rhoB * rhoB), 1e-11 * want / (rhoB * rhoB));

  // Above the free surface the extrapolated pressure is negative: clamped to 0. No neighbours: 0.
  meshfree::SPHWallPressure above;
  const double r[3] = { 0.0, 0.0, 0.01 };
  above.Add(r, 1e-4, 0.0, 1000.0, c); // a neighbour 0.01 below at p = 0: p_b = -rho0 g 0.01 < 0
  EXPECT_EQ(above.Pressure(), 0.0);
  EXPECT_EQ(meshfree::SPHWallPressure().Pressure(), 0.0);
  EXPECT_EQ(meshfree::SPHWallPressure().Term(c), 0.0);
}

TEST(SPHPhysics, KickDriftAndWallClamp)
{
  const SPHConstants c = Water(false);
  double x[3] = { 0.2, 0.05, 0.1 }, v[3] = { 1.0, -2.0, 0.5 };
  const double a[3] = { 0.0, 4.0, -9.81 }, dt = 1e-3;
  meshfree::SPHKickDrift(x, v, a, 0.5 * dt, dt);
  const double vWant[3] = { 1.0, -2.0 + 0.5 * dt * 4.0, 0.5 - 0.5 * dt * 9.81 };
  Near(v, vWant, 1e-15, "kick");
  const double xWant[3] = { 0.2 + dt * vWant[0], 0.05 + dt * vWant[1], 0.1 + dt * vWant[2] };
  Near(x, xWant, 1e-15, "drift");
  meshfree::SPHKick(v + 2, a + 2, 0.5 * dt);
  EXPECT_NEAR(v[2], 0.5 - dt * 9.81, 1e-15);

  // Past the low z wall and the high x wall: put back WallMargin inside, the outward velocity removed, the
  // inward and tangential ones kept.
  double y[3] = { 0.4005, 0.05, -0.002 }, w[3] = { 0.7, 0.3, -1.5 };
  meshfree::SPHWallClamp(y, w, c);
  EXPECT_EQ(y[0], 0.4 - c.WallMargin);
  EXPECT_EQ(y[1], 0.05);
  EXPECT_EQ(y[2], 0.0 + c.WallMargin);
  EXPECT_EQ(w[0], 0.0);
  EXPECT_EQ(w[1], 0.3);
  EXPECT_EQ(w[2], 0.0);
  double z[3] = { -0.01, 0.05, 0.1 }, u[3] = { 0.2, 0.0, 0.0 }; // already moving back in: kept
  meshfree::SPHWallClamp(z, u, c);
  EXPECT_EQ(z[0], c.WallMargin);
  EXPECT_EQ(u[0], 0.2);
  // 2D: y is not an axis; without walls nothing is clamped.
  SPHConstants flat = c;
  flat.Dimension = 2;
  double p2[3] = { 0.1, 5.0, 0.1 }, v2[3] = { 0.0, 1.0, 0.0 };
  meshfree::SPHWallClamp(p2, v2, flat);
  EXPECT_EQ(p2[1], 5.0);
  EXPECT_EQ(v2[1], 1.0);
  SPHConstants open = c;
  open.Walls = 0;
  double p3[3] = { -1.0, -1.0, -1.0 }, v3[3] = { -1.0, -1.0, -1.0 };
  meshfree::SPHWallClamp(p3, v3, open);
  EXPECT_EQ(p3[0], -1.0);
  EXPECT_EQ(v3[2], -1.0);
}

TEST(SPHPhysics, CFLStep)
{
  SPHConstants c = Water(false);
  const double v[2][3] = { { 1.0, 2.0, 2.0 }, { 0.0, 0.5, 0.0 } };     // |v| = 3
  const double a[2][3] = { { 0.0, 0.0, -9.81 }, { 30.0, 0.0, 40.0 } }; // |a| = 50
  const double rho[2] = { 1010.0, 1030.0 };
  meshfree::SPHExtremes e, first, second;
  e.Rho = first.Rho = second.Rho = c.RestDensity;
  e.Add(v[0], a[0], rho[0]);
  e.Add(v[1], a[1], rho[1]);
  second.Add(v[1], a[1], rho[1]); // the other order, split and merged: the same maxima
  first.Add(v[0], a[0], rho[0]);
  second.Merge(first);
  EXPECT_EQ(e.V2, second.V2);
  EXPECT_EQ(e.A2, second.A2);
  EXPECT_EQ(e.Rho, second.Rho);
  EXPECT_EQ(e.V2, 9.0);
  EXPECT_EQ(e.A2, 2500.0);
  EXPECT_EQ(e.Rho, 1030.0);

  const double h = c.H, lambda = 0.25;
  const double acoustic = h / (c.C0 + 3.0), force = std::sqrt(h / 50.0), viscous = 0.125 * h * h / c.Nu;
  EXPECT_NEAR(meshfree::SPHStableStep(e, lambda, c), lambda * std::min({ acoustic, force, viscous }), 1e-17);
  // Tait: the sound speed at the largest density, c0 (rho/rho0)^3.
  c.Tait = 1;
  const double taitSpeed = c.C0 * std::pow(1.03, 3.0);
  EXPECT_NEAR(
    meshfree::SPHStableStep(e, lambda, c), lambda * std::min({ h / (taitSpeed + 3.0), force, viscous }), 1e-15);
  // Each limit binding in turn: a large acceleration, then a large viscosity.
  c.Tait = 0;
  meshfree::SPHExtremes violent = e;
  violent.A2 = 1e10; // |a| = 1e5: sqrt(h / |a|) ~ 4.5e-4 < h / (c + v) ~ 8.7e-4
  EXPECT_NEAR(meshfree::SPHStableStep(violent, lambda, c), lambda * std::sqrt(h / 1e5), 1e-17);
  SPHConstants thick = c;
  thick.Nu = 1.0; // 0.125 h^2 / nu = 5e-5
  EXPECT_NEAR(meshfree::SPHStableStep(e, lambda, thick), lambda * 0.125 * h * h, 1e-18);
  // At rest without viscosity: the acoustic limit alone.
  meshfree::SPHExtremes rest;
  rest.Rho = c.RestDensity;
  c.Tait = 0;
  c.Nu = 0.0;
  EXPECT_NEAR(meshfree::SPHStableStep(rest, lambda, c), lambda * h / c.C0, 1e-17);
  // A non-finite value gives NaN (the integrator stops).
  const double bad[3] = { std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0 };
  rest.Add(bad, a[0], 1000.0);
  EXPECT_TRUE(std::isnan(meshfree::SPHStableStep(rest, lambda, c)));
}

TEST(SPHPhysics, NearBoundaryAndGridCells)
{
  SPHConstants c = Water(false);
  const double inside[3] = { 0.2, 0.05, 0.1 }, nearFloor[3] = { 0.2, 0.05, 0.015 };
  const double nearSide[3] = { 0.2, 0.085, 0.1 };
  EXPECT_FALSE(meshfree::SPHNearBoundary(inside, c));
  EXPECT_TRUE(meshfree::SPHNearBoundary(nearFloor, c));
  EXPECT_TRUE(meshfree::SPHNearBoundary(nearSide, c));
  c.Dimension = 2; // y is not a wall axis in 2D
  EXPECT_FALSE(meshfree::SPHNearBoundary(nearSide, c));
  c.ObstacleBox[0] = 0.15; // an obstacle's box around the point
  c.ObstacleBox[1] = 0.25;
  c.ObstacleBox[2] = 0.0;
  c.ObstacleBox[3] = 0.1;
  c.ObstacleBox[4] = 0.05;
  c.ObstacleBox[5] = 0.15;
  EXPECT_TRUE(meshfree::SPHNearBoundary(inside, c));

  // Cell of a coordinate: truncation, clamped into [0, dim).
  EXPECT_EQ(meshfree::GridAxisCell(0.35, 10.0, 8), 3);
  EXPECT_EQ(meshfree::GridAxisCell(-0.1, 10.0, 8), 0);
  EXPECT_EQ(meshfree::GridAxisCell(2.0, 10.0, 8), 7);
  std::int64_t first = -1, last = -1;
  EXPECT_TRUE(meshfree::GridAxisReach(0.35, 0.1, 1e-9, 10.0, 8, &first, &last));
  EXPECT_EQ(first, 2);
  EXPECT_EQ(last, 4);
  EXPECT_FALSE(meshfree::GridAxisReach(1.5, 0.1, 1e-9, 10.0, 8, &first, &last));
}
