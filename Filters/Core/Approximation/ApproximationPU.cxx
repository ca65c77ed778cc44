// SPDX-License-Identifier: BSD-3-Clause
// PU-WLS (thesis 3.16-3.21): local WLS fits at lattice centres blended by a partition of unity. The choice
// of the centres is documented in Approximation.h.
#include "Approximation/ApproximationPU.h"

#include "Common/Parallel.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{

void Approximator::PUOrigin(double origin[3]) const
{
  // The centre of the bounds, not the centroid: min and max do not depend on the order the points are
  // visited in (nor on how a distributed cloud is split), a sum does in its last bits.
  for (int a = 0; a < 3; ++a)
  {
    origin[a] = 0.5 * (this->Bounds[2 * a] + this->Bounds[2 * a + 1]);
  }
}

void Approximator::PULattice(double umin[3], double& spacing, double& cover, Index counts[3]) const
{
  const int D = this->Frame.Dimension;
  const Index nv = this->GlobalValidPoints;
  const double* sp = this->Points.SortedPoints();
  const int k = this->PatchSize(); // NeighborCount (PU-WLS), the RBF-PU patch size
  constexpr double pi = 3.141592653589793238462643383279502884;

  double umax[3] = { 0, 0, 0 }, origin[3];
  this->PUOrigin(origin);
  for (int a = 0; a < 3; ++a)
  {
    umin[a] = umax[a] = 0.0;
    counts[a] = 1;
  }
  for (int a = 0; a < D; ++a)
  {
    // A distributed cloud's box comes from SetCloud (over every part).
    umin[a] = this->Partitioned ? -this->PartitionBox[2 * a] : std::numeric_limits<double>::infinity();
    umax[a] = this->Partitioned ? this->PartitionBox[2 * a + 1] : -std::numeric_limits<double>::infinity();
  }
  for (Index i = 0; i < (this->Partitioned ? 0 : this->Points.NumberOfValidPoints()); ++i)
  {
    const double dx[3] = { sp[3 * i] - origin[0], sp[3 * i + 1] - origin[1], sp[3 * i + 2] - origin[2] };
    double u[3];
    this->Frame.Project<3>(dx, 1.0, u);
    for (int a = 0; a < D; ++a)
    {
      umin[a] = std::min(umin[a], u[a]);
      umax[a] = std::max(umax[a], u[a]);
    }
  }
  spacing = 1.0;
  cover = 1.0;
  if (D > 0)
  {
    if (this->Opts.SupportRadius > 0.0)
    {
      cover = this->Opts.SupportRadius / this->Opts.SupportFactor;
      spacing = cover / std::sqrt(static_cast<double>(D));
    }
    else
    {
      double volume = 1.0;
      for (int a = 0; a < D; ++a)
      {
        volume *= umax[a] - umin[a];
      }
      const double omega = D == 1 ? 2.0 : (D == 2 ? pi : 4.0 * pi / 3.0);
      const double density = static_cast<double>(nv) / volume;
      // The cover ball of radius R = s sqrt(d) holds about NeighborCount points.
      spacing = std::pow(k / (density * omega * std::pow(static_cast<double>(D), 0.5 * D)), 1.0 / D);
      cover = spacing * std::sqrt(static_cast<double>(D));
    }
    if (!(spacing > 0.0) || !std::isfinite(spacing))
    {
      // A cloud without extent along some axis of its frame (or an overflowing one): one cover patch per
      // axis-length, so that the node count below stays finite and positive.
      double extent = 0.0;
      for (int a = 0; a < D; ++a)
      {
        extent = std::max(extent, umax[a] - umin[a]);
      }
      spacing = extent > 0.0 && std::isfinite(extent) ? extent : 1.0;
      cover = spacing * std::sqrt(static_cast<double>(D));
    }
    for (;;)
    {
      double total = 1.0;
      for (int a = 0; a < D; ++a)
      {
        const double cells = std::ceil((umax[a] - umin[a]) / spacing);
        counts[a] = (cells >= 0.0 && cells < 1e15) ? static_cast<Index>(cells) + 1 : 1;
        total *= cells >= 0.0 ? cells + 1.0 : std::numeric_limits<double>::infinity();
      }
      if (total <= 4.0 * static_cast<double>(nv) + 64.0 && std::isfinite(total))
      {
        break;
      }
      spacing *= 1.25;
      cover = spacing * std::sqrt(static_cast<double>(D));
    }
  }
}

void Approximator::PUNode(const double umin[3], double spacing, const Index counts[3], Index node, double x[3]) const
{
  const Index index[3] = { node % counts[0], (node / counts[0]) % counts[1], node / (counts[0] * counts[1]) };
  this->PUOrigin(x);
  for (int a = 0; a < this->Frame.Dimension; ++a)
  {
    const double u = umin[a] + static_cast<double>(index[a]) * spacing;
    for (int b = 0; b < 3; ++b)
    {
      x[b] += u * this->Frame.Axes[a][b];
    }
  }
}

double Approximator::PUCentresNear(const double* xyz, Index m, std::vector<double>& centers) const
{
  double umin[3], spacing = 1.0, cover = 1.0;
  Index counts[3];
  this->PULattice(umin, spacing, cover, counts);
  double box[6];
  FiniteBox(xyz, m, box);
  const double reach2 = (cover * (1.0 + 1e-9)) * (cover * (1.0 + 1e-9));
  centers.clear();
  const Index nodes = counts[0] * counts[1] * counts[2];
  for (Index node = 0; node < nodes; ++node)
  {
    double x[3];
    this->PUNode(umin, spacing, counts, node, x);
    if (BoxDistance2(box, x) <= reach2)
    {
      centers.insert(centers.end(), x, x + 3);
    }
  }
  return cover;
}

