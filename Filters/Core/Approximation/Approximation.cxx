// SPDX-License-Identifier: BSD-3-Clause
// Approximator: cloud set-up (exclusions, neighbour grid, intrinsic frame), the evaluation loop, LS/WLS and
// MLS. PU-WLS is in ApproximationPU.cxx, SPH in ApproximationSPH.cxx.
#include "Approximation/Approximation.h"
#include "Approximation/ApproximationPU.h"
#include "Approximation/ApproximationRBF.h"
#include "cuda/ApproximationDevice.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace meshfree
{

const char* ApproximationMethodName(ApproximationMethod method)
{
  switch (method)
  {
    case ApproximationMethod::LS:
      return "LS";
    case ApproximationMethod::WLS:
      return "WLS";
    case ApproximationMethod::MLS:
      return "MLS";
    case ApproximationMethod::PUWLS:
      return "PU-WLS";
    case ApproximationMethod::SPH:
      return "SPH";
    case ApproximationMethod::RBF:
      return "RBF";
    case ApproximationMethod::Auto:
      return "Auto";
  }
  return "Unknown";
}

bool ApproximationMethodFromName(const std::string& name, ApproximationMethod& out)
{
  std::string upper;
  for (char c : name)
  {
    if (c != '-' && c != '_' && c != ' ')
    {
      upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
  }
  const struct
  {
    const char* Name;
    ApproximationMethod Method;
  } table[] = { { "LS", ApproximationMethod::LS }, { "WLS", ApproximationMethod::WLS },
    { "MLS", ApproximationMethod::MLS }, { "PUWLS", ApproximationMethod::PUWLS },
    { "SPH", ApproximationMethod::SPH }, { "RBF", ApproximationMethod::RBF },
    { "AUTO", ApproximationMethod::Auto } };
  for (const auto& entry : table)
  {
    if (upper == entry.Name)
    {
      out = entry.Method;
      return true;
    }
  }
  return false;
}

Approximator::Approximator() = default;
Approximator::~Approximator() = default;

bool Approximator::SetOptions(const ApproximationOptions& options)
{
  if (options.Degree < 0 || options.Degree > kMaxBasisDegree)
  {
    this->Err = "BasisDegree must be 0..3";
    return false;
  }
  if (options.NeighborCount < 1)
  {
    this->Err = "NeighborCount must be at least 1";
    return false;
  }
  if (!(options.Epsilon > 0.0) || !std::isfinite(options.Epsilon))
  {
    this->Err = "Epsilon must be finite and > 0";
    return false;
  }
  if (!(options.SupportFactor >= 1.0) || !std::isfinite(options.SupportFactor))
  {
    this->Err = "SupportFactor must be >= 1";
    return false;
  }
  if (!(options.Smoothing >= 0.0) || !std::isfinite(options.Smoothing))
  {
    this->Err = "Smoothing must be finite and >= 0";
    return false;
  }
  if (options.TailDegree < 0 || options.TailDegree > kMaxBasisDegree)
  {
    this->Err = "the RBF tail's degree must be 0..3";
    return false;
  }
  if (options.RBFKernel != RBFKernelType::Polyharmonic && options.RBFKernel != RBFKernelType::WendlandC2)
  {
    this->Err = "unknown RBF kernel";
    return false;
  }
  if (options.RBFGlobalLimit < 0 || options.PatchPoints < 0)
  {
    this->Err = "RBFGlobalLimit and PatchPoints must be >= 0";
    return false;
  }
  this->Opts = options;
  this->Requested = options.Method;
  if (!(this->Opts.SupportRadius > 0.0) || !std::isfinite(this->Opts.SupportRadius))
  {
    this->Opts.SupportRadius = 0.0;
  }
  return true;
}

bool Approximator::SetCloud(const double* xyz, Index n, const double* values, int components, const double* volumes,
  const CloudPartition* partition)
{
  this->Rep = ApproximationReport();
  this->Err.clear();
  this->PU.reset();
  this->RBFFits.reset();
  this->DeviceUploaded = false;
  this->GlobalDegree = -1;
  n = std::max<Index>(n, 0);
  components = std::max(components, 0);
  this->NumberOfComponents = components;
  this->Coordinates.assign(xyz, xyz + 3 * n);
  this->Values.assign(values ? values : xyz, values ? values + static_cast<size_t>(n) * components : xyz);
  this->Volumes.clear();
  if (volumes)
  {
    this->Volumes.assign(volumes, volumes + n);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Index excluded = 0;
  // A point whose values (or volume) are not usable is removed from the geometry, so that no fit sees it.
  for (Index i = 0; i < n; ++i)
  {
    double* x = &this->Coordinates[3 * i];
    bool ok = std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
    for (int c = 0; ok && c < components; ++c)
    {
      ok = std::isfinite(this->Values[static_cast<size_t>(i) * components + c]);
    }
    if (ok && volumes)
    {
      ok = std::isfinite(volumes[i]) && volumes[i] > 0.0;
    }
    if (!ok)
    {
      x[0] = x[1] = x[2] = nan;
      ++excluded;
    }
  }
  this->Rep.CloudPoints = n;
  this->Rep.ExcludedPoints = excluded;
  const bool anyLocal = this->Points.Build(this->Coordinates.data(), n);
  this->Partitioned = partition != nullptr;
  this->SumParts = partition ? partition->Sum : nullptr;
  this->MaxParts = partition ? partition->Max : nullptr;
  this->PartitionLSSums.clear();

  // Intrinsic frame: PCA of the valid points (two-pass, centred, in double) - of every part's own points
  // when the cloud is distributed.
  const Index nv = this->Points.NumberOfValidPoints();
  const double* sp = this->Points.SortedPoints();
  const std::vector<Index>& order = this->Points.SortedOrder();
  std::vector<Index> ownPositions; // sorted positions of this part's own valid points (partitioned only)
  if (partition)
  {
    ownPositions.reserve(static_cast<size_t>(nv));
    for (Index p = 0; p < nv; ++p)
    {
      if (!partition->Owned || partition->Owned[order[p]])
      {
        ownPositions.push_back(p);
      }
    }
  }
  const Index ownCount = partition ? static_cast<Index>(ownPositions.size()) : nv;
  auto position = [&](Index i) { return partition ? ownPositions[i] : i; };
  double c[3] = { 0, 0, 0 };
  for (Index i = 0; i < ownCount; ++i)
  {
    const Index p = position(i);
    for (int a = 0; a < 3; ++a)
    {
      c[a] += sp[3 * p + a];
    }
  }
  double totals[4] = { c[0], c[1], c[2], static_cast<double>(ownCount) };
  this->PartitionSum(totals, 4);
  std::copy(totals, totals + 3, c);
  this->GlobalValidPoints = partition ? static_cast<Index>(totals[3]) : nv;
  const Index globalValid = this->GlobalValidPoints;
  if (partition)
  {
    // Bounds of every part's own valid points (as min = -max(-x) to need one combine).
    double b[6];
    for (int a = 0; a < 3; ++a)
    {
      b[2 * a] = b[2 * a + 1] = -std::numeric_limits<double>::infinity();
    }
    for (Index i = 0; i < ownCount; ++i)
    {
      const Index p = ownPositions[i];
      for (int a = 0; a < 3; ++a)
      {
        b[2 * a] = std::max(b[2 * a], -sp[3 * p + a]);
        b[2 * a + 1] = std::max(b[2 * a + 1], sp[3 * p + a]);
      }
    }
    this->PartitionMax(b, 6);
    for (int a = 0; a < 3; ++a)
    {
      this->Bounds[2 * a] = globalValid > 0 ? -b[2 * a] : 0.0;
      this->Bounds[2 * a + 1] = globalValid > 0 ? b[2 * a + 1] : 0.0;
    }
  }
  else
  {
    this->Points.GetBounds(this->Bounds);
  }
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  if (globalValid > 0)
  {
    for (double& v : c)
    {
      v /= static_cast<double>(globalValid);
    }
    for (Index i = 0; i < ownCount; ++i)
    {
      const Index p = position(i);
      const Eigen::Vector3d d(sp[3 * p] - c[0], sp[3 * p + 1] - c[1], sp[3 * p + 2] - c[2]);
      cov += d * d.transpose();
    }
    this->PartitionSum(cov.data(), 9);
    cov /= static_cast<double>(globalValid);
  }
  std::copy(c, c + 3, this->CloudCenter);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0); // ascending
  const double largest = lambda(2);
  // Rounding noise of the centred coordinates: identical points whose mean is not exactly representable
  // still give a tiny non-zero covariance (~(1e-16 |c|)^2), which is no extent at all.
  double magnitude = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    magnitude = std::max({ magnitude, std::fabs(c[a]), this->Bounds[2 * a + 1] - this->Bounds[2 * a] });
  }
  const double noise = (1e-14 * magnitude) * (1e-14 * magnitude);
  int dim = 0;
  for (int a = 0; a < 3; ++a)
  {
    // Standard deviation below ~3e-7 of the largest: flat. (The eigen-solver's absolute accuracy is about
    // 1e-16 of the largest eigenvalue, so a smaller variance ratio cannot be told from zero.)
    dim += (largest > noise && lambda(a) > 1e-13 * largest) ? 1 : 0;
  }
  // An axis without extent (relative to the largest, as NeighborGrid::IsAxisFlat): over every part's bounds
  // when distributed.
  const double maxExtent = std::max(
    { this->Bounds[1] - this->Bounds[0], this->Bounds[3] - this->Bounds[2], this->Bounds[5] - this->Bounds[4] });
  auto axisFlat = [&](int a) {
    return partition ? !(this->Bounds[2 * a + 1] - this->Bounds[2 * a] > 1e-10 * maxExtent)
                     : this->Points.IsAxisFlat(a);
  };
  this->Frame = LocalFrame();
  this->Frame.Dimension = dim;
  int axisAligned = 0;
  for (int a = 0; a < 3; ++a)
  {
    axisAligned += axisFlat(a) ? 0 : 1;
  }
  if (globalValid > 0 && axisAligned == dim)
  {
    // Flat along coordinate axes (or 3D): use the coordinate axes themselves, in order.
    int row = 0;
    for (int a = 0; a < 3; ++a)
    {
      if (!axisFlat(a))
      {
        for (int b = 0; b < 3; ++b)
        {
          this->Frame.Axes[row][b] = a == b ? 1.0 : 0.0;
        }
        ++row;
      }
    }
    for (int a = 0; a < 3 && row < 3; ++a)
    {
      if (axisFlat(a))
      {
        for (int b = 0; b < 3; ++b)
        {
          this->Frame.Axes[row][b] = a == b ? 1.0 : 0.0;
        }
        ++row;
      }
    }
  }
  else
  {
    for (int a = 0; a < 3; ++a)
    {
      const Eigen::Vector3d v = eig.eigenvectors().col(2 - a); // largest variance first
      for (int b = 0; b < 3; ++b)
      {
        this->Frame.Axes[a][b] = v(b);
      }
    }
  }
  this->Rep.CloudDimension = dim;
  // The PU-WLS lattice's box over every part (collective): PU-WLS and RBF-PU place their centres on it, and
  // Auto's estimate samples it, so for Auto it is needed before the choice.
  auto partitionBox = [&]() {
    double box[6] = { 0, 0, 0, 0, 0, 0 }; // -umin, umax per axis of the frame
    for (int a = 0; a < dim; ++a)
    {
      box[2 * a] = box[2 * a + 1] = -std::numeric_limits<double>::infinity();
    }
    double origin[3];
    this->PUOrigin(origin);
    for (Index p : ownPositions)
    {
      const double dx[3] = { sp[3 * p] - origin[0], sp[3 * p + 1] - origin[1], sp[3 * p + 2] - origin[2] };
      double u[3];
      this->Frame.Project<3>(dx, 1.0, u);
      for (int a = 0; a < dim; ++a)
      {
        box[2 * a] = std::max(box[2 * a], -u[a]);
        box[2 * a + 1] = std::max(box[2 * a + 1], u[a]);
      }
    }
    this->PartitionMax(box, 6);
    std::copy(box, box + 6, this->PartitionBox);
  };
  const bool boxDone = partition && this->Requested == ApproximationMethod::Auto;
  if (boxDone)
  {
    partitionBox();
  }
  this->ResolveAuto(globalValid, dim, partition);

  // What else is global, over every part of a distributed cloud (collective, in this order on every part).
  if (partition)
  {
    if (this->Opts.Method == ApproximationMethod::LS)
    {
      double largest2 = 0.0;
      for (Index p : ownPositions)
      {
        double d2 = 0.0;
        for (int a = 0; a < 3; ++a)
        {
          d2 += (sp[3 * p + a] - this->CloudCenter[a]) * (sp[3 * p + a] - this->CloudCenter[a]);
        }
        largest2 = std::max(largest2, d2);
      }
      this->PartitionMax(&largest2, 1);
      std::copy(this->CloudCenter, this->CloudCenter + 3, this->GlobalOrigin);
      this->GlobalInvScale = 1.0 / (largest2 > 0.0 ? std::sqrt(largest2) : 1.0);
      this->PartitionLSSums.resize(static_cast<size_t>(this->Opts.Degree) + 1);
      for (int degree = this->Opts.Degree; degree >= 0; --degree)
      {
        std::vector<double> sums = this->LSMomentSums(degree, &ownPositions);
        this->PartitionSum(sums.data(), static_cast<int>(sums.size()));
        this->PartitionLSSums[degree] = std::move(sums);
      }
    }
    else if (this->Opts.Method == ApproximationMethod::PUWLS ||
      (this->Opts.Method == ApproximationMethod::RBF &&
        (!this->RBFIsGlobal() || this->Opts.RBFKernel == RBFKernelType::WendlandC2)))
    {
      if (!boxDone)
      {
        partitionBox();
      }
    }
    else if (this->Opts.Method == ApproximationMethod::SPH && !this->Volumes.empty())
    {
      double largestVolume = 0.0;
      for (Index i = 0; i < n; ++i)
      {
        const double v = this->Volumes[i];
        largestVolume = std::isfinite(v) ? std::max(largestVolume, v) : largestVolume;
      }
      this->PartitionMax(&largestVolume, 1);
      this->PartitionLargestVolume = largestVolume;
    }
  }
  const bool any = partition ? globalValid > 0 && anyLocal : anyLocal;
  if (!any)
  {
    this->Err = "the cloud has no valid point";
    return false;
  }
  return true;
}

bool Approximator::Reach(const double* xyz, Index m, ApproximationReach& reach) const
{
  // The same K, radii and levels on every part, with or without points to evaluate (the exchange that
  // follows is collective); only the queries depend on the points.
  reach = ApproximationReach();
  m = std::max<Index>(m, 0);
  const int D = std::max(this->Frame.Dimension, 0);
  const double R = this->Opts.SupportRadius;
  const bool fixed = R > 0.0;
  auto queriesFrom = [&](const double* points, Index count) {
    reach.Queries.reserve(3 * static_cast<size_t>(count));
    for (Index i = 0; i < count; ++i)
    {
      const double* x = points + 3 * i;
      if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]))
      {
        reach.Queries.insert(reach.Queries.end(), x, x + 3);
      }
    }
  };
  // Each method's widest support after its fallbacks: twice the neighbours, or twice the radius.
  switch (this->Opts.Method)
  {
    case ApproximationMethod::LS:
      reach.Global = true;
      break;
    case ApproximationMethod::WLS:
    {
      double center[3];
      for (int a = 0; a < 3; ++a)
      {
        center[a] = this->Opts.CenterSet ? this->Opts.Center[a] : 0.5 * (this->Bounds[2 * a] + this->Bounds[2 * a + 1]);
      }
      queriesFrom(center, m > 0 ? 1 : 0);
      reach.K = fixed ? 0 : 2 * this->Opts.NeighborCount;
      reach.Radius = fixed ? 2.0 * R : 0.0;
      break;
    }
    case ApproximationMethod::MLS:
    {
      const int k = std::max(this->Opts.NeighborCount, kMinimumNeighborsPerTerm * BasisSize(D, this->Opts.Degree));
      queriesFrom(xyz, m);
      reach.K = fixed ? 0 : 2 * k;
      reach.Radius = fixed ? 2.0 * R : 0.0;
      break;
    }
    case ApproximationMethod::SPH:
      queriesFrom(xyz, m);
      reach.K = fixed ? 0 : 2 * this->Opts.NeighborCount;
      reach.Radius = fixed ? 2.0 * R : 0.0;
      // Volumes from the number density read each neighbour's own neighbourhood.
      reach.SecondLevel = this->Volumes.empty();
      reach.K2 = fixed ? 0 : this->Opts.NeighborCount;
      reach.Radius2 = fixed ? R : 0.0;
      break;
    case ApproximationMethod::RBF:
      if (this->RBFIsGlobal())
      {
        // The global fit reads every point: a radius beyond the cloud's diameter gathers them all (small N).
        queriesFrom(xyz, m);
        const double diameter = std::sqrt(std::pow(this->Bounds[1] - this->Bounds[0], 2) +
          std::pow(this->Bounds[3] - this->Bounds[2], 2) + std::pow(this->Bounds[5] - this->Bounds[4], 2));
        reach.Radius = std::isfinite(diameter) && diameter > 0.0 ? 2.0 * diameter : 1.0;
      }
      else
      {
        // RBF-PU: the patches' points, within max(SupportFactor R, SupportFactor d_k) of each node near the
        // evaluation points (fixed: the support radius); no widening.
        const double cover = this->PUCentresNear(xyz, m, reach.Queries);
        reach.K = fixed ? 0 : this->PatchSize();
        reach.Radius = fixed ? R : this->Opts.SupportFactor * cover * (1.0 + 1e-9);
        reach.KFactor = fixed ? 1.0 : this->Opts.SupportFactor * (1.0 + 1e-9);
      }
      break;
    case ApproximationMethod::Auto:
      break; // resolved by SetCloud
    case ApproximationMethod::PUWLS:
    {
      // The lattice centres within R of the evaluation points, each fitted over its neighbours within
      // max(SupportFactor d_k, SupportFactor R) (fixed: the support radius), doubled by the fallback.
      const double cover = this->PUCentresNear(xyz, m, reach.Queries);
      reach.K = fixed ? 0 : this->Opts.NeighborCount;
      reach.Radius = 2.0 * (fixed ? R : this->Opts.SupportFactor * cover);
      reach.KFactor = fixed ? 1.0 : 2.0 * this->Opts.SupportFactor;
      break;
    }
  }
  return m > 0;
}

