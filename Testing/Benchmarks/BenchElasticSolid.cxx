// Speed of the meshless elastic solid (not a test): symplectic Euler phyxel-steps per second at ~100,000 phyxels
// (quadratic and linear gradient fits, with and without self-contact), and the cost and CG iterations of
// implicit steps. Usage: BenchElasticSolid [lattice edge, default 46 -> 97,336 phyxels] [steps, default 20]
// The thesis managed 299 phyxels at 7.3 steps/s (about 2,200 phyxel-steps/s, all-pairs neighbour search).
#include "Common/Parallel.h"
#include "Elastic/ElasticShapes.h"
#include "Elastic/ElasticSolid.h"

#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>

using namespace meshfree;

namespace
{
double Seconds(std::chrono::steady_clock::time_point a)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
}

ElasticSolid Build(int edge, int basis, bool contacts, double& setup)
{
  const double a = 0.01;
  const double bounds[6] = { 0, edge * a, 0, edge * a, 0, edge * a };
  std::vector<double> rest;
  SampleLattice(bounds, a, [](const double*) { return true; }, rest);
  ElasticSettings s;
  s.GradientBasis = basis;
  s.Contacts = contacts;
  s.VolumeStiffness = 1e4;
  s.Container = ElasticContainer::Box;
  const double box[6] = { -1, 1, -1, 1, 0, 2 };
  for (int i = 0; i < 6; ++i)
    s.ContainerBounds[i] = box[i];
  ElasticSolid solid;
  std::string msg;
  const auto t0 = std::chrono::steady_clock::now();
  if (!solid.Initialize(rest, 0.0, s, msg))
  {
    std::fprintf(stderr, "%s\n", msg.c_str());
    std::exit(1);
  }
  setup = Seconds(t0);
  const double v[3] = { 0.0, 0.0, -1.0 };
  solid.Reset(v);
  return solid;
}
} // namespace

int main(int argc, char* argv[])
{
  const int edge = argc > 1 ? std::atoi(argv[1]) : 46;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 20;
  std::printf("threads: %s\n", ParallelBackend());
  for (int basis : { 2, 1 })
  {
    for (bool contacts : { true, false })
    {
      double setup = 0.0;
      ElasticSolid solid = Build(edge, basis, contacts, setup);
      const double dt = solid.StableTimeStep();
      solid.StepSymplectic(dt); // warm-up
      const auto t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      for (int s = 0; s < steps; ++s)
        solid.StepSymplectic(dt);
      const double t = Seconds(t0);
      const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
      // CPU seconds are less sensitive than wall time to other processes sharing the cores.
      std::printf("symplectic  %-9s contacts %-3s: %7ld phyxels, setup %.2f s, %.2f ms/step, %.3g phyxel-steps/s "
                  "(%.3g per CPU-second), stable step %.3g s\n",
        basis == 2 ? "quadratic" : "linear", contacts ? "on" : "off", static_cast<long>(solid.Size()), setup,
        1e3 * t / steps, solid.Size() * steps / t, solid.Size() * steps / cpu, dt);
    }
  }
  for (int basis : { 2, 1 })
  {
    const int small = edge / 2;
    double setup = 0.0;
    ElasticSolid solid = Build(small, basis, false, setup);
    const double dt = 20.0 * solid.StableTimeStep();
    const int implicitSteps = 5;
    const auto t0 = std::chrono::steady_clock::now();
    long iterations = 0;
    for (int s = 0; s < implicitSteps; ++s)
    {
      double residual = 0.0;
      iterations += solid.StepImplicit(dt, residual);
    }
    const double t = Seconds(t0);
    std::printf("implicit    %-9s (dt = 20 x stable): %7ld phyxels, %.1f ms/step, %.1f CG iterations/step, "
                "%.3g phyxel-steps/s (x20 in simulated time)\n",
      basis == 2 ? "quadratic" : "linear", static_cast<long>(solid.Size()), 1e3 * t / implicitSteps,
      double(iterations) / implicitSteps, solid.Size() * implicitSteps / t);
  }
  return 0;
}
