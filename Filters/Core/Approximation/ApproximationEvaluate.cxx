// SPDX-License-Identifier: BSD-3-Clause
// Approximator: the parallel evaluation loop (blocks for progress and abort, per-thread scratch) and the
// global fits of LS (3.1-3.7) and WLS (3.8-3.15).
#include "Approximation/Approximation.h"
#include "Approximation/ApproximationPU.h"
#include "Approximation/ApproximationRBF.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace meshfree
{

bool Approximator::PrepareShapeFunctions()
{
  try
  {
    this->UnitKernel =
      Kernel(this->Opts.Weight, std::max(1, this->Frame.Dimension), 1.0, this->Opts.Epsilon);
  }
  catch (const std::exception& e)
  {
    this->Err = e.what();
    return false;
  }
  return this->GlobalValidPoints > 0; // a part of a distributed cloud may hold none itself
}

bool Approximator::PrepareGlobalFit()
{
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const Index nv = this->Points.NumberOfValidPoints();
  const double* sp = this->Points.SortedPoints();
  this->GlobalCoefficients.assign(static_cast<size_t>(kMaxBasisSize) * C, 0.0);
  this->GlobalDegree = -1;
  if (this->Opts.Method == ApproximationMethod::LS)
  {
    // Shift to the centroid, scale by the largest distance from it (3.19-3.20). A distributed cloud has both,
    // and the moment sums, from SetCloud (over every part).
    std::copy(this->CloudCenter, this->CloudCenter + 3, this->GlobalOrigin);
    if (!this->Partitioned)
    {
      double largest2 = 0.0;
      for (Index i = 0; i < nv; ++i)
      {
        double d2 = 0.0;
        for (int a = 0; a < 3; ++a)
        {
          d2 += (sp[3 * i + a] - this->GlobalOrigin[a]) * (sp[3 * i + a] - this->GlobalOrigin[a]);
        }
        largest2 = std::max(largest2, d2);
      }
      const double scale = largest2 > 0.0 ? std::sqrt(largest2) : 1.0;
      this->GlobalInvScale = 1.0 / scale;
    }
    const Index globalValid = this->GlobalValidPoints;
    for (int degree = this->Opts.Degree; degree >= 0; --degree)
    {
      const int q = BasisSize(D, D > 0 ? degree : 0);
      std::vector<double> sums;
      if (this->Partitioned && static_cast<size_t>(degree) < this->PartitionLSSums.size())
      {
        sums = this->PartitionLSSums[degree];
      }
      else
      {
        sums = this->LSMomentSums(degree, nullptr);
      }
      double* moment = sums.data(); // the moments, then the right-hand sides
      const double* rhs = sums.data() + static_cast<size_t>(q) * q;
      if (globalValid >= q &&
        SolveAccumulatedFit(
          D, degree, moment, rhs, C, this->Opts.Diagnostics, this->GlobalCoefficients.data(), this->GlobalCondition))
      {
        this->GlobalDegree = degree;
        this->GlobalNeighbors = static_cast<int>(std::min<Index>(globalValid, 2147483647));
        break;
      }
    }
    this->Rep.DegreeUsed = this->GlobalDegree;
    return this->GlobalDegree >= 0;
  }

  // WLS: one fit around the centre, with the MLS support rule and fallback chain.
  double center[3];
  for (int a = 0; a < 3; ++a)
  {
    center[a] = this->Opts.CenterSet ? this->Opts.Center[a]
                                     : 0.5 * (this->Bounds[2 * a] + this->Bounds[2 * a + 1]);
    if (!std::isfinite(center[a]))
    {
      this->Err = "the WLS centre is not finite";
      return false;
    }
  }
  std::copy(center, center + 3, this->GlobalOrigin);
  FitScratch s;
  int k = this->Opts.NeighborCount;
  double radius = this->Opts.SupportRadius;
  for (int attempt = 0; attempt < 2 && this->GlobalDegree < 0; ++attempt)
  {
    double h = 1.0;
    const int n = this->Neighbors(center, k, radius, s, h);
    s.Reserve(static_cast<size_t>(std::max(n, 1)));
    this->GlobalInvScale = 1.0 / h;
    const int m = this->GatherWeighted(center, n, h, s);
    this->GlobalDegree = this->FitDescending(
      attempt == 0 ? this->Opts.Degree : 0, s, m, this->GlobalCoefficients.data(), this->GlobalCondition);
    if (this->GlobalDegree >= 0)
    {
      this->GlobalNeighbors = m;
    }
    k *= 2;
    radius *= 2.0;
  }
  this->Rep.DegreeUsed = this->GlobalDegree;
  if (this->GlobalDegree < 0)
  {
    this->Err = "the WLS fit around the centre is degenerate even after the fallbacks";
  }
  return this->GlobalDegree >= 0;
}

std::vector<double> Approximator::LSMomentSums(int degree, const std::vector<Index>* positions) const
{
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const int q = BasisSize(D, D > 0 ? degree : 0);
  const double* sp = this->Points.SortedPoints();
  const Index* order = this->Points.SortedOrder().data();
  const Index count = positions ? static_cast<Index>(positions->size()) : this->Points.NumberOfValidPoints();
  // The sums over the points, in fixed blocks of points added in block order: the same whatever the number of
  // threads (one block, as serial as before, up to 65536 points).
  const size_t qq = static_cast<size_t>(q) * q, size = qq + static_cast<size_t>(q) * C;
  return ParallelReduce(
    count, 65536, std::vector<double>(size, 0.0),
    [&](Index begin, Index end) {
      std::vector<double> part(size, 0.0);
      constexpr Index block = 256;
      double xi[3 * block];
      Index ids[block];
      for (Index b = begin; b < end; b += block)
      {
        const Index e = std::min(end, b + block);
        for (Index i = b; i < e; ++i)
        {
          const Index p = positions ? (*positions)[i] : i;
          const double dx[3] = { sp[3 * p] - this->GlobalOrigin[0], sp[3 * p + 1] - this->GlobalOrigin[1],
            sp[3 * p + 2] - this->GlobalOrigin[2] };
          double* x = xi + 3 * (i - b);
          x[0] = x[1] = x[2] = 0.0;
          this->Frame.Project<3>(dx, this->GlobalInvScale, x);
          ids[i - b] = order[p];
        }
        AccumulateFit(
          D, degree, xi, nullptr, static_cast<int>(e - b), ids, this->Values.data(), C, part.data(), part.data() + qq);
      }
      return part;
    },
    [](std::vector<double> total, const std::vector<double>& part) {
      for (size_t a = 0; a < part.size(); ++a)
      {
        total[a] += part[a];
      }
      return total;
    });
}

Approximator::PointResult Approximator::GlobalPoint(const double x[3], const ApproximationOutput& out, Index i) const
{
  PointResult result{ true, this->GlobalNeighbors, this->GlobalCondition, false,
    this->GlobalDegree < this->Opts.Degree };
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const double dx[3] = { x[0] - this->GlobalOrigin[0], x[1] - this->GlobalOrigin[1], x[2] - this->GlobalOrigin[2] };
  double xi[3] = { 0, 0, 0 };
  this->Frame.Project<3>(dx, this->GlobalInvScale, xi);
  double local[3 * 64];
  std::vector<double> heapLocal;
  double* grad = nullptr;
  if (out.Gradients)
  {
    grad = local;
    if (3 * C > 3 * 64)
    {
      heapLocal.resize(3 * static_cast<size_t>(C));
      grad = heapLocal.data();
    }
  }
  std::vector<double> scratchValues;
  double* values = out.Values ? out.Values + i * C : nullptr;
  if (!values && C > 0)
  {
    scratchValues.resize(C);
    values = scratchValues.data();
  }
  EvaluateFit(D, this->GlobalDegree, xi, this->GlobalCoefficients.data(), C, values, grad);
  bool finite = true;
  for (int c = 0; c < C; ++c)
  {
    finite = finite && std::isfinite(values[c]);
    if (grad)
    {
      double l[3] = { 0, 0, 0 };
      for (int a = 0; a < D; ++a)
      {
        l[a] = grad[a * C + c] * this->GlobalInvScale;
      }
      double* g = out.Gradients + 3 * (i * C + c);
      this->Frame.Unproject(l, g);
      finite = finite && std::isfinite(g[0]) && std::isfinite(g[1]) && std::isfinite(g[2]);
    }
  }
  result.Valid = finite;
  return result;
}

bool Approximator::Evaluate(
  const double* xyz, Index m, const ApproximationOutput& out, const ProgressCallback& progress)
{
  return this->EvaluateAt(xyz, nullptr, m, out, progress);
}

bool Approximator::EvaluateImage(
  const ImageGeometry& image, const ApproximationOutput& out, const ProgressCallback& progress)
{
  const Index m = std::max<Index>(image.NumberOfPoints(), 0);
  if (this->Opts.Method != ApproximationMethod::PUWLS && this->Opts.Method != ApproximationMethod::RBF)
  {
    return this->EvaluateAt(nullptr, &image, m, out, progress);
  }
  // PU-WLS and RBF-PU place their centres from the evaluation points: they get them stored.
  std::vector<double> xyz(3 * static_cast<size_t>(m));
  for (Index i = 0; i < m; ++i)
  {
    ImagePoint(image, i, &xyz[3 * i]);
  }
  return this->EvaluateAt(xyz.data(), nullptr, m, out, progress);
}

bool Approximator::EvaluateAt(const double* xyz, const ImageGeometry* image, Index m, const ApproximationOutput& out,
  const ProgressCallback& progress)
{
  this->Rep.Evaluated = std::max<Index>(m, 0);
  this->Rep.Masked = this->Rep.Widened = this->Rep.DegreeLowered = 0;
  this->Rep.Aborted = false;
  this->Rep.Centers = 0;
  this->Rep.DegreeUsed = -1;
  this->Rep.DeviceEvaluated = this->Rep.DeviceToCPU = 0;
  this->Rep.DeviceKernelSeconds = 0.0;
  this->Rep.Backend = std::string("CPU (") + ParallelBackend() + ")";
  this->Rep.BackendNote.clear();
  this->Err.clear();
  if (m <= 0)
  {
    return true;
  }
  // The points the CPU loop evaluates: all (cpuPoints unused), or those the device left (cpuPoints).
  std::vector<Index> cpuPoints;
  bool listed = false;
  auto pointAt = [&](Index t) { return listed ? cpuPoints[static_cast<size_t>(t)] : t; };
  Index count = m;
  auto maskFrom = [&](Index begin) {
    for (Index t = begin; t < count; ++t)
    {
      this->Mask(out, pointAt(t));
    }
    this->Rep.Masked += count - begin;
  };
  if (!this->PrepareShapeFunctions())
  {
    if (this->Err.empty())
    {
      this->Err = "the cloud has no valid point";
    }
    maskFrom(0);
    return false;
  }
  bool ready = true;
  switch (this->Opts.Method)
  {
    case ApproximationMethod::LS:
    case ApproximationMethod::WLS:
      ready = this->PrepareGlobalFit();
      break;
    case ApproximationMethod::PUWLS:
      ready = this->PreparePU(xyz, m); // xyz is set (EvaluateImage)
      break;
    case ApproximationMethod::SPH:
      ready = this->PrepareSPHVolumes();
      break;
    case ApproximationMethod::RBF:
      ready = this->PrepareRBF(xyz, m); // xyz is set (EvaluateImage)
      break;
    case ApproximationMethod::Auto:
      ready = false; // SetCloud resolves it
      this->Err = "Auto was not resolved (no cloud)";
      break;
    case ApproximationMethod::MLS:
      break;
  }
  if (!ready)
  {
    if (this->Err.empty())
    {
      this->Err = "the fit could not be prepared";
    }
    maskFrom(0);
    return false;
  }
  if (this->Opts.Method != ApproximationMethod::MLS && this->Opts.Backend == ApproximationBackend::CUDA)
  {
    this->Rep.BackendNote = std::string("Backend CUDA: the CPU evaluated (only MLS has a device path, not ") +
      ApproximationMethodName(this->Opts.Method) + ")";
  }
  if (this->Opts.Method == ApproximationMethod::MLS)
  {
    switch (this->MLSOnDevice(xyz, image, m, out, progress, cpuPoints))
    {
      case DeviceRun::NotUsed:
        break;
      case DeviceRun::Ran:
        listed = true;
        count = static_cast<Index>(cpuPoints.size());
        break;
      case DeviceRun::Aborted:
        this->Rep.Aborted = true;
        maskFrom(0);
        this->Err = "aborted";
        return false;
    }
  }
  PerThread<FitScratch> scratch;
  struct Counts
  {
    Index Masked = 0;
    Index Widened = 0;
    Index Lowered = 0;
  };
  const Index blockSize = 16384;
  Index masked = 0, widened = 0, lowered = 0;
  for (Index begin = 0; begin < count; begin += blockSize)
  {
    if (progress && !progress(static_cast<double>(begin) / static_cast<double>(count)))
    {
      this->Rep.Aborted = true;
      maskFrom(begin);
      this->Rep.Masked += masked;
      this->Rep.Widened += widened;
      this->Rep.DegreeLowered += lowered;
      this->Err = "aborted";
      return false;
    }
    const Index end = std::min(count, begin + blockSize);
    // A global fit is cheap to evaluate: threads would cost more than they save on small blocks.
    const bool global =
      this->Opts.Method == ApproximationMethod::LS || this->Opts.Method == ApproximationMethod::WLS;
    const Counts counts = ParallelReduce(end - begin, global ? 1024 : 64, Counts(),
      [&](Index b0, Index b1) {
        FitScratch& s = scratch.Local();
        // Each block starts without the previous query's neighbour radius: the warm start may list the same
        // neighbours in another order, so a block's sums must not depend on which thread ran which block before.
        s.RadiusGuess = 0.0;
        Counts mine;
        for (Index t = begin + b0; t < begin + b1; ++t)
        {
          const Index i = pointAt(t);
          double probe[3];
          const double* x = probe;
          if (xyz)
          {
            x = xyz + 3 * i;
          }
          else
          {
            ImagePoint(*image, i, probe);
          }
          PointResult r{ false, 0, 0.0, false, false };
          if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]))
          {
            switch (this->Opts.Method)
            {
              case ApproximationMethod::LS:
              case ApproximationMethod::WLS:
                r = this->GlobalPoint(x, out, i);
                break;
              case ApproximationMethod::MLS:
                r = this->MLSPoint(x, s, out, i);
                break;
              case ApproximationMethod::PUWLS:
                r = this->PUPoint(x, s, out, i);
                break;
              case ApproximationMethod::SPH:
                r = this->SPHPoint(x, s, out, i);
                break;
              case ApproximationMethod::RBF:
                r = this->RBFPoint(x, s, out, i);
                break;
              case ApproximationMethod::Auto:
                break;
            }
          }
          if (!r.Valid)
          {
            this->Mask(out, i);
            ++mine.Masked;
            continue;
          }
          mine.Widened += r.Widened ? 1 : 0;
          mine.Lowered += r.Lowered ? 1 : 0;
          if (out.Valid)
          {
            out.Valid[i] = 1;
          }
          if (out.NeighborCounts)
          {
            out.NeighborCounts[i] = r.Neighbors;
          }
          if (out.Conditions)
          {
            out.Conditions[i] = std::isfinite(r.Condition) ? r.Condition : 0.0;
          }
        }
        return mine;
      },
      [](Counts a, const Counts& b) {
        a.Masked += b.Masked;
        a.Widened += b.Widened;
        a.Lowered += b.Lowered;
        return a;
      },
      global ? 8192 : 256);
    masked += counts.Masked;
    widened += counts.Widened;
    lowered += counts.Lowered;
  }
  if (progress)
  {
    progress(1.0);
  }
  this->Rep.Masked += masked;
  this->Rep.Widened += widened;
  this->Rep.DegreeLowered += lowered;
  return true;
}

