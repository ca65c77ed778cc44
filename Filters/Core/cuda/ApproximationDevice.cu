// The CUDA side of the device MLS (cuda/ApproximationDevice.h): one thread per evaluation point runs the k-nearest
// search, the weights and the fast path of Common/MLSFastPath.h, in the order of the CPU (Approximator::MLSShape and
// MLSPoint), so that the points it finishes carry the CPU's bits.
#include "cuda/ApproximationDevice.h"

#include "Common/KernelShapes.h"
#include "Common/MLSFastPath.h"
#include "cuda/Device.h"

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
constexpr int KMax = kMLSDeviceMaxNeighbors;
constexpr int CG = kMLSDeviceComponentGroup;
/// Points per kernel launch (and per output transfer): bounds the device output buffers.
constexpr std::int64_t ChunkPoints = std::int64_t(1) << 22;
/// Rings of cells searched around a query's cell before the query is left to the CPU (far from the cloud).
constexpr int MaxRings = 24;

/// The cloud on the device (plain pointers, passed by value).
struct CloudView
{
  const double* Points;   // 3 * n, cell-sorted
  const int* Ids;         // original index per sorted position
  const double* Values;   // n * Components, sorted order
  const long long* Cells; // 2 per cell
  long long Dims[3];
  double Origin[3];
  double Size;
  double InvSize;
  int Components;
};

struct FitConstants
{
  int K;
  double SupportFactor;
  int WeightKind;
  double WeightNormalization;
  double Axes[3][3];
  int Gradients;
  int FirstComponent; // this pass: components [FirstComponent, FirstComponent + GroupComponents)
  int GroupComponents;
};

struct ProbeView
{
  const double* Xyz; // explicit points of this chunk (null: image)
  ImageGeometry Image;
  long long First; // global index of the chunk's first point
  long long Count;
};

struct OutputView
{
  double* Values;          // Count * Components (chunk)
  double* Gradients;       // Count * Components * 3
  int* Neighbors;          // Count
  double* Conditions;      // Count
  unsigned char* NeedsCPU; // Count (OR-ed over the component passes)
};

__device__ inline bool Before(double d2, int id, double e2, int eid)
{
  return d2 < e2 || (d2 == e2 && id < eid);
}

/// The k nearest cloud points of x by (d2, original index), in bd2/bid/bpos sorted that way; returns how many
/// (fewer than k only when the cloud has fewer points), or -1 when the search gave up (too far from the cloud).
__device__ int KNearest(const CloudView& cloud, const double x[3], int k, double* bd2, int* bid, int* bpos)
{
  long long c[3];
  double reach = 0.0; // how many rings it takes to cover the grid from c
  double scale = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    double t = floor((x[a] - cloud.Origin[a]) * cloud.InvSize);
    const double top = static_cast<double>(cloud.Dims[a] - 1);
    t = t < 0.0 ? 0.0 : (t > top ? top : t);
    c[a] = static_cast<long long>(t);
    const double span = fmax(t, top - t);
    reach = fmax(reach, span);
    scale = fmax(scale, fabs(x[a]) + fabs(cloud.Origin[a]));
  }
  // Every point in a ring beyond r lies at least r cells away from x's cell (x inside it, or outside the grid
  // beyond it). The margin covers the rounding of the cell assignment and of x - Origin.
  const double margin = 1e-6 * cloud.Size + 1e-12 * scale;
  int found = 0;
  for (int r = 0;; ++r)
  {
    if (r > MaxRings)
    {
      return -1;
    }
    for (long long dz = -r; dz <= r; ++dz)
    {
      const long long cz = c[2] + dz;
      if (cz < 0 || cz >= cloud.Dims[2])
      {
        continue;
      }
      for (long long dy = -r; dy <= r; ++dy)
      {
        const long long cy = c[1] + dy;
        if (cy < 0 || cy >= cloud.Dims[1])
        {
          continue;
        }
        const bool face = dz == -r || dz == r || dy == -r || dy == r;
        const long long step = (face || r == 0) ? 1 : 2 * r;
        for (long long dx = -r; dx <= r; dx += step)
        {
          const long long cx = c[0] + dx;
          if (cx < 0 || cx >= cloud.Dims[0])
          {
            continue;
          }
          const long long cell = cx + cloud.Dims[0] * (cy + cloud.Dims[1] * cz);
          const long long begin = cloud.Cells[2 * cell], end = cloud.Cells[2 * cell + 1];
          for (long long p = begin; p < end; ++p)
          {
            const double* q = cloud.Points + 3 * p;
            // The grid's distance: (px - x)^2 + (py - y)^2 + (pz - z)^2 in that order.
            const double e0 = q[0] - x[0], e1 = q[1] - x[1], e2 = q[2] - x[2];
            const double d2 = e0 * e0 + e1 * e1 + e2 * e2;
            const int id = cloud.Ids[p];
            int j;
            if (found < k)
            {
              j = found++;
            }
            else if (Before(d2, id, bd2[k - 1], bid[k - 1]))
            {
              j = k - 1;
            }
            else
            {
              continue;
            }
            while (j > 0 && Before(d2, id, bd2[j - 1], bid[j - 1]))
            {
              bd2[j] = bd2[j - 1];
              bid[j] = bid[j - 1];
              bpos[j] = bpos[j - 1];
              --j;
            }
            bd2[j] = d2;
            bid[j] = id;
            bpos[j] = static_cast<int>(p);
          }
        }
      }
    }
    if (static_cast<double>(r) >= reach)
    {
      return found; // the whole grid has been visited
    }
    const double bound = static_cast<double>(r) * cloud.Size - margin;
    if (found == k && bound > 0.0 && bound * bound > bd2[k - 1])
    {
      return found;
    }
  }
}

