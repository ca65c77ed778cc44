// SPDX-License-Identifier: BSD-3-Clause
// PCA normals over a density- and noise-adapted neighbourhood (SurfaceNormals.h).
#include "Surface/SurfaceNormals.h"

#include "Surface/AdaptiveJet.h"

#include "Common/LocalFit.h"
#include "Common/Parallel.h"
#include "Common/Statistics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <vector>

namespace meshfree
{

namespace
{
constexpr double Pi = 3.141592653589793238462643383279502884;
// The adaptive jet's radii (AdaptiveJet.h): from SmallestScale x r_k (about 12 neighbours at k = 20) up to
// TopScale x max(r_k, the noise radius).
constexpr double SmallestScale = 0.8;
constexpr double TopScale = 2.5;

struct LocalPCA
{
  double Normal[3] = { 0.0, 0.0, 0.0 };
  double Eigenvalues[3] = { 0.0, 0.0, 0.0 }; // ascending, in world units squared
  double Residual = 0.0; // distance from the point to its neighbourhood's quadric (or plane)
  bool Valid = false;
};

/// The k nearest neighbours of x at a nonzero distance (exact duplicates of x are not neighbours: they add
/// nothing to the sampling), preceded by x's duplicates (itself included). Returns how many were found in
/// all; kth gets the distance to the k-th distinct one (or the farthest found).
int NearestDistinct(const NeighborGrid& grid, const double x[3], int k, std::vector<Index>& ids,
  std::vector<double>& d2, double& kth)
{
  int want = k + 1;
  for (;;)
  {
    const int found = grid.FindKNearest(x, want, ids, d2);
    int zeros = 0;
    while (zeros < found && d2[zeros] == 0.0)
    {
      ++zeros;
    }
    if (found < want || found - zeros >= k || want > (1 << 16))
    {
      kth = found > zeros ? std::sqrt(d2[std::min(found, zeros + k) - 1]) : 0.0;
      return found;
    }
    want = zeros + k;
  }
}

/// PCA of the points at sorted positions pos[0..count) of `sorted`, about their centroid, in coordinates
/// shifted to x and scaled by 1/scale.
LocalPCA PrincipalAxes(
  const double* sorted, const Index* pos, size_t count, const double x[3], double scale, bool jet)
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
  // Collinear or coincident neighbours leave the plane undetermined. (The closed-form solver's eigenvalues
  // are accurate to ~1e-9 of the largest, so a relative width below 1e-3 counts as a line.)
  if (!(l(1) > 1e-6 * l(2)) || !(l(2) > 0.0) || !std::isfinite(l(2)))
  {
    return out;
  }
  Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
  // Jet refinement (Cazals & Pouget 2005): the height over the PCA plane of the neighbours (the point itself
  // left out) fitted by a quadric,
  // h = a0 + a1 u + a2 v + a3 u^2 + a4 uv + a5 v^2, in the point's frame; the normal at the point is
  // n - a1 t1 - a2 t2. Exact on quadrics, where PCA is biased by O(kappa R) (0.16-0.45 degrees at k = 20).
  // For a symmetric support the slopes are orthogonal to the quadratic terms, so noise tilts them no
  // more than PCA's plane. Fewer than 2 neighbours per term, or a degenerate fit, keep the PCA normal.
  if (jet && count >= 12)
  {
    const Eigen::Vector3d t1 = eig.eigenvectors().col(2).normalized();
    const Eigen::Vector3d t2 = n.cross(t1);
    Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> B = Eigen::Matrix<double, 6, 1>::Zero();
    for (size_t j = 0; j < count; ++j)
    {
      const double* p = sorted + 3 * pos[j];
      const Eigen::Vector3d d((p[0] - x[0]) * inv, (p[1] - x[1]) * inv, (p[2] - x[2]) * inv);
      if (d.squaredNorm() == 0.0)
      {
        continue; // the point itself (and its duplicates): its distance to its neighbours' quadric is the residual
      }
      const double u = d.dot(t1), v = d.dot(t2);
      Eigen::Matrix<double, 6, 1> b;
      b << 1.0, u, v, u * u, u * v, v * v;
      M.selfadjointView<Eigen::Upper>().rankUpdate(b);
      B.noalias() += d.dot(n) * b;
    }
    M.triangularView<Eigen::StrictlyLower>() = M.transpose();
    Eigen::Matrix<double, 6, 1> a;
    double condition = 0.0;
    if (SolveMoment<6>(M, B, a, false, condition) && a.allFinite())
    {
      n = (n - a(1) * t1 - a(2) * t2).normalized();
      out.Residual = std::fabs(a(0)) * scale;
    }
  }
  if (!(out.Residual > 0.0))
  {
    // No quadric: the distance from the point to the plane through the centroid.
    out.Residual = std::fabs(n(0) * m1[0] + n(1) * m1[1] + n(2) * m1[2]) * scale;
  }
  for (int a = 0; a < 3; ++a)
  {
    out.Normal[a] = n(a);
    out.Eigenvalues[a] = std::max(0.0, l(a)) * scale * scale;
  }
  out.Valid = n.allFinite();
  return out;
}


/// From a radius query's result (sorted positions `pos`, squared distances `r2`) around a point: the distance
/// to its k-th nearest other point and its `degree` nearest others (original indices, ordered by (distance,
/// index) like NeighborGrid::FindKNearest), exact duplicates of the point left out. False (nothing written)
/// when the list holds fewer than k such points. `keys` is scratch.
bool NearestOfList(const std::vector<Index>& pos, const std::vector<double>& r2, int k,
  const std::vector<Index>& order, std::int32_t* row, int degree, double& kth, std::vector<double>& keys)
{
  keys.clear();
  for (double d2 : r2)
  {
    if (d2 > 0.0) // the point itself and its exact duplicates are not neighbours
    {
      keys.push_back(d2);
    }
  }
  if (keys.size() < static_cast<size_t>(k) || k <= 0)
  {
    return false;
  }
  std::nth_element(keys.begin(), keys.begin() + (k - 1), keys.end());
  kth = std::sqrt(keys[k - 1]);
  // The `degree` nearest by (distance, index), kept sorted by insertion (degree is small).
  constexpr int MaxDegree = 64;
  const int want = std::min(std::min(degree, k), MaxDegree);
  double bestD2[MaxDegree];
  Index bestId[MaxDegree];
  int kept = 0;
  for (size_t j = 0; j < pos.size(); ++j)
  {
    const double d2 = r2[j];
    if (!(d2 > 0.0) || (kept == want && d2 > bestD2[want - 1]))
    {
      continue;
    }
    const Index id = order[pos[j]];
    if (kept == want && d2 == bestD2[want - 1] && id > bestId[want - 1])
    {
      continue;
    }
    int at = kept < want ? kept++ : want - 1;
    while (at > 0 && (bestD2[at - 1] > d2 || (bestD2[at - 1] == d2 && bestId[at - 1] > id)))
    {
      bestD2[at] = bestD2[at - 1];
      bestId[at] = bestId[at - 1];
      --at;
    }
    bestD2[at] = d2;
    bestId[at] = id;
  }
  for (int j = 0; j < kept; ++j)
  {
    row[j] = static_cast<std::int32_t>(bestId[j]);
  }
  return true;
}

/// Outliers: points alone in their surroundings, and points farther from their neighbourhood's quadric than
/// six times the median such distance
/// (about 4 sigma for Gaussian noise) and than 5 % of the neighbourhood radius (the floor for exact data,
/// above the quadric's own O(kappa^3 R^4) misfit).
void FlagOutliers(NormalField& field)
{
  std::vector<double> residuals, distances;
  const size_t n = field.Valid.size();
  for (size_t i = 0; i < n; ++i)
  {
    if (field.Valid[i])
    {
      residuals.push_back(field.Residual[i]);
      distances.push_back(field.NeighborDistance[i]);
    }
  }
  const double threshold = std::max(6.0 * Median(residuals), 0.05 * Median(distances));
  const int k = field.GraphDegree;
  for (size_t i = 0; i < n; ++i)
  {
    if (!field.Valid[i])
    {
      continue;
    }
    // Isolated: its k-th neighbour three times farther than its nearest neighbours' (a sparse region of a
    // scan has sparse neighbours too, so only points alone in their surroundings qualify).
    double around = 0.0;
    int counted = 0;
    for (int j = 0; j < k; ++j)
    {
      const std::int32_t v = field.Graph[i * k + j];
      if (v >= 0)
      {
        around += field.NeighborDistance[v];
        ++counted;
      }
    }
    const bool isolated = counted > 0 && field.NeighborDistance[i] > 3.0 * around / counted;
    if (isolated || field.Residual[i] > threshold)
    {
      field.Outlier[i] = 1;
      ++field.OutlierCount;
    }
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
  // Per-thread query buffers of both loops below.
  struct Buffers
  {
    std::vector<Index> Ids, Positions;
    std::vector<double> Dist2;
  };
  PerThread<Buffers> buffers;
  ParallelFor(samples, 16, [&](Index begin, Index end) {
    Buffers& mine = buffers.Local();
    std::vector<Index>& ids = mine.Ids;
    std::vector<double>& d2 = mine.Dist2;
    std::vector<Index>& pos = mine.Positions;
    for (Index j = begin; j < end; ++j)
    {
      const Index s = j * nv / samples;
      const double* x = sorted + 3 * s;
      const int found = NearestDistinct(grid, x, k, ids, d2, kth[j]);
      if (found < 4 || !(kth[j] > 0.0))
      {
        kth[j] = 0.0;
        continue;
      }
      grid.FindWithinRadiusPositions(x, kth[j], pos, d2);
      const LocalPCA pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, kth[j], false);
      spread[j] = pca.Valid ? std::sqrt(pca.Eigenvalues[0]) : 0.0;
    }
  });
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
    ParallelFor(samples, 16, [&](Index begin, Index end) {
      std::vector<Index>& pos = buffers.Local().Positions;
      std::vector<double>& d2 = buffers.Local().Dist2;
      for (Index j = begin; j < end; ++j)
      {
        const double* x = sorted + 3 * (j * nv / samples);
        grid.FindWithinRadiusPositions(x, radius, pos, d2);
        const LocalPCA pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, radius, false);
        spread[j] = pca.Valid ? std::sqrt(pca.Eigenvalues[0]) : 0.0;
      }
    });
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
  field.Residual.assign(static_cast<size_t>(n), 0.0);
  field.Outlier.assign(static_cast<size_t>(n), 0);
  field.OutlierCount = 0;
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
  const bool adaptive = !fixed && options.AdaptToNoise && options.Confidence > 0.0;
  // One query a little wider than the typical radius usually holds the k nearest, which saves the k-nearest
  // search (a third of the normals' time on noise-free clouds).
  const double typical = field.Scale.Spacing / std::sqrt(Pi / std::max(3, options.NeighborCount));
  const double first = fixed ? options.SupportRadius
    : adaptive               ? 1.1 * TopScale * std::max(typical, noiseRadius)
    : noiseRadius > 0.0      ? noiseRadius
                             : 1.1 * typical;
  const double* sorted = grid.SortedPoints();
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  const Index chunk = 65536;
  Index invalid = n - nv;
  bool aborted = false;
  struct Buffers
  {
    std::vector<Index> Ids, Positions;
    std::vector<double> Dist2, Radius2, Keys;
    AdaptiveJetScratch Jet;
  };
  PerThread<Buffers> buffers;
  for (Index begin = 0; begin < nv && !aborted; begin += chunk)
  {
    const Index end = std::min(nv, begin + chunk);
    const Index bad = ParallelReduce(end - begin, 256, Index(0),
      [&](Index b0, Index b1) {
        Buffers& mine = buffers.Local();
        std::vector<Index>& ids = mine.Ids;
        std::vector<Index>& pos = mine.Positions;
        std::vector<double>& d2 = mine.Dist2;
        std::vector<double>& r2 = mine.Radius2;
        std::vector<double>& keys = mine.Keys;
        Index failed = 0;
        for (Index s = begin + b0; s < begin + b1; ++s)
        {
          const Index id = order[s];
          const double* x = sorted + 3 * s;
          std::int32_t* row = &field.Graph[static_cast<size_t>(id) * degree];
          // One radius query, wide enough for every radius the point may need, usually holds its k nearest too:
          // it gives r_k, the orientation graph and the neighbourhood. Otherwise a k-nearest query first.
          if (first > 0.0)
          {
            grid.FindWithinRadiusPositions(x, first, pos, r2);
          }
          double queried = first;
          if (!(first > 0.0 && NearestOfList(pos, r2, k, order, row, degree, field.NeighborDistance[id], keys)))
          {
            const int found = NearestDistinct(grid, x, k, ids, d2, field.NeighborDistance[id]);
            int kept = 0;
            for (int j = 0; j < found && kept < degree; ++j)
            {
              if (d2[j] > 0.0)
              {
                row[kept++] = static_cast<std::int32_t>(ids[j]);
              }
            }
            queried = 0.0;
          }
          const double rk = field.NeighborDistance[id];
          // The radius this point needs: fixed; r_k (no adaptation); or the adaptive jet's largest radius.
          const double radius = fixed ? options.SupportRadius
            : adaptive                 ? TopScale * std::max(rk, noiseRadius)
                                       : std::max(rk, noiseRadius);
          if (queried < radius)
          {
            grid.FindWithinRadiusPositions(x, radius, pos, r2);
          }
          else if (queried > radius)
          {
            // The neighbourhood is the points within the radius, as a query at it would give them.
            const double cut = radius * radius;
            size_t kept = 0;
            for (size_t j = 0; j < pos.size(); ++j)
            {
              if (r2[j] <= cut)
              {
                pos[kept] = pos[j];
                r2[kept++] = r2[j];
              }
            }
            pos.resize(kept);
            r2.resize(kept);
          }
          LocalPCA pca;
          double used = radius;
          if (adaptive)
          {
            AdaptiveJetOptions jet;
            jet.Noise = field.Scale.Noise;
            jet.Gamma = options.Confidence;
            jet.FrameRadius = std::max(rk, noiseRadius);
            jet.SmallestRadius = SmallestScale * rk;
            jet.LargestRadius = radius;
            const AdaptiveJetResult a = AdaptiveJetNormal(sorted, pos, r2, x, jet, mine.Jet);
            std::copy(a.Normal, a.Normal + 3, pca.Normal);
            std::copy(a.Eigenvalues, a.Eigenvalues + 3, pca.Eigenvalues);
            pca.Residual = a.Residual;
            pca.Valid = a.Valid;
            used = a.Radius;
          }
          else
          {
            // Where the noise sets the radius, the quadric's exactness is below the noise's tilt: PCA suffices.
            const bool jet = fixed || !(noiseRadius > rk);
            pca = PrincipalAxes(sorted, pos.data(), pos.size(), x, radius, jet);
          }
          if (!pca.Valid)
          {
            ++failed;
            continue;
          }
          for (int a = 0; a < 3; ++a)
          {
            field.Normals[3 * id + a] = pca.Normal[a];
          }
          field.Residual[id] = pca.Residual;
          const double total = pca.Eigenvalues[0] + pca.Eigenvalues[1] + pca.Eigenvalues[2];
          field.SurfaceVariation[id] = total > 0.0 ? pca.Eigenvalues[0] / total : 0.0;
          field.Radii[id] = used;
          field.Valid[id] = 1;
        }
        return failed;
      },
      [](Index a, Index b) { return a + b; });
    invalid += bad;
    aborted = progress && !progress(static_cast<double>(end) / static_cast<double>(nv));
  }
  field.InvalidCount = invalid;
  if (!aborted)
  {
    FlagOutliers(field);
  }
  return !aborted && invalid < n;
}

std::vector<double> FitSupports(
  const NormalField& field, double supportScale, double noiseScale, bool fixedRadius, double& median)
{
  const size_t n = field.Radii.size();
  std::vector<double> support(n, 0.0);
  for (size_t i = 0; i < n; ++i)
  {
    if (!(field.Radii[i] > 0.0) || field.Outlier[i])
    {
      continue;
    }
    support[i] = fixedRadius ? supportScale * field.Radii[i]
                             : std::max(supportScale * field.NeighborDistance[i], noiseScale * field.Scale.Radius);
  }
  std::vector<double> positive;
  positive.reserve(n);
  for (double r : support)
  {
    if (r > 0.0)
    {
      positive.push_back(r);
    }
  }
  median = Median(positive);
  for (double& r : support)
  {
    r = std::min(r, 3.0 * median);
  }
  return support;
}

} // namespace meshfree
