// On a CUDA device: one force evaluation of the device SPH passes (cuda/SPHDevice.h: ComputeAccelerations, i.e.
// the grid rebuilt on the device, density, the wall dummies' pressure and the accelerations) gives the CPU's
// density, pressure and acceleration bit for bit, on disordered states: a dam break's particles moved off their
// lattice and given random velocities (so densities vary, the artificial viscosity acts, particles sit near the
// walls and surface tension is on), 2D and 3D, the three kernel pairs, Ideal and Tait. Exit 77 (skipped) without
// a usable device.
#include "Cuda/SPHBackendSupport.h"
#include "cuda/Device.h"
#include "cuda/SPHDevice.h"

#include <cstdio>
#include <random>
#include <string>

namespace
{
sphtest::Checks Check;

/// The initial state with every particle moved by up to 0.3 dx per axis and given a velocity of up to 0.5 m/s
/// per axis (y untouched in 2D).
meshfree::SPHState Disordered(meshfree::SPHFluid& fluid, int dimension, double dx, unsigned seed)
{
  meshfree::SPHState state = fluid.InitialState();
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> shift(-0.3 * dx, 0.3 * dx), speed(-0.5, 0.5);
  for (std::size_t k = 0; k < state.Position.size(); ++k)
  {
    if (dimension == 2 && k % 3 == 1)
    {
      continue;
    }
    state.Position[k] += shift(random);
    state.Velocity[k] = speed(random);
  }
  return state;
}
} // namespace

int main()
{
  if (!sphtest::DevicePresent())
  {
    return 77;
  }
  const meshfree::SPHKernelPair pairs[] = { meshfree::SPHKernelPair::Spiky, meshfree::SPHKernelPair::Poly6,
    meshfree::SPHKernelPair::Mueller };
  unsigned seed = 1;
  for (int dimension : { 2, 3 })
  {
    for (bool tait : { false, true })
    {
      for (meshfree::SPHKernelPair pair : pairs)
      {
        const double dx = dimension == 2 ? 0.0025 : 0.004;
        meshfree::SPHParameters p = sphtest::DamBreak(dimension, dx, tait, 2e-4);
        p.Kernels = pair;
        const std::string what = std::to_string(dimension) + "D " + (tait ? "Tait" : "Ideal") + " kernels " +
          std::to_string(static_cast<int>(pair));
        meshfree::SPHFluid fluid;
        fluid.Setup(p);
        meshfree::SPHState cpu = Disordered(fluid, dimension, dx, seed++);
        meshfree::SPHState device;
        meshfree::cuda::SPHDevice gpu;
        const std::vector<double>& walls = fluid.BoundaryPositions();
        std::string error;
        const bool ran = gpu.Setup(fluid.Constants(), walls.data(), static_cast<std::int64_t>(walls.size() / 3),
                           fluid.BoundaryNeighborGrid(), &error) &&
          gpu.Upload(cpu, &error) && gpu.ComputeAccelerations(&error) && gpu.Download(device, &error);
        Check(ran, what + ": device force evaluation (" + error + ")");
        fluid.UpdateDerived(cpu);
        if (ran)
        {
          device.Time = cpu.Time;
          device.Steps = cpu.Steps;
          Check(sphtest::SameState(cpu, device, what), what + ": density, pressure and acceleration bit for bit");
        }
        std::printf(
          "%s: %ld particles, %zu wall dummies\n", what.c_str(), static_cast<long>(cpu.Size()), walls.size() / 3);
      }
    }
  }
  return Check.Exit();
}
