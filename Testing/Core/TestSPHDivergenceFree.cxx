// DFSPH (SPH/SPHDivergenceFree.cxx): the hydrostatic column in 2D and 3D (average density error, containment, rest,
// the pressure against rho0 g (H - z)), thread-count independence, the bit-identical continuation of a copied state
// (what the time cache relies on), hostile settings, and the 2D dam-break front against Martin & Moyce 1952.
//
// The hydrostatic column (issue 25 asks for a pressure L2 <= 2 %). Run with tolerances of 1e-4 % (density and
// divergence, up to 500 iterations) it comes to rest (kinetic energy at t sqrt(g / H) = 10: 1.5e-6 (2D), 9e-6 (3D)
// rho0 g H V) and its pressure's relative L2 error against rho0 g (H - z), averaged over t sqrt(g / H) = 8, 8.5,
// ..., 10, is 0.019 (2D; worst sample 0.019) and 0.010 (3D; worst 0.010); at the default tolerances (0.01 % /
// 0.1 %) 0.017 and 0.010. The Pressure compared is the DFSPH output (SPHDivergenceFree.cxx, "Pressure output"):
// the solves' multipliers averaged over the Advance() call (here the half unit before each sample: the run first
// goes to 7.5), scaled by the particle's gradient strength and Shepard-averaged with poly6's shape. With the last
// step's multipliers Shepard-averaged with the spiky shape (before) the same runs gave 0.042 / 0.040 (1e-4 %) and
// 0.047 / 0.036 (defaults): the column's square lattice collapses into a denser packing at t sqrt(g / H) = 1.1-1.3,
// after which the one-step multipliers jitter, scatter per particle and read 2.5 % high (the discrete gradient is
// 2.5 % weaker off the lattice). Before a-d of SPHDivergenceFree.cxx ("Why": the wall coupling made the adjoint of
// the density rate, the full Adami increase, no Shepard average in the warm start, both solves' impulses in
// Pressure) this test gave, with the same settings, a mean L2 of 0.44 (2D; worst sample 0.97) and 0.15 (3D; worst
// 0.34) and a kinetic energy of 5.8e-5 (2D) and 7.6e-4 (3D). At the default tolerances the column rests too since
// e of "Why" (HydrostaticColumnDefaultTolerances2D/3D below).
#include "SPH/SPHFluid.h"
#include "SPHScenes.h"

#include "Common/Parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

using meshfree::Index;
using meshfree::SPHFluid;
using meshfree::SPHParameters;
using meshfree::SPHSolver;
using meshfree::SPHState;

using sphscenes::InsideDomain;
using sphscenes::SetBox;

