// SPDX-License-Identifier: BSD-3-Clause
// PCA normals over a density- and noise-adapted neighbourhood (SurfaceNormals.h).
#include "Surface/SurfaceNormals.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <vector>

namespace meshfree
{

namespace
{
constexpr double Pi = 3.141592653589793238462643383279502884;

struct LocalPCA
{
  double Normal[3] = { 0.0, 0.0, 0.0 };
  double Eigenvalues[3] = { 0.0, 0.0, 0.0 }; // ascending, in world units squared
  bool Valid = false;
};

/// PCA of the points at sorted positions pos[0..count) of `sorted`, about their centroid, in coordinates
/// shifted to x and scaled by 1/scale.
LocalPCA PrincipalAxes(const double* sorted, const Index* pos, size_t count, const double x[3], double scale)
{
  LocalPCA out;
  if (count < 3 || !(scale > 0.0))
  {
    return out;
  }
  // One pass: first and second moments in the scaled coordinates (|d| <= 1), C = E[d d^T] - E[d] E[d]^T.
  const double inv = 1.0 / scale;
  double m1[3] = { 0.0, 0.0, 0.0 };
  double m2[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 }; // xx, xy, xz, yy, yz, zz
  for (size_t j = 0; j < count; ++j)
  {
    const double* p = sorted + 3 * pos[j];
    const double d0 = (p[0] - x[0]) * inv, d1 = (p[1] - x[1]) * inv, d2 = (p[2] - x[2]) * inv;
    m1[0] += d0;
    m1[1] += d1;
    m1[2] += d2;
    m2[0] += d0 * d0;
    m2[1] += d0 * d1;
    m2[2] += d0 * d2;
    m2[3] += d1 * d1;
    m2[4] += d1 * d2;
    m2[5] += d2 * d2;
  }
  const double w = 1.0 / static_cast<double>(count);
  for (double& m : m1)
  {
    m *= w;
  }
  Eigen::Matrix3d C;
  C(0, 0) = m2[0] * w - m1[0] * m1[0];
  C(0, 1) = C(1, 0) = m2[1] * w - m1[0] * m1[1];
  C(0, 2) = C(2, 0) = m2[2] * w - m1[0] * m1[2];
  C(1, 1) = m2[3] * w - m1[1] * m1[1];
  C(1, 2) = C(2, 1) = m2[4] * w - m1[1] * m1[2];
  C(2, 2) = m2[5] * w - m1[2] * m1[2];
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(C);
  const Eigen::Vector3d l = eig.eigenvalues();
  // Collinear or coincident neighbours leave the plane undetermined.
  if (!(l(1) > 1e-12 * l(2)) || !(l(2) > 0.0) || !std::isfinite(l(2)))
  {
    return out;
  }
  const Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
  for (int a = 0; a < 3; ++a)
  {
    out.Normal[a] = n(a);
    out.Eigenvalues[a] = std::max(0.0, l(a)) * scale * scale;
  }
  out.Valid = std::isfinite(n(0)) && std::isfinite(n(1)) && std::isfinite(n(2));
  return out;
}

double Median(std::vector<double> v)
{
  if (v.empty())
  {
    return 0.0;
  }
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

/// From a radius query's result (sorted positions `pos`, squared distances `r2`) around the point at sorted
/// position `self`: the distance to its k-th nearest other point and its `degree` nearest others (original
/// indices, ordered by (distance, index) like NeighborGrid::FindKNearest). `pairs` is scratch.
void NearestOfList(const std::vector<Index>& pos, const std::vector<double>& r2, Index self, int k,
  const std::vector<Index>& order, std::int32_t* row, int degree, double& kth,
  std::vector<std::pair<double, Index>>& pairs)
{
  pairs.clear();
  for (size_t j = 0; j < pos.size(); ++j)
  {
    if (pos[j] != self)
    {
      pairs.emplace_back(r2[j], order[pos[j]]);
    }
  }
  const size_t want = std::min(static_cast<size_t>(k), pairs.size());
  if (want == 0)
  {
    kth = 0.0;
    return;
  }
  std::nth_element(pairs.begin(), pairs.begin() + (want - 1), pairs.end());
  kth = std::sqrt(pairs[want - 1].first);
  const size_t kept = std::min(static_cast<size_t>(degree), want);
  std::partial_sort(pairs.begin(), pairs.begin() + kept, pairs.begin() + want);
  for (size_t j = 0; j < kept; ++j)
  {
    row[j] = static_cast<std::int32_t>(pairs[j].second);
  }
}

/// The radius that keeps the noise's tilt below tau: R^2 = 2 sigma h / (sqrt(pi) tau).
double NoiseRadius(double noise, double spacing, double tau)
{
  return std::sqrt(2.0 * noise * spacing / (std::sqrt(Pi) * tau));
}
} // namespace

CloudScale EstimateCloudScale(const NeighborGrid& grid, const NormalOptions& options)
{
  CloudScale scale;
  const Index nv = grid.NumberOfValidPoints();
  if (nv < 3)
  {
    return scale;
  }
  const int k = std::max(3, options.NeighborCount);
  const Index samples = std::min<Index>(nv, 2048);
  const double* sorted = grid.SortedPoints();
  std::vector<double> kth(static_cast<size_t>(samples), 0.0);
  std::vector<double> spread(static_cast<size_t>(samples), 0.0);
#pragma omp parallel
  {
    std::vector<Index> ids;
    std::vector<double> d2;
    std::vector<Index> pos;
#pragma omp for schedule(dynamic, 16)
    for (Index j = 0; j < samples; ++j)
    {
      const Index s = j * nv / samples;
      const double* x = sorted + 3 * s;
      // k + 1: the point finds itself first.
      const int found = grid.FindKNearest(x, k + 1, ids, d2);
      if (found < 4)
      {
        continue;
      }
      kth[j] = std::sqrt(d2[found - 1]);
      grid.FindWithinRadiusPositions(x, kth[j], pos, d2);
      const LocalPCA pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, kth[j]);
      spread[j] = pca.Valid ? std::sqrt(pca.Eigenvalues[0]) : 0.0;
    }
  }
  const double rk = Median(kth);
  scale.Spacing = rk * std::sqrt(Pi / k);
  scale.Noise = Median(spread);
  if (!options.AdaptToNoise || !(scale.Spacing > 0.0))
  {
    return scale;
  }
  // Radius -> noise -> radius: a neighbourhood smaller than the noise hides it.
  double radius = std::max(rk, NoiseRadius(scale.Noise, scale.Spacing, options.TiltTolerance));
  for (int round = 0; round < 3 && radius > rk; ++round)
  {
#pragma omp parallel
    {
      std::vector<Index> pos;
      std::vector<double> d2;
#pragma omp for schedule(dynamic, 16)
      for (Index j = 0; j < samples; ++j)
      {
        const double* x = sorted + 3 * (j * nv / samples);
        grid.FindWithinRadiusPositions(x, radius, pos, d2);
        const LocalPCA pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, radius);
        spread[j] = pca.Valid ? std::sqrt(pca.Eigenvalues[0]) : 0.0;
      }
    }
    scale.Noise = Median(spread);
    const double next = std::max(rk, NoiseRadius(scale.Noise, scale.Spacing, options.TiltTolerance));
    const bool settled = std::fabs(next - radius) < 0.05 * radius;
    radius = next;
    if (settled)
    {
      break;
    }
  }
  scale.Radius = radius > rk ? radius : 0.0;
  return scale;
}

