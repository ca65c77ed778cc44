// SPDX-License-Identifier: BSD-3-Clause
// Approximator: the choice of the back end (ApproximationBackend) and the hand-over between the device MLS
// (cuda/ApproximationDevice.h, the shared fast path of Common/MLSFastPath.h) and the CPU, which finishes the points
// the device leaves (robust path, fallbacks) with the same MLSPoint as always.
#include "Approximation/Approximation.h"
#include "Common/Parallel.h"
#include "cuda/ApproximationDevice.h"
#include "cuda/Device.h"

#include <algorithm>

namespace meshfree
{

Approximator::DeviceRun Approximator::MLSOnDevice(const double* xyz, const ImageGeometry* image, Index m,
  const ApproximationOutput& out, const ProgressCallback& progress, std::vector<Index>& cpuPoints)
{
  if (this->Opts.Backend == ApproximationBackend::CPU)
  {
    return DeviceRun::NotUsed;
  }
  const bool asked = this->Opts.Backend == ApproximationBackend::CUDA;
  const int D = this->Frame.Dimension;
  const int k =
    std::max(this->Opts.NeighborCount, kMinimumNeighborsPerTerm * BasisSize(std::max(D, 0), this->Opts.Degree));
  if (!asked && static_cast<double>(m) * static_cast<double>(k) < kAutoDeviceWork)
  {
    return DeviceRun::NotUsed; // Auto: too small to pay for the device
  }
  cuda::MLSDeviceOptions options;
  options.Dimension = D;
  options.Degree = this->Opts.Degree;
  options.Neighbors = k;
  options.SupportFactor = this->Opts.SupportFactor;
  options.WeightKind = static_cast<int>(this->Opts.Weight);
  options.WeightNormalization = this->UnitKernel.NormalizationFactor();
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      options.Axes[a][b] = this->Frame.Axes[a][b];
    }
  }
  options.Gradients = out.Gradients != nullptr;
  std::string why;
  if (!cuda::Available(&why))
  {
    // why: no device, no driver, or a build without CUDA
  }
  else if (this->Opts.SupportRadius > 0.0)
  {
    why = "a fixed SupportRadius runs on the CPU (the device MLS takes the k nearest)";
  }
  else if (out.Conditions)
  {
    why = "exact condition numbers (Diagnostics) need the CPU's eigen-decomposition";
  }
  else if (cuda::MLSDeviceSupports(options, &why))
  {
    // Upload the cloud once per SetCloud and options (re-upload when they change).
    const std::vector<double> key = { static_cast<double>(options.Degree), static_cast<double>(options.Neighbors),
      options.SupportFactor, static_cast<double>(options.WeightKind), options.WeightNormalization,
      options.Gradients ? 1.0 : 0.0 };
    if (!this->Device)
    {
      this->Device.reset(new cuda::MLSDevice);
    }
    if (!this->DeviceUploaded || key != this->DeviceKey)
    {
      const Index nv = this->Points.NumberOfValidPoints();
      const int C = this->NumberOfComponents;
      const std::vector<Index>& order = this->Points.SortedOrder();
      std::vector<double> sortedValues(static_cast<size_t>(nv) * C);
      for (Index p = 0; p < nv; ++p)
      {
        std::copy(
          this->Values.begin() + order[p] * C, this->Values.begin() + (order[p] + 1) * C, sortedValues.begin() + p * C);
      }
      cuda::MLSDeviceCloud cloud;
      cloud.Points = nv;
      cloud.SortedPoints = this->Points.SortedPoints();
      cloud.SortedOrder = order.data();
      cloud.SortedValues = sortedValues.data();
      cloud.Components = C;
      static_assert(sizeof(NeighborGrid::CellRange) == 2 * sizeof(std::int64_t), "cell ranges are two indices");
      cloud.CellRanges = reinterpret_cast<const std::int64_t*>(this->Points.Cells());
      Index dims[3];
      this->Points.GetGridDimensions(dims);
      double bounds[6];
      this->Points.GetBounds(bounds);
      for (int a = 0; a < 3; ++a)
      {
        cloud.Dimensions[a] = dims[a];
        cloud.Origin[a] = bounds[2 * a];
      }
      cloud.CellSize = this->Points.CellSize();
      this->DeviceUploaded = this->Device->Upload(cloud, options, &why);
      this->DeviceKey = this->DeviceUploaded ? key : std::vector<double>();
    }
    if (this->DeviceUploaded)
    {
      std::vector<unsigned char> needsCPU(static_cast<size_t>(m), 1);
      cuda::MLSDeviceOutput dout;
      dout.Values = out.Values;
      dout.Gradients = out.Gradients;
      dout.NeighborCounts = out.NeighborCounts;
      dout.NeedsCPU = needsCPU.data();
      // Progress: the device's chunks take the first half, the CPU's leftovers the rest.
      struct Relay
      {
        const ProgressCallback* Progress;
        static bool Call(void* data, double fraction)
        {
          const Relay* r = static_cast<const Relay*>(data);
          return !*r->Progress || (*r->Progress)(0.5 * fraction);
        }
      } relay{ &progress };
      const bool ran = image ? this->Device->EvaluateImage(*image, dout, &why, &Relay::Call, &relay)
                             : this->Device->Evaluate(xyz, m, dout, &why, &Relay::Call, &relay);
      if (ran)
      {
        cpuPoints.clear();
        for (Index i = 0; i < m; ++i)
        {
          if (needsCPU[i])
          {
            cpuPoints.push_back(i);
          }
          else if (out.Valid)
          {
            out.Valid[i] = 1;
          }
        }
        this->Rep.DeviceToCPU = static_cast<Index>(cpuPoints.size());
        this->Rep.DeviceEvaluated = m - this->Rep.DeviceToCPU;
        this->Rep.DeviceKernelSeconds = this->Device->LastKernelSeconds();
        this->Rep.Backend = "CUDA (" + cuda::DeviceName() + ")";
        return DeviceRun::Ran;
      }
      if (why == "aborted")
      {
        return DeviceRun::Aborted;
      }
    }
  }
  this->Rep.BackendNote = std::string(asked ? "Backend CUDA" : "Backend Auto") + ": the CPU evaluated (" + why + ")";
  return DeviceRun::NotUsed;
}

} // namespace meshfree