void Approximator::PartitionSum(double* values, int n) const
{
  if (this->SumParts)
  {
    this->SumParts(values, n);
  }
}

void Approximator::PartitionMax(double* values, int n) const
{
  if (this->MaxParts)
  {
    this->MaxParts(values, n);
  }
}

void Approximator::SortById(FitScratch& s, size_t n)
{
  s.Candidates.resize(n);
  for (size_t j = 0; j < n; ++j)
  {
    s.Candidates[j] = { s.Dist2[j], s.Ids[j] };
  }
  std::sort(s.Candidates.begin(), s.Candidates.end(),
    [](const std::pair<double, Index>& a, const std::pair<double, Index>& b) { return a.second < b.second; });
  for (size_t j = 0; j < n; ++j)
  {
    s.Dist2[j] = s.Candidates[j].first;
    s.Ids[j] = s.Candidates[j].second;
  }
}

void Approximator::SortNeighbors(FitScratch& s, size_t n) const
{
  s.Candidates.resize(n);
  for (size_t j = 0; j < n; ++j)
  {
    s.Candidates[j] = { s.Dist2[j], s.Ids[j] };
  }
  std::sort(s.Candidates.begin(), s.Candidates.end(), this->NeighborOrder());
  for (size_t j = 0; j < n; ++j)
  {
    s.Dist2[j] = s.Candidates[j].first;
    s.Ids[j] = s.Candidates[j].second;
  }
}