bool EstimateNormals(
  const NeighborGrid& grid, const NormalOptions& options, NormalField& field, const ProgressCallback& progress)
{
  const Index n = grid.NumberOfPoints();
  const int degree = std::max(1, options.GraphDegree);
  field.Normals.assign(static_cast<size_t>(3 * n), 0.0);
  field.Radii.assign(static_cast<size_t>(n), 0.0);
  field.NeighborDistance.assign(static_cast<size_t>(n), 0.0);
  field.SurfaceVariation.assign(static_cast<size_t>(n), 0.0);
  field.Valid.assign(static_cast<size_t>(n), 0);
  field.Graph.assign(static_cast<size_t>(n * degree), -1);
  field.GraphDegree = degree;
  field.Scale = CloudScale();
  field.InvalidCount = n;
  if (grid.NumberOfValidPoints() < 3)
  {
    return false;
  }
  const bool fixed = options.SupportRadius > 0.0;
  if (!fixed)
  {
    field.Scale = EstimateCloudScale(grid, options);
  }
  const double noiseRadius = field.Scale.Radius;
  const int k = std::max(std::max(3, options.NeighborCount), degree);
  const double* sorted = grid.SortedPoints();
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  const Index chunk = 65536;
  Index invalid = n - nv;
  bool aborted = false;
  for (Index begin = 0; begin < nv && !aborted; begin += chunk)
  {
    const Index end = std::min(nv, begin + chunk);
    Index bad = 0;
#pragma omp parallel reduction(+ : bad)
    {
      std::vector<Index> ids, pos;
      std::vector<double> d2, r2;
      std::vector<std::pair<double, Index>> pairs;
#pragma omp for schedule(dynamic, 256)
      for (Index s = begin; s < end; ++s)
      {
        const Index id = order[s];
        const double* x = sorted + 3 * s;
        std::int32_t* row = &field.Graph[static_cast<size_t>(id) * degree];
        // Where the noise radius holds more than k neighbours, the k nearest are among them: one radius
        // query gives the neighbourhood, r_k and the orientation graph. Otherwise a k-nearest query first.
        const double first = fixed ? options.SupportRadius : noiseRadius;
        if (first > 0.0)
        {
          grid.FindWithinRadiusPositions(x, first, pos, r2);
        }
        double radius = first;
        if (first > 0.0 && pos.size() > static_cast<size_t>(k))
        {
          NearestOfList(pos, r2, s, k, order, row, degree, field.NeighborDistance[id], pairs);
        }
        else
        {
          const int found = grid.FindKNearest(x, k + 1, ids, d2);
          int kept = 0;
          for (int j = 0; j < found && kept < degree; ++j)
          {
            if (ids[j] != id)
            {
              row[kept++] = static_cast<std::int32_t>(ids[j]);
            }
          }
          field.NeighborDistance[id] = found > 0 ? std::sqrt(d2[found - 1]) : 0.0;
          if (!fixed)
          {
            radius = std::max(field.NeighborDistance[id], noiseRadius);
            grid.FindWithinRadiusPositions(x, radius, pos, r2);
          }
        }
        const LocalPCA pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, radius);
        if (!pca.Valid)
        {
          ++bad;
          continue;
        }
        for (int a = 0; a < 3; ++a)
        {
          field.Normals[3 * id + a] = pca.Normal[a];
        }
        const double total = pca.Eigenvalues[0] + pca.Eigenvalues[1] + pca.Eigenvalues[2];
        field.SurfaceVariation[id] = total > 0.0 ? pca.Eigenvalues[0] / total : 0.0;
        field.Radii[id] = radius;
        field.Valid[id] = 1;
      }
    }
    invalid += bad;
    aborted = progress && !progress(static_cast<double>(end) / static_cast<double>(nv));
  }
  field.InvalidCount = invalid;
  return !aborted && invalid < n;
}

} // namespace meshfree