int Approximator::GatherWeighted(const double x[3], int n, double h, FitScratch& s) const
{
  const int D = this->Frame.Dimension;
  const double invH = 1.0 / h;
  int m = 0;
  for (int j = 0; j < n; ++j)
  {
    const double w = this->UnitKernel.ValueSquared(s.Dist2[j] / (h * h));
    if (!(w > 0.0) || !std::isfinite(w))
    {
      continue;
    }
    const Index id = s.Ids[j];
    const double dx[3] = { this->Coordinates[3 * id] - x[0], this->Coordinates[3 * id + 1] - x[1],
      this->Coordinates[3 * id + 2] - x[2] };
    double* xi = &s.Xi[3 * m];
    this->Frame.Project<3>(dx, invH, xi);
    for (int a = D; a < 3; ++a)
    {
      xi[a] = 0.0;
    }
    s.Ids[m] = id;
    s.Weights[m] = w;
    ++m;
  }
  return m;
}

int Approximator::FitDescending(int lowest, const FitScratch& s, int m, double* coefficients, double& condition) const
{
  for (int degree = this->Opts.Degree; m > 0 && degree >= lowest; --degree)
  {
    if (ComputeFitCoefficients(this->Frame.Dimension, degree, s.Xi.data(), s.Weights.data(), m, s.Ids.data(),
          this->Values.data(), this->NumberOfComponents, this->Opts.Diagnostics, coefficients, condition))
    {
      return degree;
    }
  }
  return -1;
}

} // namespace meshfree
