// SPH fluid core, part 3: Advance() on the CUDA device (cuda/SPHDevice.h). The same loop as the CPU's in
// SPHFluid.cxx (step choice, kick-drift with the wall clamp, the periodic Z-order permutation, the force
// evaluation, the kick, progress and abort), with the particles on the device from the start of the call to its
// end; per step only the CFL maxima come back to the host.
#include "SPH/SPHFluid.h"

#include "cuda/Device.h"
#include "cuda/SPHDevice.h"

namespace meshfree
{

std::string SPHFluid::DeviceDeclineReason() const
{
  std::string reason;
  if (this->Params.Solver == SPHSolver::DFSPH)
  {
    return "the DFSPH solver runs on the CPU only"; // decided before the CUDA runtime is probed
  }
  if (!cuda::Available(&reason))
  {
    return reason;
  }
  if (!this->ObstaclePosition.empty())
  {
    return "the scene has obstacles, whose projection runs on the CPU only";
  }
  return std::string();
}

SPHFluid::Status SPHFluid::AdvanceOnDevice(
  SPHState& state, double targetTime, const ProgressFunction& progress, bool& declined)
{
  declined = false;
  std::string why = this->DeviceDeclineReason();
  if (why.empty() && state.Size() >= (Index(1) << 31))
  {
    why = "2^31 particles or more";
  }
  if (why.empty() && state.Size() == 0)
  {
    why = "no particles";
  }
  if (!why.empty())
  {
    declined = true;
    this->DeviceNote = why;
    return Status::Ok;
  }
  const long reducedBefore = this->ReducedStepCount;
  auto decline = [&](const std::string& failure) {
    declined = true;
    this->ReducedStepCount = reducedBefore; // the CPU redoes the call
    this->DeviceNote = "the CUDA device failed (" + failure + ")";
    return Status::Ok;
  };
  if (!this->Device)
  {
    auto device = std::make_shared<cuda::SPHDevice>();
    if (!device->Setup(this->Physics, this->BoundaryPosition.data(), this->BoundaryCount, this->BoundaryGrid, &why))
    {
      return decline(why);
    }
    this->Device = device;
  }
  cuda::SPHDevice& device = *this->Device;
  if (!device.Upload(state, &why))
  {
    return decline(why);
  }
  // The host state stays untouched until the end (a CUDA failure leaves it for the CPU to redo the call).
  const SPHParameters& p = this->Params;
  const double start = state.Time;
  double time = state.Time;
  long stepCount = state.Steps;
  long steps = 0;
  auto report = [&](Status status) {
    SPHState result; // downloaded aside: a failed copy leaves `state` for the CPU
    if (!device.Download(result, &why))
    {
      return decline(why);
    }
    result.Time = time;
    result.Steps = stepCount;
    state = std::move(result);
    return status;
  };
  while (time < targetTime)
  {
    SPHExtremes e;
    if (!device.Extremes(e, &why))
    {
      return decline(why);
    }
    double dt;
    bool last;
    if (!this->ChooseStep(e, time, targetTime, steps, dt, last))
    {
      return report(Status::Failed);
    }
    const double half = 0.5 * dt;
    if (!device.KickDrift(half, dt, &why) || (stepCount % p.ReorderInterval == 0 && !device.Reorder(&why)) ||
      !device.ComputeAccelerations(&why) || !device.Kick(half, &why))
    {
      return decline(why);
    }
    time = last ? targetTime : time + dt;
    ++stepCount;
    ++steps;
    if (progress && (steps & 15) == 0 && !progress((time - start) / (targetTime - start)))
    {
      return report(Status::Aborted);
    }
  }
  return report(Status::Ok);
}

} // namespace meshfree
