// The dam break of SPHERIC Test 2 (Kleefsman et al. 2005) without its box: where the front is and how the water
// gauges read, every output interval, to compare the flow's timing with the experiment and with other codes
// (bench_front.py does both; issue 25, results/spheric2.md "Why P1 arrives late").
//
// Scene (as Data/Scripts/spheric_test2.py builds it, less the box): tank [0, 3.22] x [0, 1] x [0, 1] m, the water
// column against the wall at x = 3.22, round(1.228 / dx) spacings long, 0.55 m deep (the lattice's rows: 0.56 m at
// dx = 0.02 and 0.04 m), water (Viscosity 1e-3 Pa s), the source's defaults otherwise. 2D: the x-z section.
//
// Printed at t = 0 and every --every seconds: t, the front (the smallest x of the particles whose centre lies within 2 dx of the
// floor and that have at least 3 fluid neighbours, less half a spacing: the water's leading edge on the floor), the
// distance it has run from the column's face, and the water depth at the gauges H2 (x = 0.992 m), the gauge at x =
// 1.488 m and H4 (x = 2.638 m, in the reservoir), y = 0.5 m in 3D: the particles' volume spread by a tent of
// half-width 2 dx in x (and y), as spheric_test2.py measures them.
//
// With --box 1 (3D) the box is there: the whole Test 2 scene as Data/Scripts/spheric_test2.py builds it, through the
// core alone (no VTK output, no probes: the solver's own cost, e.g. for a profile). --timestep sets the step cap
// (TimeStep), --gas-stiffness WCSPH's c0^2, --density-tolerance DFSPH's, --front 0 leaves the front out (its neighbour
// search). Each line also gives the CPU seconds of the process so far and, for DFSPH, the solves' iterations per
// step over the interval.
//
// Usage: BenchSPHFront [--dim 2|3] [--dx 0.01] [--solver dfsph|wcsph] [--end 0.45] [--every 0.005]
//                      [--artificial-viscosity A] [--smoothing-length H] [--cfl C] [--box 0|1] [--timestep T]
//                      [--gas-stiffness K] [--density-tolerance T] [--front 0|1]
#include "SPH/SPHFluid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

namespace
{
int Usage(const char* message)
{
  std::fprintf(stderr,
    "BenchSPHFront: %s\nusage: BenchSPHFront [--dim 2|3] [--dx 0.01] [--solver dfsph|wcsph] [--end 0.45] "
    "[--every 0.005] [--artificial-viscosity A] [--smoothing-length H] [--cfl C] [--box 0|1] [--timestep T] "
    "[--gas-stiffness K] [--density-tolerance T] [--front 0|1]\n",
    message);
  return 2;
}
}

