// 2D dam break (column a x 2a, a / dx = 40) against Martin & Moyce 1952, Table 2 (n^2 = 2), in their units
// Z = x_front / a, T = t sqrt(2 g / a). Water (mu = 1e-3 Pa s), artificial viscosity alpha = 0.05 (the default is
// 0.02; see SPHFluid.h), free-slip walls, tank 5a long. Run time: about 6 s (3,200 particles, about 3,000 steps).
//
// Front: the leading edge of the fluid on the floor, as a wave gauge just above the bed sees it (DualSPHysics
// measures its validation case with a gauge at 0.03 a): the largest x of the particles whose centre lies within
// 1.5 dx of the floor and that have at least 3 fluid neighbours (so a detached droplet does not count), plus
// half a spacing (the particle's extent). The largest x of any particle is printed beside it; the two agree
// within 2 % here.
//
// The experiment's time origin. The experiment's column is released by removing its retaining partition, which
// takes a finite time; a simulation released instantaneously runs ahead of the early points. Peers compare with
// a corrected time origin: Lethe's Martin & Moyce VOF example (chaos-polymtl/lethe,
// examples/multiphysics/dam-break/dam-break-2d.py, time_correction = 0.175) adds 0.175 to the simulated T before
// comparing; an OpenFOAM interFoam validation of the same table (vamseeachanta/digitalmodel, pull request 1260)
// reports a raw mean deviation of 9.8 % and applies the same 0.175 for its 10 % gate. This test adopts the
// correction as published (it is not fitted to our run: our own best shift would be 0.25): the simulated front
// at T - 0.175 is compared with the table at T, for every tabulated 0.84 <= T <= 3.33.
//
// Asserted:
//  * corrected time origin: |Z_SPH(T - 0.175) / Z_M&M(T) - 1| <= 10 % at all 14 points (the gate;
//    measured at most 7.6 %, at T = 1.19);
//  * raw time origin (Z_SPH(T) against the table at the same T): within 10 % for T >= 2.32, where the gate's
//    delay no longer dominates (measured 7-10 %, little margin); for 0.84 <= T <= 2.20 the raw front leads by
//    11.5-19 %, guarded at <= 20 % so that a regression shows. What was measured not to remove that raw lead:
//    the front definition (max x gives the same), the resolution (a/dx = 80 leads as much), the kernel (poly6,
//    h = 2.6 or 3 dx), the stiffness (c0 = 20 sqrt(g H)), the artificial viscosity (0 to 0.1), wall friction
//    (artificial viscosity against the wall dummies, as DualSPHysics does) and a hydrostatically compressed
//    initial state;
//  * the Ritter bound (shallow-water front speed 2 sqrt(g 2a), dZ/dT <= 2), mass conservation and containment.
#include "SPHScenes.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace sphscenes;

TEST(SPHDamBreak, FrontAgainstMartinMoyce)
{
  DamBreakFronts fronts;
  ASSERT_NO_FATAL_FAILURE(RunMartinMoyceDamBreak(meshfree::SPHSolver::WCSPH, fronts));
  const double gateEnd = 2.3; // the raw time origin meets 10 % from here on (see the header)
  for (int k = 1; k < MartinMoyceSize; ++k)
  {
    const double T = MartinMoyceT[k];
    const double corrected = fronts.Corrected[k] / MartinMoyceZ[k] - 1.0;
    const double raw = fronts.Raw[k] / MartinMoyceZ[k] - 1.0;
    EXPECT_LE(std::fabs(corrected), 0.10) << "issue gate (corrected time origin), T = " << T;
    if (T >= gateEnd)
    {
      EXPECT_LE(std::fabs(raw), 0.10) << "raw time origin, T = " << T;
    }
    else
    {
      EXPECT_GE(raw, 0.0) << "the raw early front should lead the experiment, T = " << T;
      EXPECT_LE(raw, 0.20) << "raw early lead grew beyond its measured level, T = " << T;
    }
  }
  EXPECT_EQ(fronts.Particles, 40 * 80);
}
