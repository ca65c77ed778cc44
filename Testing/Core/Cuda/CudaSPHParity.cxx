// On a CUDA device: the device SPH integrator (cuda/SPHDevice.h, SPHFluid::SetBackend(CUDA)) gives the CPU's
// states bit for bit: one step (so the accelerations of one force evaluation, with walls, viscosity, artificial
// viscosity and surface tension), and 100 steps (four Z-order permutations, the grid rebuilt every step), in 2D
// and 3D, Ideal and Tait equations of state (Tait's inverse is a Newton seventh root, no pow), fixed and CFL
// steps. A scene with obstacles is declined (the CPU runs, with a reason). Exit 77 (skipped) without a usable
// device.
#include "Cuda/SPHBackendSupport.h"
#include "cuda/Device.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace
{
sphtest::Checks Check;

/// The state after advancing to `target` on the CPU and on the device (Ok, and the device really ran).
void Run(const meshfree::SPHParameters& p, double target, meshfree::SPHState& cpu, meshfree::SPHState& device,
  const std::string& what)
{
  meshfree::SPHFluid a, b;
  a.Setup(p);
  b.Setup(p);
  b.SetBackend(meshfree::SPHBackend::CUDA);
  cpu = a.InitialState();
  device = b.InitialState();
  Check(a.Advance(cpu, target) == meshfree::SPHFluid::Status::Ok, what + ": CPU advance");
  Check(b.Advance(device, target) == meshfree::SPHFluid::Status::Ok, what + ": device advance " + b.ErrorMessage());
  Check(b.UsedBackend() == meshfree::SPHBackend::CUDA, what + ": the device ran (" + b.BackendNote() + ")");
  std::printf("%s: %ld particles, %ld steps\n", what.c_str(), static_cast<long>(cpu.Size()), cpu.Steps);
}

} // namespace

int main()
{
  if (!sphtest::DevicePresent())
  {
    return 77;
  }
  for (int dimension : { 2, 3 })
  {
    for (bool tait : { false, true })
    {
      const double dx = dimension == 2 ? 0.0025 : 0.004; // 2,400 and 14,250 particles
      // Below the stable step of either scene (1.6e-4 s in 2D, 2.6e-4 s in 3D), so that the fixed step is taken
      // as given: one step, then 100.
      const double dt = dimension == 2 ? 1e-4 : 2e-4;
      const meshfree::SPHParameters p = sphtest::DamBreak(dimension, dx, tait, dt);
      meshfree::SPHState cpu, device;
      const std::string name = std::to_string(dimension) + (tait ? "D Tait" : "D Ideal");
      Run(p, dt, cpu, device, name + " one step");
      Check(cpu.Steps == 1, name + " one step: one step taken");
      Check(sphtest::SameBits(cpu.Acceleration, device.Acceleration), name + " one step: accelerations bitwise");
      Check(sphtest::SameState(cpu, device, name + " one step"), name + " one step: state bitwise");
      Run(p, 100 * dt, cpu, device, name + " 100 steps");
      Check(cpu.Steps == 100, name + " 100 steps: 100 steps taken");
      Check(sphtest::SameState(cpu, device, name + " 100 steps"), name + " 100 steps: state bitwise");
      // The CFL step (maxima reduced on the device) chooses the same steps.
      const meshfree::SPHParameters adaptive = sphtest::DamBreak(dimension, dx, tait, 0.0);
      Run(adaptive, 0.01, cpu, device, name + " CFL to t = 0.01");
      Check(sphtest::SameState(cpu, device, name + " CFL"), name + " CFL: state bitwise");
    }
  }
  {
    // Obstacles: declined with a reason, the CPU's result.
    const double dt = 2e-4;
    meshfree::SPHParameters p = sphtest::DamBreak(3, 0.01, false, dt);
    const double A[3] = { 0.2, 0.02, 0.0 }, B[3] = { 0.25, 0.02, 0.0 }, C[3] = { 0.22, 0.04, 0.0 },
                 D[3] = { 0.22, 0.03, 0.05 }; // a tetrahedron: four triangles
    std::vector<double> box;
    for (const double* t : { A, B, C, A, B, D, B, C, D, C, A, D })
    {
      box.insert(box.end(), t, t + 3);
    }
    meshfree::SPHFluid a, b;
    a.Setup(p, box);
    b.Setup(p, box);
    b.SetBackend(meshfree::SPHBackend::CUDA);
    meshfree::SPHState cpu = a.InitialState(), device = b.InitialState();
    a.Advance(cpu, 10 * dt);
    b.Advance(device, 10 * dt);
    Check(b.UsedBackend() == meshfree::SPHBackend::CPU && !b.BackendNote().empty(), "obstacles: declined");
    std::printf("obstacles: %s\n", b.BackendNote().c_str());
    Check(sphtest::SameState(cpu, device, "obstacles"), "obstacles: the CPU's result");
  }
  return Check.Exit();
}