int main(int argc, char** argv)
{
  using namespace meshfree;
  int dimension = 2;
  double dx = 0.01, end = 0.45, every = 0.005, artificial = -1.0, smoothing = 0.0, cfl = -1.0, timeStep = -1.0,
         stiffness = -1.0;
  double densityTolerance = -1.0;
  bool box = false, measureFront = true;
  std::string solver = "dfsph";
  for (int i = 1; i < argc; ++i)
  {
    const std::string key = argv[i];
    if (i + 1 >= argc)
    {
      return Usage(("missing value after " + key).c_str());
    }
    const char* value = argv[++i];
    if (key == "--dim")
    {
      dimension = std::atoi(value);
    }
    else if (key == "--dx")
    {
      dx = std::atof(value);
    }
    else if (key == "--solver")
    {
      solver = value;
    }
    else if (key == "--end")
    {
      end = std::atof(value);
    }
    else if (key == "--every")
    {
      every = std::atof(value);
    }
    else if (key == "--artificial-viscosity")
    {
      artificial = std::atof(value);
    }
    else if (key == "--smoothing-length")
    {
      smoothing = std::atof(value);
    }
    else if (key == "--cfl")
    {
      cfl = std::atof(value);
    }
    else if (key == "--box")
    {
      box = std::atoi(value) != 0;
    }
    else if (key == "--front")
    {
      measureFront = std::atoi(value) != 0;
    }
    else if (key == "--density-tolerance")
    {
      densityTolerance = std::atof(value);
    }
    else if (key == "--timestep")
    {
      timeStep = std::atof(value);
    }
    else if (key == "--gas-stiffness")
    {
      stiffness = std::atof(value);
    }
    else
    {
      return Usage(("unknown option " + key).c_str());
    }
  }
  if ((dimension != 2 && dimension != 3) || !(dx > 0.0) || !(end > 0.0) || !(every > 0.0) ||
    (solver != "dfsph" && solver != "wcsph") || (box && dimension != 3))
  {
    return Usage("invalid option value");
  }
  const double tank[6] = { 0.0, 3.22, 0.0, 1.0, 0.0, 1.0 };
  const double length = std::round(1.228 / dx) * dx;
  SPHParameters p;
  p.Dimension = dimension;
  p.ParticleSpacing = dx;
  p.Viscosity = 1e-3;
  p.Solver = solver == "dfsph" ? SPHSolver::DFSPH : SPHSolver::WCSPH;
  p.SmoothingLength = smoothing;
  if (artificial >= 0.0)
  {
    p.ArtificialViscosity = artificial;
  }
  if (cfl >= 0.0)
  {
    p.CFLNumber = cfl;
  }
  if (densityTolerance > 0.0)
  {
    p.DensityTolerance = densityTolerance;
  }
  if (timeStep > 0.0)
  {
    p.TimeStep = timeStep;
  }
  if (stiffness > 0.0)
  {
    p.GasStiffness = stiffness;
  }
  // Test 2's box, 0.161 x 0.403 x 0.161 m on the floor (spheric_test2.py's BOX): 12 triangles.
  std::vector<double> triangles;
  if (box)
  {
    const double b[6] = { 0.6635, 0.8245, 0.2955, 0.6985, 0.0, 0.161 };
    auto corner = [&](int k) { return std::vector<double>{ b[k & 1], b[2 + ((k >> 1) & 1)], b[4 + ((k >> 2) & 1)] }; };
    const int faces[6][4] = { { 0, 2, 6, 4 }, { 1, 5, 7, 3 }, { 0, 4, 5, 1 }, { 2, 3, 7, 6 }, { 0, 1, 3, 2 },
      { 4, 6, 7, 5 } };
    for (const auto& f : faces)
    {
      for (const int t : { 1, 2 }) // the quad (f0, f1, f2, f3) as (f0, f1, f2) and (f0, f2, f3)
      {
        for (const int k : { f[0], f[t], f[t + 1] })
        {
          const std::vector<double> c = corner(k);
          triangles.insert(triangles.end(), c.begin(), c.end());
        }
      }
    }
  }
  const double fluid[6] = { tank[1] - length, tank[1], 0.0, dimension == 2 ? 0.0 : 1.0, 0.0, 0.55 };
  for (int a = 0; a < 6; ++a)
  {
    p.FluidBounds[a] = fluid[a];
    p.DomainBounds[a] = dimension == 2 && (a == 2 || a == 3) ? 0.0 : tank[a];
  }
  SPHFluid fluidSolver;
  try
  {
    fluidSolver.Setup(p, triangles);
  }
  catch (const std::exception& e)
  {
    return Usage(e.what());
  }
  SPHState state = fluidSolver.InitialState();
  double top = 0.0;
  for (Index i = 0; i < state.Size(); ++i)
  {
    top = std::max(top, state.Position[3 * i + 2] + 0.5 * dx);
  }
  std::printf("# SPHERIC Test 2 %s the box: %dD, dx = %g m, %s, %lld particles, column %.4g x %.4g m, "
              "support %g m, artificial viscosity %g, CFL %g, TimeStep %g\n",
    box ? "with" : "without", dimension, dx, solver == "dfsph" ? "DFSPH" : "WCSPH",
    static_cast<long long>(state.Size()), length, top, fluidSolver.SupportRadius(), p.ArtificialViscosity,
    p.CFLNumber, p.TimeStep);
  std::printf("# t front_x front_run H2 H3(x=1.488) H4 steps wall_s cpu_s density_iterations_per_step "
              "divergence_iterations_per_step\n");
  const double gauges[3] = { 0.992, 1.488, 2.638 };
  const auto start = std::chrono::steady_clock::now();
  const long outputs = static_cast<long>(std::floor(end / every + 1e-9));
  for (long k = 0; k <= outputs; ++k) // k = 0: the initial state
  {
    const double t = k * every;
    if (k > 0 && fluidSolver.Advance(state, t) != SPHFluid::Status::Ok)
    {
      std::fprintf(stderr, "BenchSPHFront: %s\n", fluidSolver.ErrorMessage().c_str());
      return 1;
    }
    // The front needs the neighbour counts: a neighbour search of its own (--front 0 leaves it out, front nan).
    const std::vector<int> neighbours =
      measureFront ? fluidSolver.NeighborCounts(state) : std::vector<int>(state.Size(), 0);
    double front = tank[1];
    double depth[3] = { 0.0, 0.0, 0.0 };
    for (Index i = 0; i < state.Size(); ++i)
    {
      const double* x = &state.Position[3 * i];
      if (x[2] < 2.0 * dx && neighbours[i] >= 3)
      {
        front = std::min(front, x[0]);
      }
      const double wy = dimension == 3 ? 1.0 - std::fabs(x[1] - 0.5) / (2.0 * dx) : 1.0;
      for (int g = 0; g < 3; ++g)
      {
        const double wx = 1.0 - std::fabs(x[0] - gauges[g]) / (2.0 * dx);
        if (wx > 0.0 && wy > 0.0)
        {
          depth[g] += wx * wy;
        }
      }
    }
    for (double& d : depth)
    {
      d *= dimension == 3 ? dx / 4.0 : dx / 2.0; // the tents of a lattice's columns sum to 2 (x) and 4 (x, y)
    }
    front = measureFront ? front - 0.5 * dx : std::nan("");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double cpu = static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
    const double steps = static_cast<double>(std::max(state.Report.Steps, 1L));
    std::printf("%.4f %.4f %.4f %.4f %.4f %.4f %ld %.1f %.2f %.2f %.2f\n", state.Time, front, tank[1] - length - front,
      depth[0], depth[1], depth[2], state.Steps, wall, cpu, state.Report.DensityIterations / steps,
      state.Report.DivergenceIterations / steps);
    std::fflush(stdout);
  }
  return 0;
}
