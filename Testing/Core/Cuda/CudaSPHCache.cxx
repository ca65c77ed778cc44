// On a CUDA device: the time cache (Common/StateCache.h, as the SPH Fluid source uses it) with the device back
// end. A 3D dam break is advanced output time by output time on the device, each reported state cached; every
// cached state equals the CPU's at the same time bit for bit, and restoring any cached state and advancing it
// again on the device reproduces the next cached state bit for bit (the device uploads what it is given and
// downloads only at the reported times). Exit 77 (skipped) without a usable device.
#include "Common/StateCache.h"
#include "Cuda/SPHBackendSupport.h"
#include "cuda/Device.h"

#include <cstdio>

int main()
{
  if (!sphtest::DevicePresent())
  {
    return 77;
  }
  sphtest::Checks check;
  const meshfree::SPHParameters p = sphtest::DamBreak(3, 0.005, false, 0.0); // CFL steps, ~10,000 particles
  meshfree::SPHFluid cpu, device;
  cpu.Setup(p);
  device.Setup(p);
  device.SetBackend(meshfree::SPHBackend::CUDA);
  meshfree::StateCache<meshfree::SPHState> cache(16);
  meshfree::SPHState onDevice = device.InitialState(), onCpu = cpu.InitialState();
  cache.Insert(0, onDevice);
  const double interval = 0.005;
  const long outputs = 6;
  for (long k = 1; k <= outputs; ++k)
  {
    check(device.Advance(onDevice, k * interval) == meshfree::SPHFluid::Status::Ok, "device advance");
    check(device.UsedBackend() == meshfree::SPHBackend::CUDA, "the device ran (" + device.BackendNote() + ")");
    cpu.Advance(onCpu, k * interval);
    check(sphtest::SameState(onCpu, onDevice, "t = " + std::to_string(k * interval)),
      "device state equals the CPU's at output " + std::to_string(k));
    cache.Insert(k, onDevice);
  }
  // Back and forth: restore each cached state (latest first, as when scrubbing back) and advance one interval.
  for (long k = outputs - 1; k >= 0; --k)
  {
    long found = -1;
    const meshfree::SPHState* cached = cache.FindAtOrBefore(k, found);
    check(cached != nullptr && found == k, "output " + std::to_string(k) + " cached");
    if (cached == nullptr)
    {
      continue;
    }
    meshfree::SPHState again = *cached;
    device.Advance(again, (k + 1) * interval);
    long next = -1;
    const meshfree::SPHState* expected = cache.FindAtOrBefore(k + 1, next);
    check(
      expected != nullptr && next == k + 1 && sphtest::SameState(*expected, again, "from output " + std::to_string(k)),
      "restored output " + std::to_string(k) + " advanced again equals output " + std::to_string(k + 1));
  }
  return check.Exit();
}