int Approximator::Neighbors(const double x[3], int k, double radius, FitScratch& s, double& h) const
{
  if (radius > 0.0)
  {
    this->Points.FindWithinRadius(x, radius, s.Ids, &s.Dist2);
    h = radius;
    this->SortNeighbors(s, s.Ids.size());
    return static_cast<int>(s.Ids.size());
  }
  if (s.Ids.size() < static_cast<size_t>(k))
  {
    s.Ids.resize(k);
    s.Dist2.resize(k);
  }
  int found = -1;
  if (s.RadiusGuess > 0.0 && k < this->Points.NumberOfValidPoints())
  {
    // Consecutive evaluation points are usually close. The k nearest points of the previous query lie
    // within d_k(previous) + |x - previous| of x (triangle inequality), so one radius query of that size
    // holds at least k points, and a selection in the neighbour order gives exactly the k nearest - faster
    // than the shell search. A far jump makes the ball too big: then the exact k-nearest search is used.
    const double step = std::sqrt((x[0] - s.LastQuery[0]) * (x[0] - s.LastQuery[0]) +
      (x[1] - s.LastQuery[1]) * (x[1] - s.LastQuery[1]) + (x[2] - s.LastQuery[2]) * (x[2] - s.LastQuery[2]));
    double r = s.RadiusGuess + step;
    if (!(step < s.RadiusGuess))
    {
      r = -1.0;
    }
    for (int attempt = 0; attempt < 2 && found < 0 && r > 0.0; ++attempt, r *= 1.6)
    {
      this->Points.FindWithinRadius(x, r, s.Ids, &s.Dist2);
      const size_t count = s.Ids.size();
      if (count < static_cast<size_t>(k))
      {
        continue;
      }
      s.Candidates.resize(count);
      for (size_t j = 0; j < count; ++j)
      {
        s.Candidates[j] = { s.Dist2[j], s.Ids[j] };
      }
      // Afterwards the k-th nearest sits at k - 1 (also when count == k: the farthest goes last) and
      // the nearer ones before it, sorted as FindKNearest() gives them.
      std::nth_element(s.Candidates.begin(), s.Candidates.begin() + (k - 1), s.Candidates.end(), this->NeighborOrder());
      std::sort(s.Candidates.begin(), s.Candidates.begin() + (k - 1), this->NeighborOrder());
      for (int j = 0; j < k; ++j)
      {
        s.Dist2[j] = s.Candidates[j].first;
        s.Ids[j] = s.Candidates[j].second;
      }
      found = k;
    }
    if (found < 0 && s.Ids.size() < static_cast<size_t>(k))
    {
      s.Ids.resize(k);
      s.Dist2.resize(k);
    }
  }
  if (found < 0)
  {
    found = this->Points.FindKNearest(x, k, s.Ids.data(), s.Dist2.data());
  }
  const double farthest = found > 0 ? std::sqrt(s.Dist2[found - 1]) : 0.0; // the k-th nearest sits last
  if (found > 0)
  {
    s.RadiusGuess = farthest;
    std::copy(x, x + 3, s.LastQuery);
  }
  h = this->Opts.SupportFactor * farthest;
  if (!(h > 0.0))
  {
    // Every neighbour sits exactly at x: any positive support gives them all the weight W(0).
    const double diameter = std::sqrt(std::pow(this->Bounds[1] - this->Bounds[0], 2) +
      std::pow(this->Bounds[3] - this->Bounds[2], 2) + std::pow(this->Bounds[5] - this->Bounds[4], 2));
    h = diameter > 0.0 ? 1e-9 * diameter : 1.0;
  }
  return found;
}