namespace
{
struct ColumnResult
{
  double PressureL2 = 0.0;          // mean over the samples t sqrt(g / H) = 8, 8.5, ..., 10 (each the average
                                    // Pressure over the half unit before it)
  double WorstPressureL2 = 0.0;     // largest of those
  double AverageDensityError = 0.0; // mean of max(rho / rho0 - 1, 0) over all particles (compression only), at 10
  double WorstInterior = 0.0;       // max rho / rho0 - 1 (compression) below the surface layer, at 10
  double KineticEnergy = 0.0;       // at 10, over rho0 g H V H
  double DensityIterations = 0.0;   // per step, over the whole run
  double DivergenceIterations = 0.0;
  double SecondsPerStep = 0.0;      // wall-clock, over the whole run
};

// A column of height H = 40 dx (2D) or 16 dx (3D), run for t sqrt(g / H) = 10; its pressure's relative L2 error
// against rho0 g (H - z) sampled at t sqrt(g / H) = 8, 8.5, ..., 10 (it fluctuates from one instant to the next).
ColumnResult Column(int dimension, bool defaultTolerances)
{
  const double dx = 0.01, g = 9.81;
  const double H = (dimension == 2 ? 40 : 16) * dx, W = (dimension == 2 ? 20 : 8) * dx;
  SPHParameters p;
  p.Solver = SPHSolver::DFSPH;
  p.Dimension = dimension;
  p.ParticleSpacing = dx;
  p.Viscosity = 0.5; // damps the start-up transient; the equilibrium does not depend on it
  if (!defaultTolerances)
  {
    p.DensityTolerance = 1e-4; // percent: the pressure, not only the density, converged (see the header)
    p.DivergenceTolerance = 1e-4;
    p.MaximumIterations = 500;
  }
  SetBox(p.FluidBounds, { 0.0, W, 0.0, dimension == 2 ? 0.0 : W, 0.0, H });
  SetBox(p.DomainBounds, { 0.0, W, 0.0, dimension == 2 ? 0.0 : W, 0.0, 1.25 * H });
  SPHFluid fluid;
  fluid.Setup(p);
  SPHState s = fluid.InitialState();
  const double unit = std::sqrt(H / g);
  ColumnResult r;
  const int samples = 5;
  long steps = 0, densityIterations = 0, divergenceIterations = 0;
  const auto started = std::chrono::steady_clock::now();
  // The DFSPH Pressure output is the time average over the Advance() call (SPHDivergenceFree.cxx, "Pressure
  // output"): each sample averages the half unit before it, so the run first goes to t sqrt(g / H) = 7.5.
  EXPECT_EQ(fluid.Advance(s, 7.5 * unit), SPHFluid::Status::Ok) << fluid.ErrorMessage();
  steps += s.Report.Steps;
  densityIterations += s.Report.DensityIterations;
  divergenceIterations += s.Report.DivergenceIterations;
  for (int k = 0; k < samples; ++k)
  {
    EXPECT_EQ(fluid.Advance(s, (8.0 + 0.5 * k) * unit), SPHFluid::Status::Ok) << fluid.ErrorMessage();
    steps += s.Report.Steps;
    densityIterations += s.Report.DensityIterations;
    divergenceIterations += s.Report.DivergenceIterations;
    double num = 0.0, den = 0.0;
    for (Index i = 0; i < s.Size(); ++i)
    {
      const double exact = p.RestDensity * g * (H - s.Position[3 * i + 2]);
      EXPECT_GE(s.Pressure[i], 0.0);
      num += (s.Pressure[i] - exact) * (s.Pressure[i] - exact);
      den += exact * exact;
    }
    const double l2 = std::sqrt(num / den);
    std::printf("t sqrt(g / H) = %.1f: pressure L2 %.4f\n", 8.0 + 0.5 * k, l2);
    r.PressureL2 += l2 / samples;
    r.WorstPressureL2 = std::max(r.WorstPressureL2, l2);
  }
  r.SecondsPerStep =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() / std::max(1L, steps);
  r.DensityIterations = static_cast<double>(densityIterations) / std::max(1L, steps);
  r.DivergenceIterations = static_cast<double>(divergenceIterations) / std::max(1L, steps);
  EXPECT_TRUE(SPHFluid::Statistics(s, fluid.ParticleMass()).Finite);
  EXPECT_TRUE(InsideDomain(s, p));
  std::printf("unconverged steps: %ld\n", fluid.UnconvergedSteps());
  for (Index i = 0; i < s.Size(); ++i)
  {
    const double z = s.Position[3 * i + 2];
    r.AverageDensityError += std::max(s.Density[i] / p.RestDensity - 1.0, 0.0);
    if (z < H - fluid.SupportRadius())
    {
      r.WorstInterior = std::max(r.WorstInterior, s.Density[i] / p.RestDensity - 1.0);
    }
  }
  r.AverageDensityError /= static_cast<double>(std::max<Index>(1, s.Size()));
  r.KineticEnergy = SPHFluid::Statistics(s, fluid.ParticleMass()).KineticEnergy /
    (p.RestDensity * g * H * W * (dimension == 3 ? W : 1.0) * H);
  std::printf("DFSPH hydrostatic %dD: %ld particles, %ld steps, pressure L2 mean %.4f / worst %.4f, average density "
              "error %.5f %%, worst interior compression %.4f, KE/(rho0 g H V) %.2e, last step: %d density / %d "
              "divergence iterations, solver's average error %.5f %%\n",
    dimension, static_cast<long>(s.Size()), s.Steps, r.PressureL2, r.WorstPressureL2, 100.0 * r.AverageDensityError,
    r.WorstInterior, r.KineticEnergy, s.Report.LastDensityIterations, s.Report.LastDivergenceIterations,
    100.0 * s.Report.AverageDensityError);
  std::printf("  per step: %.2f density / %.2f divergence iterations, %.3f ms wall-clock\n", r.DensityIterations,
    r.DivergenceIterations, 1e3 * r.SecondsPerStep);
  return r;
}
}

