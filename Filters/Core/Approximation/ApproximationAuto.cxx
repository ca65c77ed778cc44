// SPDX-License-Identifier: BSD-3-Clause
// Approximator: Auto's choice of a method (ResolveAuto) and the error estimates it rests on - leave-one-out
// residuals of the whole cloud for small 2D clouds (AutoLeaveOneOut, LeaveOneOutRBF, LeaveOneOutPU) and of
// sampled local fits for 3D clouds (AutoSampledLeaveOneOut).
#include "Approximation/ApproximationRBF.h"
#include "Approximation/ApproximationPU.h"

#include "Common/PolynomialBasis.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace meshfree
{
namespace
{
/// Auto's estimates: the rms over `count` components of the relative mean squares summed in sums (spline,
/// PU-WLS); false when there is none or one is not finite.
bool RmsOverComponents(const double sums[2], int count, double errors[2])
{
  if (count == 0)
  {
    return false;
  }
  errors[0] = std::sqrt(sums[0] / count);
  errors[1] = std::sqrt(sums[1] / count);
  return std::isfinite(errors[0]) && std::isfinite(errors[1]);
}
} // namespace

void Approximator::ResolveAuto(Index globalValid, int dimension, const CloudPartition* partition)
{
  this->Opts.Method = this->Requested;
  char text[400];
  if (this->Requested == ApproximationMethod::Auto)
  {
    // Measured with Testing/Benchmarks/run_benchmarks.py (Renka & Brown's ten functions in 2D, a 3D Franke field,
    // N = 100 to 10,000; README, "Run time against error"). 2D: at N = 100 the global thin-plate spline is the
    // most accurate MeshFree setting on 8 of 10 functions and PU-WLS of degree 3 on the other two (F6, a
    // sphere's cap, by 8.7x; F7, oscillating, by 1.1x), at a quarter of the spline's time; from N = 300 on
    // PU-WLS of degree 3 is within 2x of the best error at a fraction of the time on every function (degree 3
    // converges like h^4, the thin-plate spline like h^2). Up to kAutoRBFPoints2D points, where neither wins
    // everywhere, the leave-one-out errors of both decide (cheap there: a dense system of <= 200 rows and ~50
    // small patch fits); the spline must beat PU-WLS's estimate by kAutoRBFMargin to pay for its time.
    // 3D: r^3 (global up to RBFGlobalLimit, RBF-PU of 160-point patches above) is the most accurate MeshFree
    // setting on most of the ten trivariate functions, PU-WLS of degree 3 over 40 neighbours on others (F6 at
    // every N by 2.6-8.8x, F4 from 3,000 on) at a fraction of the time: the leave-one-out errors of both at
    // kAutoSamples sampled neighbourhoods decide (AutoSampledLeaveOneOut: a few ms), with the same margin
    // for the spline. 1D: r^3 (global, RBF-PU above RBFGlobalLimit). With
    // smoothing (noisy data): the smoothing spline up to RBFGlobalLimit, a moving least-squares fit (which does
    // not interpolate) above.
    const bool smoothing = this->Opts.Smoothing > 0.0;
    this->Opts.RBFKernel = RBFKernelType::Polyharmonic; // the kernel measured
    const Index small2D = std::min<Index>(kAutoRBFPoints2D, this->Opts.RBFGlobalLimit);
    const int puDegree = std::max(this->Opts.Degree, 3);
    if (dimension == 0)
    {
      this->Opts.Method = ApproximationMethod::RBF;
      std::snprintf(text, sizeof(text), "every valid point at one position: their mean value");
    }
    else if (smoothing)
    {
      const bool rbf = globalValid <= this->Opts.RBFGlobalLimit;
      this->Opts.Method = rbf ? ApproximationMethod::RBF : ApproximationMethod::MLS;
      std::snprintf(text, sizeof(text),
        rbf ? "Smoothing > 0 (noisy data), %lld valid points <= RBFGlobalLimit %lld: the global smoothing spline"
            : "Smoothing > 0 (noisy data), %lld valid points > RBFGlobalLimit %lld: MLS, a least-squares fit that "
              "averages the noise",
        static_cast<long long>(globalValid), static_cast<long long>(this->Opts.RBFGlobalLimit));
    }
    else if (dimension == 2 && globalValid > small2D)
    {
      this->Opts.Method = ApproximationMethod::PUWLS;
      this->Opts.Degree = puDegree;
      std::snprintf(text, sizeof(text),
        "2D cloud of %lld valid points > %lld: PU-WLS of degree %d, as accurate as the thin-plate spline or more "
        "(it converges faster) at a fraction of its time",
        static_cast<long long>(globalValid), static_cast<long long>(small2D), this->Opts.Degree);
    }
    else if (dimension == 2)
    {
      double loo[2] = { 0.0, 0.0 };
      const bool estimated = this->AutoLeaveOneOut(partition, loo);
      const bool spline = !estimated || loo[0] * kAutoRBFMargin < loo[1];
      this->Opts.Method = spline ? ApproximationMethod::RBF : ApproximationMethod::PUWLS;
      if (!spline)
      {
        this->Opts.Degree = puDegree;
      }
      if (!estimated)
      {
        std::snprintf(text, sizeof(text),
          "2D cloud of %lld valid points <= %lld: the global thin-plate spline (no leave-one-out estimate: %s)",
          static_cast<long long>(globalValid), static_cast<long long>(small2D),
          this->NumberOfComponents == 0 ? "no values" : "not defined for this cloud");
      }
      else
      {
        std::snprintf(text, sizeof(text),
          "2D cloud of %lld valid points <= %lld: leave-one-out error (rms / std of the values) of the thin-plate "
          "spline %.3g, of PU-WLS degree %d %.3g: %s",
          static_cast<long long>(globalValid), static_cast<long long>(small2D), loo[0], puDegree, loo[1],
          spline ? "the spline (more accurate by more than its margin of 1.25x, which pays for its time)"
                 : "PU-WLS (as accurate within the margin of 1.25x, at a fraction of the spline's time)");
      }
    }
    else if (dimension == 3)
    {
      const bool global = globalValid <= this->Opts.RBFGlobalLimit;
      const int puPoints = std::max(this->Opts.NeighborCount, kAutoPUPoints3D);
      // The estimate's spline patch: RBF-PU's, at most half a small cloud (whose global fit it stands for).
      const int patch = this->Opts.PatchPoints > 0 ? this->Opts.PatchPoints : kRBFPatchPoints[3];
      const int rbfPoints = static_cast<int>(std::max<Index>(puPoints, std::min<Index>(patch, globalValid / 2)));
      double loo[2] = { 0.0, 0.0 };
      const bool estimated = this->AutoSampledLeaveOneOut(partition, rbfPoints, puPoints, puDegree, loo);
      // The spline must beat PU-WLS by kAutoRBFMargin only where it costs more: RBF-PU costs 5-10x PU-WLS, the
      // global fit up to RBFGlobalLimit about as much or less (measured: 0.002 against 0.013 s at 100 points,
      // 0.08 against 0.03 s at 1,000, ~7,000 evaluation points).
      const bool pu = estimated && (global ? loo[1] < loo[0] : loo[1] <= kAutoRBFMargin * loo[0]);
      this->Opts.Method = pu ? ApproximationMethod::PUWLS : ApproximationMethod::RBF;
      if (pu)
      {
        this->Opts.Degree = puDegree;
        this->Opts.NeighborCount = puPoints;
      }
      if (!estimated)
      {
        std::snprintf(text, sizeof(text),
          "3D cloud of %lld valid points: the polyharmonic spline r^3 (%s; no leave-one-out estimate: %s)",
          static_cast<long long>(globalValid), global ? "one global fit" : "RBF-PU above RBFGlobalLimit",
          this->NumberOfComponents == 0 ? "no values" : "too few full neighbourhoods");
      }
      else
      {
        std::snprintf(text, sizeof(text),
          "3D cloud of %lld valid points: leave-one-out error (rms / std of the values, at %d sampled "
          "neighbourhoods) of the spline r^3 %.3g, of PU-WLS degree %d over %d neighbours %.3g: %s",
          static_cast<long long>(globalValid), static_cast<int>(kAutoSamples), loo[0], puDegree, puPoints, loo[1],
          pu ? (global ? "PU-WLS (the more accurate)"
                       : "PU-WLS (as accurate within the margin of 1.25x, at a fraction of RBF-PU's time)")
             : (global ? "the spline, one global fit (as accurate or more, and about as fast up to RBFGlobalLimit)"
                       : "the spline (more accurate by more than its margin of 1.25x), RBF-PU above RBFGlobalLimit"));
      }
    }
    else
    {
      this->Opts.Method = ApproximationMethod::RBF;
      const bool global = globalValid <= this->Opts.RBFGlobalLimit;
      std::snprintf(text, sizeof(text), "%dD cloud of %lld valid points: the polyharmonic spline r^3 (%s), the most "
                                        "accurate here",
        dimension, static_cast<long long>(globalValid), global ? "one global fit" : "RBF-PU above RBFGlobalLimit");
    }
    this->Rep.MethodReason = text;
  }
  if (this->Opts.Method == ApproximationMethod::RBF)
  {
    const bool global = dimension == 0 || globalValid <= this->Opts.RBFGlobalLimit;
    this->Rep.MethodUsed = global ? "RBF (global)" : "RBF-PU";
    if (this->Requested != ApproximationMethod::Auto)
    {
      std::snprintf(text, sizeof(text), "%lld valid points %s RBFGlobalLimit %lld: %s",
        static_cast<long long>(globalValid), global ? "<=" : ">", static_cast<long long>(this->Opts.RBFGlobalLimit),
        global ? "one global fit" : "a partition of unity of local fits");
      this->Rep.MethodReason = text;
    }
  }
  else
  {
    this->Rep.MethodUsed = ApproximationMethodName(this->Opts.Method);
    if (this->Requested == ApproximationMethod::Auto)
    {
      this->Rep.MethodUsed += " degree " + std::to_string(this->Opts.Degree);
    }
  }
}

bool Approximator::AutoLeaveOneOut(const CloudPartition* partition, double errors[2]) const
{
  const int C = this->NumberOfComponents;
  if (C == 0 || (partition && !partition->Gather))
  {
    return false;
  }
  // This part's own valid points (position, values), gathered over every part when distributed. The estimate
  // runs on a serial copy of the whole (small) cloud, whose result does not depend on the points' order: the
  // same choice on every part and in a serial run.
  const Index nv = this->Points.NumberOfValidPoints();
  const double* sp = this->Points.SortedPoints();
  const std::vector<Index>& order = this->Points.SortedOrder();
  const size_t stride = 3 + static_cast<size_t>(C);
  std::vector<double> mine, all;
  mine.reserve(stride * static_cast<size_t>(nv));
  for (Index p = 0; p < nv; ++p)
  {
    const Index id = order[p];
    if (partition && partition->Owned && !partition->Owned[id])
    {
      continue;
    }
    mine.insert(mine.end(), sp + 3 * p, sp + 3 * p + 3);
    mine.insert(mine.end(), &this->Values[static_cast<size_t>(id) * C], &this->Values[static_cast<size_t>(id) * C] + C);
  }
  if (partition)
  {
    partition->Gather(mine, all);
  }
  else
  {
    all.swap(mine);
  }
  const Index n = static_cast<Index>(all.size() / stride);
  std::vector<double> xyz(3 * static_cast<size_t>(n)), values(static_cast<size_t>(n) * C);
  for (Index i = 0; i < n; ++i)
  {
    std::copy_n(&all[stride * i], 3, &xyz[3 * i]);
    std::copy_n(&all[stride * i + 3], C, &values[static_cast<size_t>(i) * C]);
  }
  ApproximationOptions options = this->Opts;
  options.Method = ApproximationMethod::PUWLS;
  options.Degree = std::max(this->Opts.Degree, 3);
  options.Diagnostics = false;
  options.ComputeGradients = false;
  options.Smoothing = 0.0;
  options.RBFKernel = RBFKernelType::Polyharmonic;
  options.RBFGlobalLimit = std::max<Index>(n, 1);
  Approximator trial;
  std::vector<double> splineLOO, puLOO;
  if (!trial.SetOptions(options) || !trial.SetCloud(xyz.data(), n, values.data(), C) ||
    trial.CloudDimension() != 2 || !trial.LeaveOneOutPU(puLOO))
  {
    return false;
  }
  trial.Opts.Method = ApproximationMethod::RBF;
  if (!trial.LeaveOneOutRBF(splineLOO))
  {
    return false;
  }
  // Over the points where both are defined, in the cloud's sorted order (independent of the input's order):
  // per component the rms of the residuals relative to the values' standard deviation, then the rms over the
  // components (a constant component, fitted exactly by both, is left out).
  const Index tn = trial.Points.NumberOfValidPoints();
  const std::vector<Index>& tOrder = trial.Points.SortedOrder();
  double sums[2] = { 0.0, 0.0 };
  int used = 0;
  for (int c = 0; c < C; ++c)
  {
    double mean = 0.0, count = 0.0;
    double squares[2] = { 0.0, 0.0 };
    for (Index p = 0; p < tn; ++p)
    {
      const size_t at = static_cast<size_t>(tOrder[p]) * C + c;
      if (std::isfinite(splineLOO[at]) && std::isfinite(puLOO[at]))
      {
        mean += trial.Values[at];
        count += 1.0;
      }
    }
    if (count < 0.5 * static_cast<double>(tn) || count < 3.0)
    {
      return false; // the estimate would rest on too few points
    }
    mean /= count;
    double variance = 0.0;
    for (Index p = 0; p < tn; ++p)
    {
      const size_t at = static_cast<size_t>(tOrder[p]) * C + c;
      if (std::isfinite(splineLOO[at]) && std::isfinite(puLOO[at]))
      {
        variance += (trial.Values[at] - mean) * (trial.Values[at] - mean);
        squares[0] += splineLOO[at] * splineLOO[at];
        squares[1] += puLOO[at] * puLOO[at];
      }
    }
    if (!(variance > 0.0))
    {
      continue;
    }
    sums[0] += squares[0] / variance;
    sums[1] += squares[1] / variance;
    ++used;
  }
  return RmsOverComponents(sums, used, errors);
}

bool Approximator::LeaveOneOutRBF(std::vector<double>& residuals)
{
  this->RBFLeaveOneOut = true;
  const bool ok = this->PrepareRBF(nullptr, 0) && this->RBFFits && this->RBFFits->Global;
  this->RBFLeaveOneOut = false;
  if (!ok)
  {
    return false;
  }
  residuals.swap(this->RBFFits->LeaveOneOut);
  return !residuals.empty();
}

bool Approximator::LeaveOneOutPU(std::vector<double>& residuals) const
{
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const Index n = static_cast<Index>(this->Coordinates.size() / 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  residuals.assign(static_cast<size_t>(n) * C, nan);
  if (D <= 0 || C == 0)
  {
    return false;
  }
  // The centres within R of the cloud's points, fitted as PreparePU fits them; for each fit and each point j
  // in it that the fit blends into (|x_j - x_c| < R), the fit's value at x_j without point j:
  // f_j - (f_j - L(x_j)) / (1 - h_jj), h_jj = w_j b_j^T M^-1 b_j (M = sum w b b^T, the weighted fit's hat
  // matrix), blended there by theta as PUPoint blends.
  std::vector<double> centers;
  const double R = this->PUCentresNear(this->Points.SortedPoints(), this->Points.NumberOfValidPoints(), centers);
  const Index nodes = static_cast<Index>(centers.size() / 3);
  const size_t stride = static_cast<size_t>(kMaxBasisSize) * C;
  std::vector<double> sums(static_cast<size_t>(n) * C, 0.0), thetas(static_cast<size_t>(n), 0.0);
  std::vector<unsigned char> undefined(static_cast<size_t>(n), 0);
  std::vector<double> coefficients(stride), local(static_cast<size_t>(C));
  FitScratch s;
  for (Index node = 0; node < nodes; ++node)
  {
    const double* x = &centers[3 * node];
    double h = 0.0, condition = 0.0;
    int m = 0;
    const int degree = this->FitPUCentre(x, R, s, coefficients.data(), condition, h, m);
    if (degree < 0)
    {
      continue;
    }
    const RuntimeBasis basis(D, degree);
    const int q = basis.Size();
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(q, q);
    double row[kMaxBasisSize];
    for (int j = 0; j < m; ++j)
    {
      basis.Evaluate(&s.Xi[3 * j], row);
      const Eigen::Map<const Eigen::VectorXd> b(row, q);
      M.noalias() += s.Weights[j] * (b * b.transpose());
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(M);
    if (ldlt.info() != Eigen::Success)
    {
      continue;
    }
    for (int j = 0; j < m; ++j)
    {
      const Index id = s.Ids[j];
      const double* xj = &this->Coordinates[3 * id];
      const double d2 =
        (xj[0] - x[0]) * (xj[0] - x[0]) + (xj[1] - x[1]) * (xj[1] - x[1]) + (xj[2] - x[2]) * (xj[2] - x[2]);
      const double theta = this->UnitKernel.ValueSquared(d2 / (R * R));
      if (!(theta > 0.0))
      {
        continue;
      }
      basis.Evaluate(&s.Xi[3 * j], row);
      const Eigen::Map<const Eigen::VectorXd> b(row, q);
      const double leverage = s.Weights[j] * b.dot(ldlt.solve(b));
      if (!(leverage < 1.0 - 1e-8) || !std::isfinite(leverage))
      {
        undefined[id] = 1; // the fit passes through x_j whatever the others: no estimate without it
        continue;
      }
      EvaluateFit(D, degree, &s.Xi[3 * j], coefficients.data(), C, local.data(), nullptr);
      thetas[id] += theta;
      for (int c = 0; c < C; ++c)
      {
        const double f = this->Values[static_cast<size_t>(id) * C + c];
        sums[static_cast<size_t>(id) * C + c] += theta * (f - (f - local[c]) / (1.0 - leverage));
      }
    }
  }
  for (Index id = 0; id < n; ++id)
  {
    if (thetas[id] > 0.0 && !undefined[id])
    {
      for (int c = 0; c < C; ++c)
      {
        const size_t at = static_cast<size_t>(id) * C + c;
        residuals[at] = this->Values[at] - sums[at] / thetas[id];
      }
    }
  }
  return true;
}

bool Approximator::AutoSampledLeaveOneOut(
  const CloudPartition* partition, int rbfPoints, int puPoints, int puDegree, double errors[2]) const
{
  const int C = this->NumberOfComponents;
  const int D = this->Frame.Dimension;
  if (C == 0 || D < 1 || (partition && !partition->Gather) || this->GlobalValidPoints < 2 * puPoints)
  {
    return false;
  }
  // Sample positions: the nodes of a coarse lattice (about kAutoSamples of them) over the cloud's box in its
  // frame, the PU-WLS lattice's box (over every part when distributed).
  double umin[3], spacing = 1.0, cover = 1.0;
  Index counts[3];
  this->PULattice(umin, spacing, cover, counts);
  Index fine = 1;
  for (int a = 0; a < D; ++a)
  {
    fine *= counts[a];
  }
  const double coarse =
    spacing * std::max(1.0, std::pow(static_cast<double>(fine) / kAutoSamples, 1.0 / static_cast<double>(D)));
  Index coarseCounts[3] = { 1, 1, 1 };
  for (int a = 0; a < D; ++a)
  {
    const double extent = static_cast<double>(counts[a] - 1) * spacing;
    coarseCounts[a] = std::max<Index>(1, static_cast<Index>(std::floor(extent / coarse)));
  }
  const Index samples = coarseCounts[0] * coarseCounts[1] * coarseCounts[2];
  // The samples' positions: the coarse nodes' centres.
  double origin[3];
  this->PUOrigin(origin);
  std::vector<double> centres(3 * static_cast<size_t>(samples));
  for (Index node = 0; node < samples; ++node)
  {
    const Index index[3] = { node % coarseCounts[0], (node / coarseCounts[0]) % coarseCounts[1],
      node / (coarseCounts[0] * coarseCounts[1]) };
    double* x = &centres[3 * node];
    std::copy(origin, origin + 3, x);
    for (int a = 0; a < D; ++a)
    {
      const double u = umin[a] + (static_cast<double>(index[a]) + 0.5) * coarse;
      for (int b = 0; b < 3; ++b)
      {
        x[b] += u * this->Frame.Axes[a][b];
      }
    }
  }
  // Each sample's neighbourhood: this part's own valid points within rho, its nearest `need` of them (the union
  // over the parts holds the cloud's nearest `need`); rho is a ball holding about 4 x need points at the cloud's
  // mean density (the cover ball R holds about NeighborCount).
  const int need = std::max(rbfPoints, puPoints);
  const double rho = 1.6 * cover *
    std::pow(static_cast<double>(need) / std::max(1, this->Opts.NeighborCount), 1.0 / static_cast<double>(D));
  const size_t stride = 4 + static_cast<size_t>(C); // sample, x, y, z, values
  std::vector<double> mine, all;
  FitScratch s;
  std::vector<std::pair<double, Index>> near;
  for (Index node = 0; node < samples; ++node)
  {
    this->Points.FindWithinRadius(&centres[3 * node], rho, s.Ids, &s.Dist2);
    near.clear();
    for (size_t j = 0; j < s.Ids.size(); ++j)
    {
      const Index id = s.Ids[j];
      if (!partition || !partition->Owned || partition->Owned[id])
      {
        near.emplace_back(s.Dist2[j], id);
      }
    }
    if (static_cast<int>(near.size()) > need)
    {
      std::nth_element(near.begin(), near.begin() + (need - 1), near.end(), this->NeighborOrder());
      near.resize(static_cast<size_t>(need));
    }
    for (const auto& pair : near)
    {
      mine.push_back(static_cast<double>(node));
      mine.insert(mine.end(), &this->Coordinates[3 * pair.second], &this->Coordinates[3 * pair.second] + 3);
      const double* v = &this->Values[static_cast<size_t>(pair.second) * C];
      mine.insert(mine.end(), v, v + C);
    }
  }
  if (partition)
  {
    partition->Gather(mine, all);
  }
  else
  {
    all.swap(mine);
  }
  // Every part now holds the same records; ordered by sample, then distance to the sample, then position and
  // values (nothing depends on which part held a point, nor on the input's order).
  const Index records = static_cast<Index>(all.size() / stride);
  std::vector<double> dist2(static_cast<size_t>(records));
  for (Index r = 0; r < records; ++r)
  {
    const double* rec = &all[stride * r];
    const double* x = &centres[3 * static_cast<Index>(rec[0])];
    dist2[r] = (rec[1] - x[0]) * (rec[1] - x[0]) + (rec[2] - x[1]) * (rec[2] - x[1]) + (rec[3] - x[2]) * (rec[3] - x[2]);
  }
  std::vector<Index> order(static_cast<size_t>(records));
  std::iota(order.begin(), order.end(), Index(0));
  std::sort(order.begin(), order.end(), [&](Index a, Index b) {
    const double* ra = &all[stride * a];
    const double* rb = &all[stride * b];
    if (ra[0] != rb[0])
    {
      return ra[0] < rb[0];
    }
    if (dist2[a] != dist2[b])
    {
      return dist2[a] < dist2[b];
    }
    return std::lexicographical_compare(ra + 1, ra + stride, rb + 1, rb + stride);
  });

  // Per sample with a full neighbourhood, each method's fit as it would run there - the polyharmonic fit over
  // the rbfPoints nearest (an RBF-PU patch), the weighted polynomial fit of degree puDegree over the puPoints
  // nearest with support SupportFactor x the puPoints-th distance (a PU-WLS centre) - and its leave-one-out
  // residuals (Rippa's formula; r / (1 - h_jj)) at the points it would blend into, weighted by its blending
  // weight theta(|x_j - x_c| / R) (R: the support / SupportFactor, the cover radius of its lattice).
  const int beta = D == 2 ? 2 : 3;
  const RuntimeBasis basis(D, puDegree);
  const int q = basis.Size();
  std::vector<double> xi(3 * static_cast<size_t>(need)), f(static_cast<size_t>(need) * C),
    w(static_cast<size_t>(need) * C), tail(static_cast<size_t>(kMaxBasisSize) * C),
    loo(static_cast<size_t>(need) * C), pu(static_cast<size_t>(puPoints) * C), weights(static_cast<size_t>(need)),
    b(static_cast<size_t>(need) * q);
  // Per component and method: the blend-weighted sums of squared residuals and of the weights; per component:
  // the mean and squared deviations of the values scored (Welford's update: no cancellation far from zero).
  std::vector<double> squares(2 * static_cast<size_t>(C), 0.0), mean(C, 0.0), deviations(C, 0.0);
  double thetaSums[2] = { 0.0, 0.0 };
  double used = 0.0, scored = 0.0;
  Index first = 0;
  while (first < records)
  {
    Index last = first;
    const double node = all[stride * order[first]];
    while (last < records && all[stride * order[last]] == node)
    {
      ++last;
    }
    const Index m = last - first;
    const Index* ids = &order[first];
    first = last;
    if (m < need)
    {
      continue; // the sample's neighbourhood is not full (a corner of the box outside the data)
    }
    const double* x = &centres[3 * static_cast<Index>(node)];
    auto local = [&](int count, double invH) {
      for (int j = 0; j < count; ++j)
      {
        const double* rec = &all[stride * ids[j]];
        const double dx[3] = { rec[1] - x[0], rec[2] - x[1], rec[3] - x[2] };
        this->Frame.Project<3>(dx, invH, &xi[3 * j]);
        for (int a = D; a < 3; ++a)
        {
          xi[3 * j + a] = 0.0;
        }
        std::copy_n(rec + 4, C, &f[static_cast<size_t>(j) * C]);
      }
    };
    // The weighted polynomial fit first (f then holds the puPoints nearest values, the first of the patch's).
    const double hp = this->Opts.SupportFactor * std::sqrt(dist2[ids[puPoints - 1]]);
    const double hr = std::sqrt(dist2[ids[rbfPoints - 1]]);
    if (!(hp > 0.0) || !(hr > 0.0))
    {
      continue;
    }
    local(puPoints, 1.0 / hp);
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(q, q);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(q, C);
    for (int j = 0; j < puPoints; ++j)
    {
      weights[j] = this->UnitKernel.ValueSquared(dist2[ids[j]] / (hp * hp));
      basis.Evaluate(&xi[3 * j], &b[static_cast<size_t>(j) * q]);
      const Eigen::Map<const Eigen::VectorXd> bj(&b[static_cast<size_t>(j) * q], q);
      M.noalias() += weights[j] * (bj * bj.transpose());
      for (int c = 0; c < C; ++c)
      {
        rhs.col(c) += weights[j] * f[static_cast<size_t>(j) * C + c] * bj;
      }
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(M);
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-14))
    {
      continue;
    }
    const Eigen::MatrixXd coefficients = ldlt.solve(rhs);
    const double coverPU2 = hp * hp / (this->Opts.SupportFactor * this->Opts.SupportFactor);
    bool defined = true;
    for (int j = 0; j < puPoints && defined; ++j)
    {
      std::fill_n(&pu[static_cast<size_t>(j) * C], C, 0.0);
      if (!(dist2[ids[j]] < coverPU2))
      {
        continue; // blends nothing there
      }
      const Eigen::Map<const Eigen::VectorXd> bj(&b[static_cast<size_t>(j) * q], q);
      const double leverage = weights[j] * bj.dot(ldlt.solve(bj));
      defined = leverage < 1.0 - 1e-8 && std::isfinite(leverage);
      for (int c = 0; c < C && defined; ++c)
      {
        const double r = f[static_cast<size_t>(j) * C + c] - bj.dot(coefficients.col(c));
        pu[static_cast<size_t>(j) * C + c] = r / (1.0 - leverage);
        defined = std::isfinite(pu[static_cast<size_t>(j) * C + c]);
      }
    }
    // The polyharmonic patch (its support is SupportFactor x its cover radius, as RBF-PU's).
    local(rbfPoints, 1.0 / hr);
    PolyharmonicFit fit;
    if (!defined || !SolvePolyharmonic(D, beta, this->Opts.TailDegree, 0.0, xi.data(), rbfPoints, f.data(), C,
                      w.data(), tail.data(), fit, loo.data()))
    {
      continue;
    }
    const double coverRBF2 = hr * hr / (this->Opts.SupportFactor * this->Opts.SupportFactor);
    for (int j = 0; j < rbfPoints && defined; ++j)
    {
      for (int c = 0; c < C && defined; ++c)
      {
        defined = std::isfinite(loo[static_cast<size_t>(j) * C + c]) || !(dist2[ids[j]] < coverRBF2);
      }
    }
    if (!defined)
    {
      continue;
    }
    used += 1.0;
    for (int j = 0; j < rbfPoints; ++j)
    {
      const double d2 = dist2[ids[j]];
      const double theta[2] = { d2 < coverRBF2 ? this->UnitKernel.ValueSquared(d2 / coverRBF2) : 0.0,
        j < puPoints && d2 < coverPU2 ? this->UnitKernel.ValueSquared(d2 / coverPU2) : 0.0 };
      if (!(theta[0] > 0.0) && !(theta[1] > 0.0))
      {
        continue;
      }
      thetaSums[0] += theta[0];
      thetaSums[1] += theta[1];
      scored += 1.0;
      for (int c = 0; c < C; ++c)
      {
        const size_t at = static_cast<size_t>(j) * C + c;
        if (theta[0] > 0.0)
        {
          squares[2 * c] += theta[0] * loo[at] * loo[at];
        }
        if (theta[1] > 0.0)
        {
          squares[2 * c + 1] += theta[1] * pu[at] * pu[at];
        }
        const double delta = f[at] - mean[c];
        mean[c] += delta / scored;
        deviations[c] += delta * (f[at] - mean[c]);
      }
    }
  }
  if (used < kAutoMinimumSamples || !(thetaSums[0] > 0.0) || !(thetaSums[1] > 0.0))
  {
    return false;
  }
  // Per component the weighted mean squared residual relative to the variance of the values scored (a constant
  // component is left out), then the rms over the components.
  double sums[2] = { 0.0, 0.0 };
  int components = 0;
  for (int c = 0; c < C; ++c)
  {
    const double variance = deviations[c] / scored;
    if (!(variance > 0.0))
    {
      continue;
    }
    sums[0] += squares[2 * c] / (thetaSums[0] * variance);
    sums[1] += squares[2 * c + 1] / (thetaSums[1] * variance);
    ++components;
  }
  return RmsOverComponents(sums, components, errors);
}

} // namespace meshfree
