// The CUDA side of the device MLS (cuda/ApproximationDevice.h): one thread per evaluation point runs the k-nearest
// search, the weights and the fast path of Common/MLSFastPath.h, in the order of the CPU (Approximator::MLSShape and
// MLSPoint), so that the points it finishes carry the CPU's bits.
#include "cuda/ApproximationDevice.h"

#include "Approximation/MLSDevicePoint.h"
#include "cuda/Device.h"
#include "cuda/DeviceBuffer.cuh"

#include <cuda_runtime.h>

#include <algorithm>
#include <vector>

namespace meshfree
{
namespace cuda
{
namespace
{
constexpr int BlockSize = 128;
using mls::CloudView;
using mls::FitConstants;
using mls::OutputView;
constexpr int CG = mls::kComponentGroup;
static_assert(mls::kMaxNeighbors == kMLSDeviceMaxNeighbors && CG == kMLSDeviceComponentGroup, "one set of limits");
/// Points per kernel launch (and per output transfer): bounds the device output buffers.
constexpr std::int64_t ChunkPoints = std::int64_t(1) << 22;

struct ProbeView
{
  const double* Xyz; // explicit points of this chunk (null: image)
  ImageGeometry Image;
  long long First; // global index of the chunk's first point
  long long Count;
};

template <int D, int M>
__global__ void MLSKernel(CloudView cloud, FitConstants fc, ProbeView probes, OutputView out)
{
  const long long t = static_cast<long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (t >= probes.Count)
  {
    return;
  }
  double x[3];
  if (probes.Xyz)
  {
    x[0] = probes.Xyz[3 * t];
    x[1] = probes.Xyz[3 * t + 1];
    x[2] = probes.Xyz[3 * t + 2];
  }
  else
  {
    ImagePoint(probes.Image, probes.First + t, x);
  }
  if (!mls::MLSFast<D, M>(cloud, fc, x, t, out))
  {
    out.NeedsCPU[t] = 1;
  }
}

template <int D, int M>
void Launch(
  long long count, const CloudView& cloud, const FitConstants& fc, const ProbeView& probes, const OutputView& out)
{
  const unsigned blocks = static_cast<unsigned>((count + BlockSize - 1) / BlockSize);
  MLSKernel<D, M><<<blocks, BlockSize>>>(cloud, fc, probes, out);
}
} // namespace

struct MLSDevice::State
{
  DeviceBuffer<double> Points, Values, Probes, OutValues, OutGradients, OutConditions;
  DeviceBuffer<int> Ids, OutNeighbors;
  DeviceBuffer<long long> Cells;
  DeviceBuffer<unsigned char> OutNeedsCPU;
  CloudView Cloud{};
  MLSDeviceOptions Options;
  bool Ready = false;
  double KernelSeconds = 0.0;
  std::vector<int> HostNeighbors;