TEST(SPHDivergenceFree, HydrostaticColumn2D)
{
  const ColumnResult r = Column(2, false);
  EXPECT_LE(r.AverageDensityError, 0.001); // the gate: 0.1 %
  EXPECT_LE(r.WorstInterior, 0.01);
  EXPECT_LE(r.KineticEnergy, 1e-4); // at rest (measured 1.5e-6)
  EXPECT_LE(r.PressureL2, 0.02);    // the gate (measured 0.019)
}

TEST(SPHDivergenceFree, HydrostaticColumn3D)
{
  const ColumnResult r = Column(3, false);
  EXPECT_LE(r.AverageDensityError, 0.001);
  EXPECT_LE(r.WorstInterior, 0.01);
  EXPECT_LE(r.KineticEnergy, 1e-4); // measured 9.1e-6
  EXPECT_LE(r.PressureL2, 0.02);    // measured 0.010
}

// The same columns at the default tolerances (0.01 % density, 0.1 % divergence, at most 100 iterations): the case
// users run. With the relaxed Jacobi solves that stopped on the average error alone (before the projected CG and
// the density solve's tenfold reduction, SPHDivergenceFree.cxx "Solver" and "Stopping") these columns never came
// to rest: kinetic energy 1.2e-3 (2D) and 3.7e-4 (3D), pressure L2 mean 0.55 and 0.28 (worst samples 1.06, 0.37).
TEST(SPHDivergenceFree, HydrostaticColumnDefaultTolerances2D)
{
  const ColumnResult r = Column(2, true);
  EXPECT_LE(r.AverageDensityError, 0.001);
  EXPECT_LE(r.WorstInterior, 0.01);
  EXPECT_LE(r.KineticEnergy, 1e-4); // at rest (measured 5.4e-7)
  EXPECT_LE(r.PressureL2, 0.02);    // the gate (measured 0.017, worst sample 0.018)
}

TEST(SPHDivergenceFree, HydrostaticColumnDefaultTolerances3D)
{
  const ColumnResult r = Column(3, true);
  EXPECT_LE(r.AverageDensityError, 0.001);
  EXPECT_LE(r.WorstInterior, 0.01);
  EXPECT_LE(r.KineticEnergy, 1e-4); // measured 1.6e-5
  EXPECT_LE(r.PressureL2, 0.02);    // measured 0.010 (worst sample 0.011)
}

namespace
{
SPHParameters SmallScene(int dimension)
{
  SPHParameters p;
  p.Solver = SPHSolver::DFSPH;
  p.Dimension = dimension;
  p.ParticleSpacing = 0.01;
  p.Viscosity = 0.01;
  SetBox(p.FluidBounds, { 0.0, 0.1, 0.0, dimension == 2 ? 0.0 : 0.05, 0.0, 0.15 });
  SetBox(p.DomainBounds, { 0.0, 0.3, 0.0, dimension == 2 ? 0.0 : 0.05, 0.0, 0.2 });
  return p;
}
}

TEST(SPHDivergenceFree, SameBitsWhateverTheThreadCount)
{
  for (int dimension : { 2, 3 })
  {
    SPHParameters p = SmallScene(dimension);
    std::vector<SPHState> results;
    for (int threads : { 1, 2, 3 })
    {
      meshfree::SetMaxThreads(threads);
      SPHFluid fluid;
      fluid.Setup(p);
      SPHState s = fluid.InitialState();
      ASSERT_EQ(fluid.Advance(s, 0.1), SPHFluid::Status::Ok) << fluid.ErrorMessage();
      EXPECT_GT(s.Report.DensityIterations, 0);
      results.push_back(s);
    }
    meshfree::SetMaxThreads(0);
    for (std::size_t k = 1; k < results.size(); ++k)
    {
      EXPECT_EQ(results[k].Position, results[0].Position) << dimension << "D, run " << k;
      EXPECT_EQ(results[k].Velocity, results[0].Velocity);
      EXPECT_EQ(results[k].Pressure, results[0].Pressure);
      EXPECT_EQ(results[k].DensityStiffness, results[0].DensityStiffness);
      EXPECT_EQ(results[k].Report.DensityIterations, results[0].Report.DensityIterations);
    }
  }
}

