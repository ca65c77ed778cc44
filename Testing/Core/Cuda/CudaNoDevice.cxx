// Without a usable CUDA device (or in a build without CUDA): Available() is false with a reason, the same reason
// on every call and from every thread (probed once), DeviceName() is empty and the launcher declines with that
// reason; the SPH fluid asked for the CUDA back end runs on the CPU, says why, and gives the CPU's states bit for
// bit. Exit 77 (skipped) where a device is usable.
#include "Cuda/SPHBackendSupport.h"
#include "cuda/Device.h"
#include "cuda/SPHDensity.h"
#include "cuda/SPHDevice.h"

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace
{
int failures = 0;

void Check(bool ok, const char* what)
{
  if (!ok)
  {
    std::printf("FAILED: %s\n", what);
    ++failures;
  }
}
}

int main()
{
  // First calls from several threads at once: the probe runs once and every caller gets the same answer.
  std::vector<std::string> reasons(8);
  std::vector<int> answers(8, -1);
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
  {
    threads.emplace_back([&, t] { answers[t] = meshfree::cuda::Available(&reasons[t]) ? 1 : 0; });
  }
  for (std::thread& thread : threads)
  {
    thread.join();
  }
  std::string reason;
  if (meshfree::cuda::Available(&reason))
  {
    std::printf("SKIPPED: a CUDA device is usable (%s)\n", meshfree::cuda::DeviceName().c_str());
    return 77;
  }
  std::printf("no CUDA device: %s\n", reason.c_str());
  Check(!reason.empty(), "Available() gives a reason");
  for (int t = 0; t < 8; ++t)
  {
    Check(answers[t] == 0 && reasons[t] == reason, "the same answer and reason from every thread");
  }
  std::string again;
  Check(!meshfree::cuda::Available(&again) && again == reason, "the answer is cached");
  Check(!meshfree::cuda::Available(), "Available() without a reason pointer");
  Check(meshfree::cuda::DeviceName().empty(), "no device name");

  const double x[3] = { 0.0, 0.0, 0.0 };
  const std::int64_t start[2] = { 0, 0 };
  meshfree::SPHDensityConstants c;
  c.H = 1.0;
  c.H2 = 1.0;
  c.Mass = 1.0;
  c.DensityNorm = 1.0;
  double rho = -1.0;
  std::string error;
  Check(!meshfree::cuda::SPHDensityFromHost(1, x, start, nullptr, 0, nullptr, start, nullptr, c, &rho, &error),
    "the launcher declines");
  Check(error == reason, "the launcher gives the same reason");
  Check(rho == -1.0, "the launcher leaves the output alone");

  // The SPH integrator: the device object declines with the reason; SPHFluid with Backend CUDA runs the CPU.
  meshfree::cuda::SPHDevice device;
  meshfree::NeighborGrid empty;
  error.clear();
  Check(!device.Setup(meshfree::SPHConstants(), nullptr, 0, empty, &error) && error == reason,
    "the device integrator declines with the reason");
  for (int dimension : { 2, 3 })
  {
    const meshfree::SPHParameters p = sphtest::DamBreak(dimension, dimension == 2 ? 0.005 : 0.01, false, 0.0);
    meshfree::SPHFluid cpu, fallback;
    cpu.Setup(p);
    fallback.Setup(p);
    fallback.SetBackend(meshfree::SPHBackend::CUDA);
    Check(fallback.DeviceDeclineReason() == reason, "SPHFluid::DeviceDeclineReason() is the reason");
    meshfree::SPHState a = cpu.InitialState(), b = fallback.InitialState();
    for (double t : { 0.01, 0.02 })
    {
      Check(cpu.Advance(a, t) == meshfree::SPHFluid::Status::Ok, "CPU advance");
      Check(fallback.Advance(b, t) == meshfree::SPHFluid::Status::Ok, "Backend CUDA advance");
      Check(fallback.UsedBackend() == meshfree::SPHBackend::CPU, "Backend CUDA ran on the CPU");
      Check(fallback.BackendNote() == reason, "BackendNote() says why");
      Check(cpu.UsedBackend() == meshfree::SPHBackend::CPU && cpu.BackendNote().empty(), "Backend CPU: no note");
      Check(sphtest::SameState(a, b, "fallback"), "Backend CUDA gives the CPU's state bit for bit");
    }
    Check(a.Steps > 20, "the runs took steps");
  }
  return failures == 0 ? 0 : 1;
}