void Approximator::Mask(const ApproximationOutput& out, Index i) const
{
  const int C = this->NumberOfComponents;
  if (out.Values)
  {
    std::fill(out.Values + i * C, out.Values + (i + 1) * C, this->Opts.NullValue);
  }
  if (out.Gradients)
  {
    std::fill(out.Gradients + 3 * i * C, out.Gradients + 3 * (i + 1) * C, 0.0);
  }
  if (out.Valid)
  {
    out.Valid[i] = 0;
  }
  if (out.NeighborCounts)
  {
    out.NeighborCounts[i] = 0.0;
  }
  if (out.Conditions)
  {
    out.Conditions[i] = 0.0;
  }
}

int Approximator::MLSShape(const double x[3], FitScratch& s, bool gradient, bool exact, double& h,
  PointResult& result) const
{
  result = PointResult{ false, 0, 0.0, false, false };
  const int D = this->Frame.Dimension;
  // A moving fit needs clearly more neighbours than basis terms: with k equal to the basis size (20 for
  // cubics in 3D, the default NeighborCount) each fit nearly interpolates and overshoots between points.
  int k = std::max(this->Opts.NeighborCount, kMinimumNeighborsPerTerm * BasisSize(std::max(D, 0), this->Opts.Degree));
  double radius = this->Opts.SupportRadius;
  const double* coords = this->Coordinates.data();
  for (int attempt = 0; attempt < 2; ++attempt)
  {
    const int n = this->Neighbors(x, k, radius, s, h);
    s.Reserve(static_cast<size_t>(std::max(n, 1)));
    const double invH = 1.0 / h;
    const double invH2 = invH * invH;
    int m = 0;
    for (int j = 0; j < n; ++j)
    {
      const double w = this->UnitKernel.ValueSquared(s.Dist2[j] * invH2);
      if (!(w > 0.0) || !std::isfinite(w))
      {
        continue;
      }
      const Index id = s.Ids[j];
      const double dx[3] = { coords[3 * id] - x[0], coords[3 * id + 1] - x[1], coords[3 * id + 2] - x[2] };
      double* xi = &s.Xi[3 * m];
      for (int a = 0; a < 3; ++a)
      {
        xi[a] = a < D ? (this->Frame.Axes[a][0] * dx[0] + this->Frame.Axes[a][1] * dx[1] +
                          this->Frame.Axes[a][2] * dx[2]) *
            invH
                      : 0.0;
      }
      if (gradient)
      {
        // d w / d xi_eval = grad W at r = x - x_j = -xi (the unit kernel has h = 1).
        const double r[3] = { -xi[0], -xi[1], -xi[2] };
        this->UnitKernel.Gradient(r, &s.WeightDerivatives[3 * m]);
      }
      s.Ids[m] = id;
      s.Weights[m] = w;
      ++m;
    }
    if (m > 0)
    {
      const int lowest = attempt == 0 ? this->Opts.Degree : 0;
      for (int degree = this->Opts.Degree; degree >= lowest; --degree)
      {
        double condition = 0.0;
        if (ComputeMLSShapeFunctions(D, degree, s.Xi.data(), s.Weights.data(), s.WeightDerivatives.data(), m,
              gradient, exact, s.Rows.data(), s.Phi.data(), s.DPhi.data(), condition))
        {
          result.Valid = true;
          result.Neighbors = m;
          result.Condition = condition;
          result.Widened = attempt > 0;
          result.Lowered = degree < this->Opts.Degree;
          return m;
        }
      }
    }
    // Widen the support: twice the neighbours, or twice the radius.
    k = 2 * k;
    radius = 2.0 * radius;
  }
  return 0;
}