TEST(SPHDivergenceFree, CopiedStateContinuesBitForBit)
{
  // What the source's time cache does: a state kept at an output time and restored later continues exactly as
  // the uninterrupted run (the warm-start stiffness travels with the state).
  SPHParameters p = SmallScene(2);
  SPHFluid a, b;
  a.Setup(p);
  b.Setup(p);
  SPHState s = a.InitialState();
  ASSERT_EQ(a.Advance(s, 0.05), SPHFluid::Status::Ok);
  SPHState copy = s;
  ASSERT_EQ(a.Advance(s, 0.1), SPHFluid::Status::Ok);
  ASSERT_EQ(b.Advance(copy, 0.1), SPHFluid::Status::Ok); // another solver object, as after a cache restore
  EXPECT_EQ(copy.Position, s.Position);
  EXPECT_EQ(copy.Velocity, s.Velocity);
  EXPECT_EQ(copy.Id, s.Id);
  EXPECT_EQ(copy.Steps, s.Steps);
  EXPECT_EQ(s.DensityStiffness.size(), static_cast<std::size_t>(s.Size()));
}

TEST(SPHDivergenceFree, FieldsOfTheLastOutputAreReusedOnlyForThatState)
{
  // The first step of an Advance() reuses the fields (neighbour lists, density, gradients) that the last call's
  // output computed, when the state it starts from has the same positions and densities. Without a reorder at
  // the start of the call (ReorderInterval larger than the run) that path is taken: it must give the bits of a
  // solver that computes them afresh; and a solver handed an older state (a cache restore into the same object)
  // must not reuse the newer state's fields.
  for (int dimension : { 2, 3 })
  {
    SPHParameters p = SmallScene(dimension);
    p.ReorderInterval = 100000;
    SPHFluid a, fresh;
    a.Setup(p);
    fresh.Setup(p);
    SPHState s = a.InitialState();
    ASSERT_EQ(a.Advance(s, 0.03), SPHFluid::Status::Ok) << a.ErrorMessage();
    const SPHState older = s;
    ASSERT_EQ(a.Advance(s, 0.06), SPHFluid::Status::Ok); // reuses the fields of the output at 0.03
    SPHState reference = older;
    ASSERT_EQ(fresh.Advance(reference, 0.06), SPHFluid::Status::Ok); // computes them
    EXPECT_EQ(reference.Position, s.Position) << dimension << "D";
    EXPECT_EQ(reference.Velocity, s.Velocity) << dimension << "D";
    EXPECT_EQ(reference.Pressure, s.Pressure) << dimension << "D";
    SPHState again = older; // a holds the fields of the state at 0.06 now
    ASSERT_EQ(a.Advance(again, 0.06), SPHFluid::Status::Ok);
    EXPECT_EQ(again.Position, s.Position) << dimension << "D";
    EXPECT_EQ(again.Velocity, s.Velocity) << dimension << "D";
    EXPECT_EQ(again.Pressure, s.Pressure) << dimension << "D";
  }
}

TEST(SPHDivergenceFree, StiffnessIsPartOfTheState)
{
  // The warm-start stiffness changes the continuation, so a cache that dropped it would not reproduce the run.
  SPHParameters p = SmallScene(2);
  SPHFluid a;
  a.Setup(p);
  SPHState s = a.InitialState();
  ASSERT_EQ(a.Advance(s, 0.05), SPHFluid::Status::Ok);
  SPHState cold = s;
  std::fill(cold.DensityStiffness.begin(), cold.DensityStiffness.end(), 0.0);
  std::fill(cold.DivergenceStiffness.begin(), cold.DivergenceStiffness.end(), 0.0);
  ASSERT_EQ(a.Advance(s, 0.06), SPHFluid::Status::Ok);
  ASSERT_EQ(a.Advance(cold, 0.06), SPHFluid::Status::Ok);
  EXPECT_NE(cold.Position, s.Position);
}

