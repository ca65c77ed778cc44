// SPH core tests' shared scenes: box set-up, containment, and the 2D dam break of Martin & Moyce 1952 (Table 2,
// n^2 = 2) run to the table's times with the front measured as TestSPHDamBreak.cxx's header explains (a gauge just
// above the bed: the largest x of the particles within 1.5 dx of the floor with at least 3 fluid neighbours, plus
// half a spacing), at the corrected (T - 0.175, Lethe's time-origin correction) and raw (T) origins.
#ifndef meshfree_Testing_SPHScenes_h
#define meshfree_Testing_SPHScenes_h

#include "SPH/SPHFluid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <vector>

namespace sphscenes
{
using meshfree::Index;
using meshfree::SPHFluid;
using meshfree::SPHParameters;
using meshfree::SPHState;

inline void SetBox(double* target, std::initializer_list<double> values)
{
  int i = 0;
  for (double v : values)
  {
    target[i++] = v;
  }
}

inline bool InsideDomain(const SPHState& s, const SPHParameters& p)
{
  for (Index i = 0; i < s.Size(); ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (a == 1 && p.Dimension == 2)
      {
        continue;
      }
      const double x = s.Position[3 * i + a];
      if (!(x > p.DomainBounds[2 * a] && x < p.DomainBounds[2 * a + 1]))
      {
        return false;
      }
    }
  }
  return true;
}

// Martin & Moyce 1952, Table 2 (n^2 = 2): T = t sqrt(2 g / a), Z = x_front / a.
inline constexpr double MartinMoyceT[] = { 0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20, 2.32, 2.51, 2.65, 2.83,
  2.98, 3.11, 3.33 };
inline constexpr double MartinMoyceZ[] = { 1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78, 3.00, 3.22, 3.44,
  3.67, 3.89, 4.11 };
inline constexpr int MartinMoyceSize = 15;
inline constexpr double MartinMoyceOrigin = 0.175; // Lethe's time-origin correction (TestSPHDamBreak.cxx)

struct DamBreakFronts
{
  std::vector<double> Corrected = std::vector<double>(MartinMoyceSize, 0.0); // Z(SPH, T - origin)
  std::vector<double> Raw = std::vector<double>(MartinMoyceSize, 0.0);       // Z(SPH, T)
  Index Particles = 0;
  long Steps = 0;
};

/// The column a x 2a (a = 0.1, a / dx = 40) in a tank 5a long, water, artificial viscosity 0.05, with `solver`;
/// fills `out` for the tabulated 0.84 <= T <= 3.33. Asserts along the way: the Ritter bound (dZ/dT <= 2), finite
/// statistics, containment. Use with ASSERT_NO_FATAL_FAILURE.
inline void RunMartinMoyceDamBreak(meshfree::SPHSolver solverKind, DamBreakFronts& out)
{
  const double a = 0.1, dx = a / 40.0, g = 9.81;
  SPHParameters p;
  p.Dimension = 2;
  p.ParticleSpacing = dx;
  p.Viscosity = 1e-3;
  p.ArtificialViscosity = 0.05; // see TestSPHDamBreak.cxx's header
  p.Solver = solverKind;
  const double domain[6] = { 0.0, 5.0 * a, 0.0, 0.0, 0.0, 2.5 * a };
  SetBox(p.FluidBounds, { 0.0, a, 0.0, 0.0, 0.0, 2.0 * a });
  std::copy(domain, domain + 6, p.DomainBounds);
  SPHFluid solver;
  solver.Setup(p);
  SPHState s = solver.InitialState();
  ASSERT_EQ(s.Size(), 40 * 80);

  const double scale = std::sqrt(2.0 * g / a);
  // The times the state is needed at, in order: T - origin (corrected) and T (raw) for every tabulated T.
  struct Probe
  {
    double T;
    int Row;
    bool Raw;
  };
  std::vector<Probe> probes;
  for (int k = 1; k < MartinMoyceSize; ++k) // 0.84 <= T <= 3.33
  {
    probes.push_back({ MartinMoyceT[k] - MartinMoyceOrigin, k, false });
    probes.push_back({ MartinMoyceT[k], k, true });
  }
  std::stable_sort(probes.begin(), probes.end(), [](const Probe& l, const Probe& r) { return l.T < r.T; });

  double previousT = 0.0, previousZ = 1.0;
  for (const Probe& probe : probes)
  {
    ASSERT_EQ(solver.Advance(s, probe.T / scale), SPHFluid::Status::Ok) << solver.ErrorMessage();
    const std::vector<int> neighbours = solver.NeighborCounts(s);
    double front = 0.0;
    for (Index i = 0; i < s.Size(); ++i)
    {
      const double x = s.Position[3 * i], z = s.Position[3 * i + 2];
      if (z - domain[4] < 1.5 * dx && neighbours[i] >= 3)
      {
        front = std::max(front, x);
      }
    }
    const double z = (front + 0.5 * dx) / a;
    (probe.Raw ? out.Raw : out.Corrected)[probe.Row] = z;
    EXPECT_LE((z - previousZ) / (probe.T - previousT), 2.0) << "faster than the Ritter front at T = " << probe.T;
    previousT = probe.T;
    previousZ = z;
    ASSERT_TRUE(SPHFluid::Statistics(s, solver.ParticleMass()).Finite);
    for (Index i = 0; i < s.Size(); ++i)
    {
      ASSERT_GT(s.Position[3 * i], domain[0]);
      ASSERT_LT(s.Position[3 * i], domain[1]);
      ASSERT_GT(s.Position[3 * i + 2], domain[4]);
      ASSERT_LT(s.Position[3 * i + 2], domain[5]);
    }
  }
  out.Particles = s.Size();
  out.Steps = static_cast<long>(s.Steps);
  std::printf("   T   Z(M&M) | Z(SPH, T-0.175) error  | Z(SPH, T) error (raw origin)\n");
  for (int k = 1; k < MartinMoyceSize; ++k)
  {
    std::printf("%5.2f  %5.2f  |  %6.3f         %+5.1f %% |  %6.3f  %+5.1f %%\n", MartinMoyceT[k], MartinMoyceZ[k],
      out.Corrected[k], 100.0 * (out.Corrected[k] / MartinMoyceZ[k] - 1.0), out.Raw[k],
      100.0 * (out.Raw[k] / MartinMoyceZ[k] - 1.0));
  }
  std::printf("%ld steps\n", out.Steps);
}
} // namespace sphscenes

#endif