Approximator::PointResult Approximator::MLSPoint(
  const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const
{
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const bool gradient = out.Gradients != nullptr;
  PointResult result;
  double h = 1.0;
  const int m = this->MLSShape(x, s, gradient, out.Conditions != nullptr, h, result);
  if (m <= 0)
  {
    return result;
  }
  // Apply the shape functions to every component (one pass over the neighbours).
  bool finite = true;
  if (out.Values)
  {
    double* v = out.Values + i * C;
    std::fill(v, v + C, 0.0);
    for (int j = 0; j < m; ++j)
    {
      const double* f = &this->Values[static_cast<size_t>(s.Ids[j]) * C];
      const double phi = s.Phi[j];
      for (int c = 0; c < C; ++c)
      {
        v[c] += phi * f[c];
      }
    }
    for (int c = 0; c < C; ++c)
    {
      finite = finite && std::isfinite(v[c]);
    }
  }
  if (gradient)
  {
    const double invH = 1.0 / h;
    double* g = out.Gradients + 3 * i * C;
    for (int c = 0; c < C; ++c)
    {
      double local[3] = { 0, 0, 0 };
      for (int a = 0; a < D; ++a)
      {
        const double* dphi = &s.DPhi[static_cast<size_t>(a) * m];
        double sum = 0.0;
        for (int j = 0; j < m; ++j)
        {
          sum += dphi[j] * this->Values[static_cast<size_t>(s.Ids[j]) * C + c];
        }
        local[a] = sum * invH;
      }
      this->Frame.Unproject(local, g + 3 * c);
      finite = finite && std::isfinite(g[3 * c]) && std::isfinite(g[3 * c + 1]) && std::isfinite(g[3 * c + 2]);
    }
  }
  result.Valid = result.Valid && finite;
  return result;
}

bool Approximator::ShapeFunctions(
  const double x[3], std::vector<Index>& ids, std::vector<double>& phi, FitScratch& scratch) const
{
  ids.clear();
  phi.clear();
  if (this->Points.NumberOfValidPoints() == 0 || !std::isfinite(x[0]) || !std::isfinite(x[1]) ||
    !std::isfinite(x[2]))
  {
    return false;
  }
  PointResult result;
  double h = 1.0;
  const int m = this->MLSShape(x, scratch, false, false, h, result);
  for (int j = 0; j < m; ++j)
  {
    if (!std::isfinite(scratch.Phi[j]))
    {
      ids.clear();
      phi.clear();
      return false;
    }
    ids.push_back(scratch.Ids[j]);
    phi.push_back(scratch.Phi[j]);
  }
  return m > 0;
}

} // namespace meshfree