int Approximator::FitPUCentre(const double x[3], double R, FitScratch& s, double* coefficients, double& condition,
  double& h, int& m) const
{
  if (this->Opts.SupportRadius > 0.0)
  {
    h = this->Opts.SupportRadius;
  }
  else
  {
    this->Neighbors(x, this->Opts.NeighborCount, 0.0, s, h);
    h = std::max(h, this->Opts.SupportFactor * R);
  }
  m = 0;
  for (int attempt = 0; attempt < 2; ++attempt, h *= 2.0)
  {
    this->Points.FindWithinRadius(x, h, s.Ids, &s.Dist2);
    this->SortNeighbors(s, s.Ids.size());
    const int n = static_cast<int>(s.Ids.size());
    if (attempt == 0 && !std::any_of(s.Dist2.begin(), s.Dist2.end(), [&](double d2) { return d2 < R * R; }))
    {
      return -1; // no data inside its cover region: the centre blends nothing
    }
    s.Reserve(static_cast<size_t>(std::max(n, 1)));
    m = this->GatherWeighted(x, n, h, s);
    const int degree = this->FitDescending(attempt == 0 ? this->Opts.Degree : 0, s, m, coefficients, condition);
    if (degree >= 0)
    {
      return degree;
    }
  }
  return -1;
}

bool Approximator::PreparePU(const double* xyz, Index count)
{
  this->PU.reset(new PUData);
  PUData& pu = *this->PU;
  const int C = this->NumberOfComponents;
  // Only the centres within R of the evaluation points can blend into them: the others are not fitted.
  std::vector<double> centers;
  const double cover = this->PUCentresNear(xyz, count, centers);
  pu.CoverRadius = cover;
  const Index nodes = static_cast<Index>(centers.size() / 3);
  const size_t stride = static_cast<size_t>(kMaxBasisSize) * C;
  std::vector<double> supports(nodes), conditions(nodes), coefficients(stride * nodes);
  std::vector<int> degrees(nodes, -1), fitCounts(nodes, 0);

  PerThread<FitScratch> scratch;
  ParallelFor(nodes, 16, [&](Index begin, Index end) {
    FitScratch& s = scratch.Local();
    for (Index node = begin; node < end; ++node)
    {
      double h = 0.0;
      int m = 0;
      degrees[node] =
        this->FitPUCentre(&centers[3 * node], cover, s, &coefficients[stride * node], conditions[node], h, m);
      if (degrees[node] >= 0)
      {
        fitCounts[node] = m;
        supports[node] = h;
      }
    }
  });
  Index kept = 0;
  for (Index node = 0; node < nodes; ++node)
  {
    if (degrees[node] < 0)
    {
      continue;
    }
    pu.Centers.insert(pu.Centers.end(), &centers[3 * node], &centers[3 * node] + 3);
    pu.Supports.push_back(supports[node]);
    pu.Degrees.push_back(degrees[node]);
    pu.Counts.push_back(fitCounts[node]);
    pu.Conditions.push_back(conditions[node]);
    pu.Coefficients.insert(
      pu.Coefficients.end(), coefficients.begin() + stride * node, coefficients.begin() + stride * (node + 1));
    ++kept;
  }
  this->Rep.Centers = kept;
  if (kept == 0)
  {
    this->Err = "no PU-WLS centre has a valid fit";
    return false;
  }
  pu.CenterGrid.Build(pu.Centers.data(), kept);
  return true;
}

Approximator::PointResult Approximator::PUPoint(
  const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const
{
  const PUData& pu = *this->PU;
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  const size_t stride = static_cast<size_t>(kMaxBasisSize) * C;
  auto local = [&](Index c, const double dx[3], double* values, double* gradients) {
    double xi[3] = { 0, 0, 0 };
    const double support = pu.Supports[c];
    this->Frame.Project<3>(dx, 1.0 / support, xi);
    EvaluateFit(D, pu.Degrees[c], xi, &pu.Coefficients[stride * c], C, values, gradients);
    for (int a = 0; gradients && a < D * C; ++a)
    {
      gradients[a] /= support; // per unit xi -> per unit length
    }
  };
  auto info = [&](Index c, PointResult& result) {
    result.Neighbors = pu.Counts[c];
    result.Condition = pu.Conditions[c];
    result.Lowered = pu.Degrees[c] < this->Opts.Degree;
  };
  return this->BlendCentres(x, pu.CenterGrid, pu.Centers.data(), pu.CoverRadius, s, out, i, local, info);
}

bool Approximator::WriteBlend(Index i, const double* sumValues, const double* sumGrad, const double* sumDTheta,
  double sumTheta, const ApproximationOutput& out) const
{
  const int D = this->Frame.Dimension;
  const int C = this->NumberOfComponents;
  bool finite = true;
  for (int q = 0; q < C; ++q)
  {
    const double f = sumValues[q] / sumTheta;
    finite = finite && std::isfinite(f);
    if (out.Values)
    {
      out.Values[i * C + q] = f;
    }
    if (out.Gradients)
    {
      // grad (sum theta L / sum theta) = (sum grad(theta L) - f sum grad theta) / sum theta (3.21).
      double l[3] = { 0, 0, 0 };
      for (int a = 0; a < D; ++a)
      {
        l[a] = (sumGrad[a * C + q] - f * sumDTheta[a]) / sumTheta;
      }
      double* g = out.Gradients + 3 * (i * C + q);
      this->Frame.Unproject(l, g);
      finite = finite && std::isfinite(g[0]) && std::isfinite(g[1]) && std::isfinite(g[2]);
    }
  }
  return finite;
}

} // namespace meshfree