  bool Run(const double* xyz, const ImageGeometry* image, std::int64_t m, const MLSDeviceOutput& out,
    std::string* error, bool (*progress)(void*, double), void* progressData);
};

MLSDevice::MLSDevice()
  : S(new State)
{
}

MLSDevice::~MLSDevice() = default;

double MLSDevice::LastKernelSeconds() const
{
  return this->S->KernelSeconds;
}

bool MLSDevice::Upload(const MLSDeviceCloud& cloud, const MLSDeviceOptions& options, std::string* error)
{
  State& s = *this->S;
  s.Ready = false;
  std::string reason;
  if (!Available(&reason))
  {
    if (error)
    {
      *error = reason;
    }
    return false;
  }
  if (!MLSDeviceSupports(options, error))
  {
    return false;
  }
  if (cloud.Points <= 0 || cloud.Points >= (std::int64_t(1) << 31) - 1)
  {
    if (error)
    {
      *error = "the device MLS needs 1 to 2^31 - 2 valid cloud points";
    }
    return false;
  }
  const std::int64_t cells = cloud.Dimensions[0] * cloud.Dimensions[1] * cloud.Dimensions[2];
  std::vector<int> ids(static_cast<std::size_t>(cloud.Points));
  for (std::int64_t p = 0; p < cloud.Points; ++p)
  {
    if (cloud.SortedOrder[p] < 0 || cloud.SortedOrder[p] > 2147483646)
    {
      if (error)
      {
        *error = "the device MLS needs point indices below 2^31 - 1";
      }
      return false;
    }
    ids[p] = static_cast<int>(cloud.SortedOrder[p]);
  }
  static_assert(sizeof(long long) == sizeof(std::int64_t), "cell ranges are 64-bit");
  const std::size_t nv = static_cast<std::size_t>(cloud.Points) * static_cast<std::size_t>(cloud.Components);
  if (!s.Points.Upload(cloud.SortedPoints, 3 * static_cast<std::size_t>(cloud.Points), error) ||
    !s.Ids.Upload(ids.data(), ids.size(), error) || !s.Values.Upload(cloud.SortedValues, nv, error) ||
    !s.Cells.Upload(reinterpret_cast<const long long*>(cloud.CellRanges), 2 * static_cast<std::size_t>(cells), error))
  {
    return false;
  }
  s.Cloud.Points = s.Points.Data;
  s.Cloud.Ids = s.Ids.Data;
  s.Cloud.Values = s.Values.Data;
  s.Cloud.Cells = s.Cells.Data;
  for (int a = 0; a < 3; ++a)
  {
    s.Cloud.Dims[a] = cloud.Dimensions[a];
    s.Cloud.Origin[a] = cloud.Origin[a];
  }
  s.Cloud.Size = cloud.CellSize;
  s.Cloud.InvSize = 1.0 / cloud.CellSize;
  s.Cloud.Components = cloud.Components;
  s.Options = options;
  s.Ready = true;
  return true;
}

bool MLSDevice::State::Run(const double* xyz, const ImageGeometry* image, std::int64_t m, const MLSDeviceOutput& out,
  std::string* error, bool (*progress)(void*, double), void* progressData)
{
  this->KernelSeconds = 0.0;
  if (!this->Ready)
  {
    if (error)
    {
      *error = "the device MLS has no cloud (Upload failed or was not called)";
    }
    return false;
  }
  if (m <= 0)
  {
    return true;
  }
  const int C = this->Cloud.Components;
  const std::int64_t chunk = std::min<std::int64_t>(m, ChunkPoints);
  const std::size_t cs = static_cast<std::size_t>(chunk);
  const bool gradients = this->Options.Gradients && out.Gradients;
  if (!this->OutValues.Reserve(cs * std::max(C, 1), error) ||
    !this->OutGradients.Reserve(gradients ? 3 * cs * std::max(C, 1) : 1, error) ||
    !this->OutNeighbors.Reserve(cs, error) || !this->OutConditions.Reserve(cs, error) ||
    !this->OutNeedsCPU.Reserve(cs, error) || (xyz && !this->Probes.Reserve(3 * cs, error)))
  {
    return false;
  }
  cudaEvent_t start, stop;
  if (!Check(cudaEventCreate(&start), "cudaEventCreate", error) ||
    !Check(cudaEventCreate(&stop), "cudaEventCreate", error))
  {
    return false;
  }
  struct Events
  {
    cudaEvent_t A, B;
    ~Events()
    {
      cudaEventDestroy(this->A);
      cudaEventDestroy(this->B);
    }
  } events{ start, stop };
  FitConstants fc{};
  fc.K = this->Options.Neighbors;
  fc.SupportFactor = this->Options.SupportFactor;
  fc.WeightKind = this->Options.WeightKind;
  fc.WeightNormalization = this->Options.WeightNormalization;
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      fc.Axes[a][b] = this->Options.Axes[a][b];
    }
  }
  fc.Gradients = gradients ? 1 : 0;
  OutputView ov{ this->OutValues.Data, this->OutGradients.Data, this->OutNeighbors.Data, this->OutConditions.Data,
    this->OutNeedsCPU.Data };
  this->HostNeighbors.resize(cs);
  for (std::int64_t first = 0; first < m; first += chunk)
  {
    if (progress && !progress(progressData, static_cast<double>(first) / static_cast<double>(m)))
    {
      if (error)
      {
        *error = "aborted";
      }
      return false;
    }
    const std::int64_t count = std::min(chunk, m - first);
    const std::size_t n = static_cast<std::size_t>(count);
    ProbeView pv{};
    pv.First = first;
    pv.Count = count;
    if (xyz)
    {
      if (!Check(cudaMemcpy(this->Probes.Data, xyz + 3 * first, sizeof(double) * 3 * n, cudaMemcpyHostToDevice),
            "cudaMemcpy", error))
      {
        return false;
      }
      pv.Xyz = this->Probes.Data;
    }
    else
    {
      pv.Image = *image;
    }
    if (!Check(cudaMemset(this->OutNeedsCPU.Data, 0, n), "cudaMemset", error) ||
      !Check(cudaEventRecord(start), "cudaEventRecord", error))
    {
      return false;
    }
    for (int c0 = 0; c0 < std::max(C, 1); c0 += CG)
    {
      fc.FirstComponent = c0;
      fc.GroupComponents = std::min(CG, C - c0);
      const int D = this->Options.Dimension, M = this->Options.Degree;
      if (D == 2 && M == 1)
      {
        Launch<2, 1>(count, this->Cloud, fc, pv, ov);
      }
      else if (D == 2 && M == 2)
      {
        Launch<2, 2>(count, this->Cloud, fc, pv, ov);
      }
      else if (D == 2 && M == 3)
      {
        Launch<2, 3>(count, this->Cloud, fc, pv, ov);
      }
      else if (D == 3 && M == 1)
      {
        Launch<3, 1>(count, this->Cloud, fc, pv, ov);
      }
      else
      {
        Launch<3, 2>(count, this->Cloud, fc, pv, ov);
      }
      if (!Check(cudaGetLastError(), "MLS kernel launch", error))
      {
        return false;
      }
    }
    float ms = 0.0f;
    if (!Check(cudaEventRecord(stop), "cudaEventRecord", error) ||
      !Check(cudaEventSynchronize(stop), "MLS kernel", error) ||
      !Check(cudaEventElapsedTime(&ms, start, stop), "cudaEventElapsedTime", error))
    {
      return false;
    }
    this->KernelSeconds += 1e-3 * ms;
    const std::size_t nc = n * static_cast<std::size_t>(C);
    const bool copied =
      Check(cudaMemcpy(out.NeedsCPU + first, this->OutNeedsCPU.Data, n, cudaMemcpyDeviceToHost), "cudaMemcpy", error) &&
      (!out.Values || nc == 0 ||
        Check(cudaMemcpy(out.Values + first * C, this->OutValues.Data, sizeof(double) * nc, cudaMemcpyDeviceToHost),
          "cudaMemcpy", error)) &&
      (!gradients || nc == 0 ||
        Check(cudaMemcpy(out.Gradients + 3 * first * C, this->OutGradients.Data, sizeof(double) * 3 * nc,
                cudaMemcpyDeviceToHost),
          "cudaMemcpy", error)) &&
      (!out.Conditions ||
        Check(cudaMemcpy(out.Conditions + first, this->OutConditions.Data, sizeof(double) * n, cudaMemcpyDeviceToHost),
          "cudaMemcpy", error)) &&
      (!out.NeighborCounts ||
        Check(cudaMemcpy(this->HostNeighbors.data(), this->OutNeighbors.Data, sizeof(int) * n, cudaMemcpyDeviceToHost),
          "cudaMemcpy", error));
    if (!copied)
    {
      return false;
    }
    if (out.NeighborCounts)
    {
      for (std::size_t i = 0; i < n; ++i)
      {
        out.NeighborCounts[first + static_cast<std::int64_t>(i)] = this->HostNeighbors[i];
      }
    }
  }
  if (progress)
  {
    progress(progressData, 1.0);
  }
  return true;
}

bool MLSDevice::Evaluate(const double* xyz, std::int64_t m, const MLSDeviceOutput& out, std::string* error,
  bool (*progress)(void*, double), void* progressData)
{
  return this->S->Run(xyz, nullptr, m, out, error, progress, progressData);
}

bool MLSDevice::EvaluateImage(const ImageGeometry& image, const MLSDeviceOutput& out, std::string* error,
  bool (*progress)(void*, double), void* progressData)
{
  return this->S->Run(nullptr, &image, image.NumberOfPoints(), out, error, progress, progressData);
}

} // namespace cuda
} // namespace meshfree