TEST(SPHDivergenceFree, HostileSettings)
{
  { // invalid tolerances and iteration counts are refused
    SPHParameters p = SmallScene(2);
    SPHFluid fluid;
    p.DensityTolerance = -1.0;
    EXPECT_THROW(fluid.Setup(p), std::invalid_argument);
    p.DensityTolerance = std::nan("");
    EXPECT_THROW(fluid.Setup(p), std::invalid_argument);
    p.DensityTolerance = 0.01;
    p.DivergenceTolerance = -0.1;
    EXPECT_THROW(fluid.Setup(p), std::invalid_argument);
    p.DivergenceTolerance = 0.1;
    p.MaximumIterations = 0;
    EXPECT_THROW(fluid.Setup(p), std::invalid_argument);
  }
  { // tolerance 0: a warning, every solve runs MaximumIterations, counted as unconverged; a finite, contained state
    SPHParameters p = SmallScene(2);
    p.DensityTolerance = 0.0;
    p.MaximumIterations = 5;
    SPHFluid fluid;
    fluid.Setup(p);
    ASSERT_FALSE(fluid.Warnings().empty());
    EXPECT_NE(fluid.Warnings().front().find("tolerance of 0"), std::string::npos);
    SPHState s = fluid.InitialState();
    ASSERT_EQ(fluid.Advance(s, 0.02), SPHFluid::Status::Ok) << fluid.ErrorMessage();
    EXPECT_GT(fluid.UnconvergedSteps(), 0);
    EXPECT_EQ(s.Report.LastDensityIterations, 5);
    EXPECT_TRUE(SPHFluid::Statistics(s, fluid.ParticleMass()).Finite);
    EXPECT_TRUE(InsideDomain(s, p));
  }
  { // a huge fixed step: reduced to the velocity limit and counted, never NaN
    SPHParameters p = SmallScene(2);
    p.CFLNumber = 0.0;
    p.TimeStep = 10.0;
    SPHFluid fluid;
    fluid.Setup(p);
    SPHState s = fluid.InitialState();
    ASSERT_EQ(fluid.Advance(s, 0.1), SPHFluid::Status::Ok) << fluid.ErrorMessage();
    EXPECT_GT(fluid.ReducedSteps(), 0);
    EXPECT_TRUE(SPHFluid::Statistics(s, fluid.ParticleMass()).Finite);
    EXPECT_TRUE(InsideDomain(s, p));
  }
  { // a CFL number above DFSPH's limit of 1: a warning, and the steps of CFLNumber 1 (the same states); 1 itself,
    // above WCSPH's 0.4, is accepted without one and takes longer steps than 0.4
    SPHParameters p = SmallScene(2);
    p.TimeStep = 1.0;
    std::vector<SPHState> states;
    for (double lambda : { 10.0, 1.0, 0.4 })
    {
      p.CFLNumber = lambda;
      SPHFluid fluid;
      fluid.Setup(p);
      EXPECT_EQ(fluid.Warnings().empty(), lambda <= 1.0) << lambda;
      if (lambda > 1.0 && !fluid.Warnings().empty())
      {
        EXPECT_NE(fluid.Warnings().front().find("CFLNumber"), std::string::npos);
      }
      SPHState s = fluid.InitialState();
      ASSERT_EQ(fluid.Advance(s, 0.1), SPHFluid::Status::Ok) << fluid.ErrorMessage();
      EXPECT_TRUE(SPHFluid::Statistics(s, fluid.ParticleMass()).Finite);
      EXPECT_TRUE(InsideDomain(s, p));
      states.push_back(s);
    }
    EXPECT_EQ(states[0].Position, states[1].Position);
    EXPECT_EQ(states[0].Steps, states[1].Steps);
    EXPECT_LT(states[1].Steps, states[2].Steps);
  }
  { // one particle: it falls to the floor and stays in the container
    SPHParameters p = SmallScene(3);
    SetBox(p.FluidBounds, { 0.1, 0.11, 0.02, 0.03, 0.1, 0.11 });
    SPHFluid fluid;
    fluid.Setup(p);
    SPHState s = fluid.InitialState();
    ASSERT_EQ(s.Size(), 1);
    ASSERT_EQ(fluid.Advance(s, 0.5), SPHFluid::Status::Ok) << fluid.ErrorMessage();
    EXPECT_TRUE(SPHFluid::Statistics(s, fluid.ParticleMass()).Finite);
    EXPECT_TRUE(InsideDomain(s, p));
    EXPECT_LT(s.Position[2], 0.02); // on the floor
    EXPECT_GE(s.Pressure[0], 0.0);
  }
  { // no particles at all
    SPHParameters p = SmallScene(2);
    SetBox(p.FluidBounds, { 0.1, 0.1, 0.0, 0.0, 0.0, 0.1 });
    SPHFluid fluid;
    fluid.Setup(p);
    SPHState s = fluid.InitialState();
    EXPECT_EQ(s.Size(), 0);
    EXPECT_EQ(fluid.Advance(s, 0.1), SPHFluid::Status::Ok);
    EXPECT_EQ(s.Time, 0.1);
  }
  { // the CUDA back end is not used for DFSPH: the CPU runs it and says why
    SPHParameters p = SmallScene(2);
    SPHFluid fluid;
    fluid.Setup(p);
    EXPECT_NE(fluid.DeviceDeclineReason().find("DFSPH"), std::string::npos);
    fluid.SetBackend(meshfree::SPHBackend::CUDA);
    SPHState s = fluid.InitialState();
    ASSERT_EQ(fluid.Advance(s, 0.01), SPHFluid::Status::Ok);
    EXPECT_EQ(fluid.UsedBackend(), meshfree::SPHBackend::CPU);
    EXPECT_NE(fluid.BackendNote().find("DFSPH"), std::string::npos);
  }
}