/// One MLS point (see the file comment); returns whether it was finished here.
template <int D, int M>
__device__ bool MLSFast(
  const CloudView& cloud, const FitConstants& fc, const double x[3], long long t, const OutputView& out)
{
  constexpr int Q = mls::BasisSizeOf<D, M>::Value;
  constexpr int R = mls::MLSColumns<D, M>::Value;
  if (!(fabs(x[0]) <= 1.7976931348623157e308) || !(fabs(x[1]) <= 1.7976931348623157e308) ||
    !(fabs(x[2]) <= 1.7976931348623157e308))
  {
    return false;
  }
  double bd2[KMax];
  int bid[KMax];
  int bpos[KMax];
  const int found = KNearest(cloud, x, fc.K, bd2, bid, bpos);
  if (found <= 0)
  {
    return false;
  }
  const double h = fc.SupportFactor * sqrt(bd2[found - 1]);
  if (!(h > 0.0))
  {
    return false; // the CPU's all-coincident rule
  }
  // The CPU sums over the neighbours in index order.
  for (int j = 1; j < found; ++j)
  {
    const double d2 = bd2[j];
    const int id = bid[j], pos = bpos[j];
    int i = j;
    while (i > 0 && bid[i - 1] > id)
    {
      bd2[i] = bd2[i - 1];
      bid[i] = bid[i - 1];
      bpos[i] = bpos[i - 1];
      --i;
    }
    bd2[i] = d2;
    bid[i] = id;
    bpos[i] = pos;
  }
  const double invH = 1.0 / h;
  const double invH2 = invH * invH;
  int m = 0; // bd2 now holds the weights of the m neighbours kept, bpos their sorted positions
  for (int j = 0; j < found; ++j)
  {
    // The unit kernel's ValueSquared: q^2 = |d2 / h^2| x 1 (its inverse radius squared is exactly 1).
    const double w = PlainWeightSquared(fc.WeightKind, fc.WeightNormalization, fabs(bd2[j] * invH2));
    if (!(w > 0.0) || !(w <= 1.7976931348623157e308))
    {
      continue;
    }
    bd2[m] = w;
    bpos[m] = bpos[j];
    ++m;
  }
  if (m < Q)
  {
    return false;
  }
  auto local = [&](int j, double xi[3]) {
    const double* q = cloud.Points + 3 * static_cast<long long>(bpos[j]);
    const double dx[3] = { q[0] - x[0], q[1] - x[1], q[2] - x[2] };
    for (int a = 0; a < 3; ++a)
    {
      xi[a] = a < D ? (fc.Axes[a][0] * dx[0] + fc.Axes[a][1] * dx[1] + fc.Axes[a][2] * dx[2]) * invH : 0.0;
    }
  };
  double moment[Q * Q];
  MESHFREE_UNROLL
  for (int a = 0; a < Q * Q; ++a)
  {
    moment[a] = 0.0;
  }
  for (int j = 0; j < m; ++j)
  {
    double xi[3];
    local(j, xi);
    double p[Q];
    mls::EvaluateBasis<D, M>(xi, p);
    mls::AccumulateMoment<Q>(p, bd2[j], moment);
  }
  double s[Q];
  if (!mls::EquilibrateMoment<Q>(moment, s))
  {
    return false;
  }
  double y[Q * R];
  double condition = 0.0;
  const int r = fc.Gradients ? R : 1;
  if (!mls::CholeskyIdentitySolve<Q, R>(moment, s, r, y, condition))
  {
    return false;
  }
  // Apply the shape functions (Approximator::MLSPoint): values v_c = sum_j phi_j f_jc and gradient sums
  // sum_j dphi_aj f_jc, each accumulated from 0 in neighbour order.
  const int C = cloud.Components;
  double v[CG], g[3][CG];
  MESHFREE_UNROLL
  for (int c = 0; c < CG; ++c)
  {
    v[c] = 0.0;
    g[0][c] = g[1][c] = g[2][c] = 0.0;
  }
  for (int j = 0; j < m; ++j)
  {
    double xi[3];
    local(j, xi);
    double p[Q];
    mls::EvaluateBasis<D, M>(xi, p);
    const double w = bd2[j];
    const double phi = w * mls::ShapeDot<Q>(p, y);
    const double* f = cloud.Values + static_cast<long long>(bpos[j]) * C + fc.FirstComponent;
    MESHFREE_UNROLL
    for (int c = 0; c < CG; ++c)
    {
      if (c < fc.GroupComponents)
      {
        v[c] += phi * f[c];
      }
    }
    if (R > 1 && fc.Gradients)
    {
      MESHFREE_UNROLL
      for (int a = 0; a < D; ++a)
      {
        const double dphi = w * mls::ShapeDot<Q>(p, y + (1 + a) * Q);
        MESHFREE_UNROLL
        for (int c = 0; c < CG; ++c)
        {
          if (c < fc.GroupComponents)
          {
            g[a][c] += dphi * f[c];
          }
        }
      }
    }
  }
  bool finite = true;
  double grad[3][CG];
  MESHFREE_UNROLL
  for (int c = 0; c < CG; ++c)
  {
    finite = finite && fabs(v[c]) <= 1.7976931348623157e308;
    if (fc.Gradients)
    {
      // Frame.Unproject of the local gradient (sum / h per axis): g_i = 0 + sum_a A_ai l_a.
      double l[3] = { 0.0, 0.0, 0.0 };
      MESHFREE_UNROLL
      for (int a = 0; a < D; ++a)
      {
        l[a] = g[a][c] * invH;
      }
      MESHFREE_UNROLL
      for (int i = 0; i < 3; ++i)
      {
        grad[i][c] = 0.0;
      }
      MESHFREE_UNROLL
      for (int a = 0; a < D; ++a)
      {
        MESHFREE_UNROLL
        for (int i = 0; i < 3; ++i)
        {
          grad[i][c] += fc.Axes[a][i] * l[a];
        }
      }
      if (c < fc.GroupComponents)
      {
        finite = finite && fabs(grad[0][c]) <= 1.7976931348623157e308 && fabs(grad[1][c]) <= 1.7976931348623157e308 &&
          fabs(grad[2][c]) <= 1.7976931348623157e308;
      }
    }
  }
  if (!finite)
  {
    return false; // the CPU masks it, with its own bookkeeping
  }
  MESHFREE_UNROLL
  for (int c = 0; c < CG; ++c)
  {
    if (c < fc.GroupComponents)
    {
      const long long o = t * C + fc.FirstComponent + c;
      out.Values[o] = v[c];
      if (fc.Gradients)
      {
        out.Gradients[3 * o] = grad[0][c];
        out.Gradients[3 * o + 1] = grad[1][c];
        out.Gradients[3 * o + 2] = grad[2][c];
      }
    }
  }
  out.Neighbors[t] = m;
  out.Conditions[t] = condition;
  return true;
}

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
  if (!MLSFast<D, M>(cloud, fc, x, t, out))
  {
    out.NeedsCPU[t] = 1;
  }
}

