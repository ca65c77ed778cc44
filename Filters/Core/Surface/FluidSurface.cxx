// SPDX-License-Identifier: BSD-3-Clause
// SPH colour-field surface of a particle fluid, isotropic or with Yu & Turk's anisotropic kernels
// (FluidSurface.h).
#include "Surface/FluidSurface.h"

#include "Common/Parallel.h"
#include "Common/Statistics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace meshfree
{

namespace
{
constexpr double Pi = 3.141592653589793238462643383279502884;

} // namespace

bool FluidSurface::SetParticles(
  const NeighborGrid& grid, const double* volumes, const FluidSurfaceOptions& options, const Distribution* d)
{
  this->Grid = &grid;
  this->Options = options;
  this->Unit = Kernel(KernelType::Wendland, 3, 1.0);
  const Index nv = grid.NumberOfValidPoints();
  this->Volumes.clear();
  this->Centres.clear();
  this->Transforms.clear();
  this->Determinants.clear();
  this->Volume = 0.0;
  this->SampleShortfall = -HUGE_VAL;
  if (GlobalSum(d, nv) == 0)
  {
    this->H = 0.0;
    return false;
  }
  const double* sorted = grid.SortedPoints();
  const std::vector<Index>& order = grid.SortedOrder();

  // The kernel radius: twice the spacing that the k-nearest balls of a sample of particles give (the sample: the
  // whole cloud's particles whose positions hash lowest, each evaluated where it is owned).
  constexpr int k = 20;
  CloudSample sample;
  // (Distinct positions only: exact duplicates, which particles may have, hash alike; a cell's points are sorted by
  // position, so a duplicate follows its first copy.)
  sample.Choose(d, sorted, nv, 2048, [d, &order, sorted](Index s) {
    return IsOwn(d, order[s]) && (s == 0 || !std::equal(sorted + 3 * s, sorted + 3 * s + 3, sorted + 3 * (s - 1)));
  });
  const std::vector<Index>& mine = sample.Local();
  const Index samples = static_cast<Index>(mine.size());
  std::vector<double> kth(static_cast<size_t>(samples), 0.0);
  // Per-thread query buffers, reused by the three loops below.
  struct Query
  {
    std::vector<Index> Ids;
    std::vector<double> Dist2;
  };
  PerThread<Query> queries;
  ParallelFor(samples, 16, [&](Index begin, Index end) {
    Query& q = queries.Local();
    for (Index j = begin; j < end; ++j)
    {
      const int found = grid.FindKNearest(sorted + 3 * mine[j], k + 1, q.Ids, q.Dist2);
      kth[j] = found > 0 ? std::sqrt(q.Dist2[found - 1]) : 0.0;
    }
  });
  for (Index j = 0; d && j < samples; ++j)
  {
    this->SampleShortfall = std::max(this->SampleShortfall, meshfree::Shortfall(d, sorted + 3 * mine[j], kth[j]));
  }
  const double rk = Median(sample.Gather(d, kth));
  const double spacing0 = rk * std::cbrt(4.0 / 3.0 * Pi / (k + 1));
  this->H = options.SupportRadius > 0.0 ? options.SupportRadius : 2.0 * spacing0;
  if (!(this->H > 0.0) || !std::isfinite(this->H))
  {
    // One particle, or all at one place: a kernel of unit size relative to nothing; take the bounds or 1.
    double b[6];
    grid.GetBounds(b);
    const double extent = std::max({ b[1] - b[0], b[3] - b[2], b[5] - b[4] });
    this->H = extent > 0.0 ? extent : 1.0;
  }

  // The bulk's number density sum_k W(|x_j - x_k|, H) (the particle itself included), as the median over the
  // sample, and every volume, in units of H^3: with a kernel radius of 1e300 (or particles at 1e-300) H^3 and
  // 1/H^3 leave double's range, the ratios do not.
  std::vector<double> density(static_cast<size_t>(samples), 0.0);
  const double invH = 1.0 / this->H;
  ParallelFor(samples, 16, [&](Index begin, Index end) {
    Query& q = queries.Local();
    for (Index j = begin; j < end; ++j)
    {
      grid.FindWithinRadiusPositions(sorted + 3 * mine[j], this->H, q.Ids, q.Dist2);
      double sum = 0.0;
      for (double r2 : q.Dist2)
      {
        sum += this->Unit.ValueSquared(r2 * invH * invH);
      }
      density[j] = sum;
    }
  });
  for (Index j = 0; d && j < samples; ++j)
  {
    this->SampleShortfall = std::max(this->SampleShortfall, meshfree::Shortfall(d, sorted + 3 * mine[j], this->H));
  }
  const double bulk = Median(sample.Gather(d, density));
  const double v0 = bulk > 0.0 ? 1.0 / bulk : 0.125; // relative to H^3
  this->ParticleSpacing = this->H * std::cbrt(v0);
  this->Volumes.assign(static_cast<size_t>(nv), v0);
  double total = 0.0;
  for (Index s = 0; s < nv; ++s)
  {
    const Index id = order[s];
    if (volumes && volumes[id] > 0.0 && std::isfinite(volumes[id]))
    {
      this->Volumes[s] = volumes[id] * invH * invH * invH;
    }
    total += IsOwn(d, id) ? this->Volumes[s] : 0.0;
  }
  this->Volume = GlobalSum(d, total) * this->H * this->H * this->H;
  this->QueryRadius = this->H;
  if (!options.Anisotropic)
  {
    return true;
  }

  // Anisotropic kernels: weighted PCA of the neighbours within twice the spacing.
  const double reach = 2.0 * this->ParticleSpacing;
  const double ratio = std::max(1.0, options.AnisotropyRatio);
  const double lambda = std::min(1.0, std::max(0.0, options.Smoothing));
  this->Centres.assign(static_cast<size_t>(3 * nv), 0.0);
  this->Transforms.assign(static_cast<size_t>(9 * nv), 0.0);
  // The largest stretch and shift set the query radius (maxima: exact in any order).
  struct Extent
  {
    double Stretch = 1.0;
    double Shift = 0.0;
  };
  const Extent largest = ParallelReduce(nv, 256, Extent(),
    [&](Index begin, Index end) {
      Query& buffers = queries.Local();
      std::vector<Index>& pos = buffers.Ids;
      std::vector<double>& d2 = buffers.Dist2;
      Extent mine;
      for (Index s = begin; s < end; ++s)
      {
        const double* x = sorted + 3 * s;
        grid.FindWithinRadiusPositions(x, reach, pos, d2);
        double sw = 0.0;
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (size_t j = 0; j < pos.size(); ++j)
        {
          const double q = std::sqrt(d2[j]) / reach;
          const double w = 1.0 - q * q * q;
          const double* p = sorted + 3 * pos[j];
          mean += w * Eigen::Vector3d(p[0] - x[0], p[1] - x[1], p[2] - x[2]);
          sw += w;
        }
        mean /= sw; // sw >= 1: the particle itself
        Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
        for (size_t j = 0; j < pos.size(); ++j)
        {
          const double q = std::sqrt(d2[j]) / reach;
          const double w = 1.0 - q * q * q;
          const double* p = sorted + 3 * pos[j];
          const Eigen::Vector3d d = Eigen::Vector3d(p[0] - x[0], p[1] - x[1], p[2] - x[2]) - mean;
          C.noalias() += w * d * d.transpose();
        }
        C /= sw;
        Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
        if (static_cast<int>(pos.size()) >= options.MinimumNeighbors)
        {
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
          eig.computeDirect(C);
          Eigen::Vector3d sigma = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt(); // ascending
          const double top = sigma(2);
          if (top > 0.0 && std::isfinite(top))
          {
            sigma = sigma.cwiseMax(top / ratio);
            // Stretches of unit product: the kernel keeps the isotropic kernel's volume.
            const Eigen::Vector3d stretch = sigma / std::cbrt(sigma(0) * sigma(1) * sigma(2));
            M = eig.eigenvectors() * stretch.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
            mine.Stretch = std::max(mine.Stretch, stretch.maxCoeff());
          }
        }
        for (int a = 0; a < 3; ++a)
        {
          this->Centres[3 * s + a] = x[a] + lambda * mean(a);
          for (int b = 0; b < 3; ++b)
          {
            this->Transforms[9 * s + 3 * a + b] = M(a, b);
          }
        }
        mine.Shift = std::max(mine.Shift, lambda * mean.norm());
      }
      return mine;
    },
    [](Extent a, const Extent& b) {
      a.Stretch = std::max(a.Stretch, b.Stretch);
      a.Shift = std::max(a.Shift, b.Shift);
      return a;
    });
  this->QueryRadius = this->H * GlobalMax(d, largest.Stretch) + GlobalMax(d, largest.Shift);
  return true;
}

double FluidSurface::Colour(const double x[3], FieldScratch& s) const
{
  double value = 0.0;
  this->Evaluate(x, value, nullptr, s);
  return this->Options.Level - value;
}

bool FluidSurface::Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& s) const
{
  if (!this->Grid || !(this->H > 0.0))
  {
    return false;
  }
  this->Grid->FindWithinRadiusPositions(x, this->QueryRadius, s.Positions, s.Dist2);
  const double invH = 1.0 / this->H;
  double c = 0.0, g[3] = { 0.0, 0.0, 0.0 };
  const size_t found = s.Positions.size();
  if (this->Transforms.empty())
  {
    const double* sorted = this->Grid->SortedPoints();
    for (size_t j = 0; j < found; ++j)
    {
      const Index p = s.Positions[j];
      const double q = std::sqrt(s.Dist2[j]) * invH;
      if (!(q < 1.0))
      {
        continue;
      }
      const double v = this->Volumes[p]; // V_j / H^3
      c += v * this->Unit.Value(q);
      if (gradient && q > 0.0)
      {
        const double dw = v * this->Unit.RadialDerivative(q) * invH / (q * this->H);
        for (int a = 0; a < 3; ++a)
        {
          g[a] += dw * (x[a] - sorted[3 * p + a]);
        }
      }
    }
  }
  else
  {
    for (size_t j = 0; j < found; ++j)
    {
      const Index p = s.Positions[j];
      const double* m = &this->Transforms[9 * p];
      const double r[3] = { x[0] - this->Centres[3 * p], x[1] - this->Centres[3 * p + 1], x[2] - this->Centres[3 * p + 2] };
      const double u[3] = { m[0] * r[0] + m[1] * r[1] + m[2] * r[2], m[3] * r[0] + m[4] * r[1] + m[5] * r[2],
        m[6] * r[0] + m[7] * r[1] + m[8] * r[2] };
      const double q = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) * invH;
      if (!(q < 1.0))
      {
        continue;
      }
      const double v = this->Volumes[p]; // V_j / H^3
      c += v * this->Unit.Value(q);
      if (gradient && q > 0.0)
      {
        // grad |M r| = M^T u / |u| (M symmetric).
        const double dw = v * this->Unit.RadialDerivative(q) * invH / (q * this->H);
        for (int a = 0; a < 3; ++a)
        {
          g[a] += dw * (m[a] * u[0] + m[3 + a] * u[1] + m[6 + a] * u[2]);
        }
      }
    }
  }
  value = this->Options.Level - c;
  if (gradient)
  {
    for (int a = 0; a < 3; ++a)
    {
      gradient[a] = -g[a];
    }
  }
  return std::isfinite(value);
}

} // namespace meshfree