// The 2D dam break of TestSPHDamBreak.cxx (same scene, front definition and Lethe's 0.175 time-origin correction)
// with DFSPH. Measured (a / dx = 40, 742 steps against WCSPH's ~3,000): corrected time origin within 7.3 % of
// Martin & Moyce at every tabulated 0.84 <= T <= 3.33 (+3.0 % at T = 0.84, +7.3 % at 1.19, from T = 2.32 on within
// 2.8 %); raw time origin within 10 % for T >= 2.32 (at most 9.7 %), and an early lead of 11-19 % (guarded at
// 25 %). The bounds (12.5 % corrected before T = 1.4, 10 % after) are the relaxed Jacobi solver's: it gave 765
// steps, +8.1 % at T = 0.84 and +10.7 % at T = 1.19 (corrected), at most 8.9 % (raw, T >= 2.32), an early lead of
// 12-22 %. (Before the wall coupling of SPHDivergenceFree.cxx was made consistent: 727 steps, at most 9.8 %,
// +11.7 % at T = 1.19.)
TEST(SPHDivergenceFree, DamBreakFrontAgainstMartinMoyce)
{
  using namespace sphscenes;
  DamBreakFronts fronts;
  ASSERT_NO_FATAL_FAILURE(RunMartinMoyceDamBreak(SPHSolver::DFSPH, fronts));
  const double gateEnd = 2.3; // the raw time origin meets 10 % from here on (TestSPHDamBreak.cxx)
  for (int k = 1; k < MartinMoyceSize; ++k)
  {
    const double T = MartinMoyceT[k];
    const double corrected = fronts.Corrected[k] / MartinMoyceZ[k] - 1.0;
    const double raw = fronts.Raw[k] / MartinMoyceZ[k] - 1.0;
    EXPECT_LE(std::fabs(corrected), T >= 1.4 ? 0.10 : 0.125) << "corrected time origin, T = " << T;
    if (T >= gateEnd)
    {
      EXPECT_LE(std::fabs(raw), 0.10) << "raw time origin, T = " << T;
    }
    else
    {
      EXPECT_GE(raw, 0.0) << "the raw early front should lead the experiment, T = " << T;
      EXPECT_LE(raw, 0.25) << "raw early lead grew beyond its measured level, T = " << T;
    }
  }
  EXPECT_EQ(fronts.Particles, 40 * 80);
}