bool Check(cudaError_t status, const char* what, std::string* error)
{
  if (status == cudaSuccess)
  {
    return true;
  }
  if (error)
  {
    *error = std::string(what) + ": " + cudaGetErrorName(status) + " (" + cudaGetErrorString(status) + ")";
  }
  return false;
}

/// A device allocation freed on destruction.
template <class T>
struct Buffer
{
  T* Data = nullptr;
  std::size_t Count = 0;
  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() { cudaFree(this->Data); }
  bool Allocate(std::size_t count, std::string* error)
  {
    if (this->Count >= count && this->Data)
    {
      return true;
    }
    cudaFree(this->Data);
    this->Data = nullptr;
    this->Count = 0;
    if (!Check(cudaMalloc(&this->Data, sizeof(T) * (count > 0 ? count : 1)), "cudaMalloc", error))
    {
      return false;
    }
    this->Count = count;
    return true;
  }
  bool Upload(const T* host, std::size_t count, std::string* error)
  {
    return this->Allocate(count, error) &&
      (count == 0 ||
        Check(cudaMemcpy(this->Data, host, sizeof(T) * count, cudaMemcpyHostToDevice), "cudaMemcpy", error));
  }
};

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
  Buffer<double> Points, Values, Probes, OutValues, OutGradients, OutConditions;
  Buffer<int> Ids, OutNeighbors;
  Buffer<long long> Cells;
  Buffer<unsigned char> OutNeedsCPU;
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
  if (!this->OutValues.Allocate(cs * std::max(C, 1), error) ||
    !this->OutGradients.Allocate(gradients ? 3 * cs * std::max(C, 1) : 1, error) ||
    !this->OutNeighbors.Allocate(cs, error) || !this->OutConditions.Allocate(cs, error) ||
    !this->OutNeedsCPU.Allocate(cs, error) || (xyz && !this->Probes.Allocate(3 * cs, error)))
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
