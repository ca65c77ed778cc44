// SPDX-License-Identifier: BSD-3-Clause
#include "Surface/CloudNormals.h"

#include "Common/LargeArrays.h"
#include "Common/Parallel.h"
#include "Surface/PointSetSurface.h"
#include "Surface/UniqueCloud.h"

#include <algorithm>
#include <memory>
#include <cmath>
#include <cstdint>

namespace meshfree
{

namespace
{
/// The results of the distinct points given to every input point (invalid coordinates: invalid results).
void ExpandDuplicates(const CloudNormalsResult& distinct, const UniqueCloud& unique, Index n, CloudNormalsResult& result)
{
  detail::AssignLarge(result.Normals, static_cast<size_t>(3 * n), 0.0);
  detail::AssignLarge(result.Curvature, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(result.SurfaceVariation, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(result.Confidence, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(result.Radius, static_cast<size_t>(n), 0.0);
  detail::AssignLarge(result.Valid, static_cast<size_t>(n), static_cast<unsigned char>(0));
  result.Invalid = 0;
  for (Index i = 0; i < n; ++i)
  {
    const Index u = unique.Unique[i];
    if (u < 0)
    {
      ++result.Invalid;
      continue;
    }
    std::copy(&distinct.Normals[3 * u], &distinct.Normals[3 * u] + 3, &result.Normals[3 * i]);
    std::copy(&distinct.Points[3 * u], &distinct.Points[3 * u] + 3, &result.Points[3 * i]);
    result.Curvature[i] = distinct.Curvature[u];
    result.SurfaceVariation[i] = distinct.SurfaceVariation[u];
    result.Confidence[i] = distinct.Confidence[u];
    result.Radius[i] = distinct.Radius[u];
    result.Valid[i] = distinct.Valid[u];
    result.Invalid += distinct.Valid[u] ? 0 : 1;
  }
  result.Scale = distinct.Scale;
  result.Orientation = distinct.Orientation;
  result.Projected = distinct.Projected;
  result.Outliers = distinct.Outliers;
  result.Duplicates = unique.Duplicates;
  result.Shortfall = distinct.Shortfall;
  result.Aborted = distinct.Aborted;
}
/// Rounds of averaging of the jets' curvature over the orientation graph (see SmoothJetCurvature).
constexpr int CurvatureRounds = 24;
/// Graph neighbours whose normals differ by more than acos(CurvatureAgreement) (a crease, the other side of a thin
/// part) are left out of the averages.
constexpr double CurvatureAgreement = 0.5;

/// Curvature: the jets' mean curvature (field.MeanCurvature, along the normals as estimated, `unoriented`) signed
/// along the oriented normals, then CurvatureRounds rounds of averaging each point's value with its graph
/// neighbours' (field.Graph: its GraphDegree nearest; outliers and those across a crease or a thin part left
/// out). A noisy
/// cloud's jets take at most 256 of their neighbours, each a different spread subset: their curvatures' noise is
/// largely independent from one point to the next, while the rounds reach a few spacings (the jets' radius is many
/// more): they take out most of the noise and keep exactness on spheres (see CloudNormals.h; 8 rounds left the
/// 50k-point noisy sphere of TestSurfaceNormals' NoisyCurvatureAndItsSign behind the sphere fits, 24 put it
/// ahead at about 0.4 CPU s per 1M points; exact data pay a little smoothing: torus 0.2 -> 0.5 % mean error). In the grid's order
/// (neighbours near in memory), the graph translated to it once. 0 where invalid.
void SmoothJetCurvature(const NeighborGrid& grid, const NormalField& field, const std::vector<double>& unoriented,
  const Distribution* d, std::vector<double>& curvature)
{
  const Index n = static_cast<Index>(field.Valid.size());
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  const int degree = field.GraphDegree;
  detail::Buffer<std::int32_t> rank(static_cast<size_t>(n), -1);
  ParallelFor(nv, 4096, [&](Index b0, Index b1) {
    for (Index s = b0; s < b1; ++s)
    {
      rank[order[s]] = static_cast<std::int32_t>(s);
    }
  });
  // Per sorted position: the value signed along the oriented normal, and the neighbours that take part (their
  // number, the point included, in `count`). A row's unused entries point to the slot after the last position,
  // which holds -0.0: x + (-0.0) is x for every x (-0.0 too), so that every row sums `degree` terms without a branch
  // and the same bits as its neighbours alone.
  const std::int32_t none = static_cast<std::int32_t>(nv);
  std::vector<double> k, next; // std::vector: UpdateHaloInOrder's
  detail::AssignLarge(k, static_cast<size_t>(nv) + 1, 0.0);
  detail::AssignLarge(next, static_cast<size_t>(nv) + 1, 0.0);
  k[nv] = next[nv] = -0.0;
  detail::Buffer<std::int32_t> graph(static_cast<size_t>(nv) * degree, none);
  detail::Buffer<std::int32_t> count(static_cast<size_t>(nv), 1);
  ParallelFor(nv, 4096, [&](Index b0, Index b1) {
    for (Index s = b0; s < b1; ++s)
    {
      const Index i = order[s];
      if (!field.Valid[i])
      {
        continue;
      }
      const double* a = &unoriented[3 * i];
      const double* ni = &field.Normals[3 * i];
      const double value = field.MeanCurvature[i];
      k[s] = a[0] * ni[0] + a[1] * ni[1] + a[2] * ni[2] < 0.0 ? -value : value;
      int kept = 0;
      for (int j = 0; j < degree; ++j)
      {
        const std::int32_t v = field.Graph[static_cast<size_t>(i) * degree + j];
        if (v < 0 || !field.Valid[v] || field.Outlier[v])
        {
          continue;
        }
        const double* nv3 = &field.Normals[3 * static_cast<size_t>(v)];
        if (ni[0] * nv3[0] + ni[1] * nv3[1] + ni[2] * nv3[2] > CurvatureAgreement)
        {
          graph[static_cast<size_t>(s) * degree + kept++] = rank[v];
        }
      }
      count[s] = 1 + kept;
    }
  });
  for (int round = 0; round < CurvatureRounds; ++round)
  {
    ParallelFor(nv, 4096, [&](Index b0, Index b1) {
      for (Index s = b0; s < b1; ++s)
      {
        const std::int32_t* row = &graph[static_cast<size_t>(s) * degree];
        double sum = k[s];
        for (int j = 0; j < degree; ++j)
        {
          sum += k[row[j]];
        }
        next[s] = sum / count[s];
      }
    });
    k.swap(next);
    if (d)
    {
      // The halo's values of this round from their owners (they average over neighbours beyond the halo).
      UpdateHaloInOrder(d, order, n, { &k });
    }
  }
  detail::AssignLarge(curvature, static_cast<size_t>(n), 0.0);
  ParallelFor(nv, 4096, [&](Index b0, Index b1) {
    for (Index s = b0; s < b1; ++s)
    {
      curvature[order[s]] = field.Valid[order[s]] ? k[s] : 0.0;
    }
  });
}
} // namespace

bool ComputeCloudNormals(const double* xyz, Index n, const double* referenceNormals, const CloudNormalsOptions& options,
  CloudNormalsResult& result, const ProgressCallback& progress)
{
  const Distribution* d = options.Neighborhood.Processes;
  result = CloudNormalsResult();
  detail::ReserveLarge(result.Points, static_cast<size_t>(3 * std::max<Index>(n, 0)));
  result.Points.assign(xyz, xyz + 3 * std::max<Index>(n, 0));
  NeighborGrid grid;
  if (options.Framed)
  {
    grid.SetFrame(options.FrameBounds, options.FramePoints);
  }
  grid.Build(xyz, n);
  UniqueCloud unique;
  std::unique_ptr<DistinctDistribution> processes;
  // Whether any process has duplicates: then all compute on their distinct points (collectively).
  if (MergeDuplicates(grid, xyz, referenceNormals, n, d, unique, processes, unique.Duplicates))
  {
    // Computed on the distinct points, in the same frame; every duplicate gets its representative's results.
    CloudNormalsOptions distinctOptions = options;
    distinctOptions.Framed = true;
    grid.GetFrame(distinctOptions.FrameBounds, distinctOptions.FramePoints);
    distinctOptions.Neighborhood.Processes = processes ? processes.get() : d;
    CloudNormalsResult distinct;
    const bool done = ComputeCloudNormals(unique.Points.data(), static_cast<Index>(unique.Points.size() / 3),
      referenceNormals ? unique.Normals.data() : nullptr, distinctOptions, distinct, progress);
    ExpandDuplicates(distinct, unique, n, result);
    if (d)
    {
      result.Invalid = 0;
      for (Index i = 0; i < n; ++i)
      {
        result.Invalid += IsOwn(d, i) && !result.Valid[i] ? 1 : 0;
      }
    }
    return done;
  }
  NormalField field;
  // Aborting is local: a distributed computation goes on through every collective step and is discarded at the end.
  bool aborted = false;
  auto stop = [&progress, &aborted](double f) {
    aborted = aborted || (progress && !progress(f));
    return aborted;
  };
  const auto stage = [&progress](double begin, double end) -> ProgressCallback {
    if (!progress)
    {
      return ProgressCallback();
    }
    return [progress, begin, end](double f) { return progress(begin + (end - begin) * f); };
  };
  // The curvature from the normals' own jets (a second, sphere-exact jet over the same neighbours), unless the
  // points are projected: then from the spheres fitted at the projected points, as the projection fits them anyway.
  const bool jetCurvature = options.ComputeCurvature && !options.ProjectPoints;
  NormalOptions neighborhood = options.Neighborhood;
  neighborhood.MeanCurvature = jetCurvature;
  const bool estimated = EstimateNormals(grid, neighborhood, field, stage(0.0, 0.5));
  result.Scale = field.Scale;
  result.Shortfall = field.Shortfall;
  if (!estimated && stop(0.5) && !d)
  {
    result.Aborted = true;
    return false;
  }
  OrientationOptions orientation;
  orientation.Mode = options.Orientation;
  std::copy(options.Viewpoint, options.Viewpoint + 3, orientation.Viewpoint);
  orientation.Reference = referenceNormals;
  orientation.Processes = d;
  if (orientation.Mode == OrientationMode::Reference && !referenceNormals)
  {
    orientation.Mode = OrientationMode::Propagation;
  }
  // The jets' curvature is signed along the normals as estimated: kept to compare with the oriented ones.
  std::vector<double> unoriented;
  if (jetCurvature)
  {
    detail::ReserveLarge(unoriented, field.Normals.size());
    unoriented.assign(field.Normals.begin(), field.Normals.end());
  }
  result.Orientation = OrientNormals(grid, field, orientation, result.Confidence);
  result.Shortfall = std::max(result.Shortfall, result.Orientation.Shortfall);
  detail::AssignLarge(result.Curvature, static_cast<size_t>(n), 0.0);
  if (jetCurvature)
  {
    SmoothJetCurvature(grid, field, unoriented, d, result.Curvature);
  }
  if (stop(0.6) && !d)
  {
    result.Aborted = true;
    return false;
  }

  // The projection (and then the curvature) from the algebraic spheres fitted over the oriented cloud.
  const bool fits = options.ProjectPoints;
  double median = 0.0;
  PointSetSurface surface;
  if (fits)
  {
    const std::vector<double> support = FitSupports(field, options.SupportScale, options.NoiseScale,
      options.Neighborhood.SupportRadius > 0.0, median, d);
    surface.SetCloud(grid, field.Normals.data(), support.data(), d);
    // A projection moves a point at most one support and queries one support around it there.
    for (Index i = 0; d && i < n; ++i)
    {
      if (field.Valid[i] && IsOwn(d, i))
      {
        result.Shortfall = std::max(result.Shortfall, Shortfall(d, xyz + 3 * i, 2.0 * 3.0 * median));
      }
    }
  }
  // In the grid's (Morton) order: neighbouring points share their neighbours in cache (at 1M points twice as
  // fast as the input's order when that is random).
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  const Index chunk = 65536;
  Index projected = 0;
  PerThread<FieldScratch> scratch;
  for (Index begin = 0; fits && begin < nv && !aborted; begin += chunk)
  {
    const Index end = std::min(nv, begin + chunk);
    projected += ParallelReduce(end - begin, 256, Index(0),
      [&](Index b0, Index b1) {
        FieldScratch& fs = scratch.Local();
        Index count = 0;
        for (Index s = begin + b0; s < begin + b1; ++s)
        {
          const Index i = order[s];
          if (!field.Valid[i] || !IsOwn(d, i))
          {
            continue;
          }
          double* x = &result.Points[3 * i];
          double* normal = &field.Normals[3 * i];
          if (options.ProjectPoints)
          {
            double moved[3] = { x[0], x[1], x[2] }, direction[3];
            if (surface.Project(moved, direction, median, std::max(1, options.ProjectionIterations), fs))
            {
              std::copy(moved, moved + 3, x);
              std::copy(direction, direction + 3, normal);
              ++count;
            }
          }
          SphereFit fit;
          if (options.ComputeCurvature && surface.Fit(x, fit, fs))
          {
            result.Curvature[i] = fit.Curvature;
          }
        }
        return count;
      },
      [](Index a, Index b) { return a + b; });
    stop(0.6 + 0.4 * static_cast<double>(end) / static_cast<double>(nv));
  }
  if (d)
  {
    // The halo's final values from their owners (a distinct point's duplicates may be another process' own).
    UpdateHalo(d, result.Points, 3);
    UpdateHalo(d, field.Normals, 3);
    UpdateHalo(d, result.Curvature);
    UpdateHalo(d, result.Confidence);
  }
  result.Projected = projected;
  result.Normals = std::move(field.Normals);
  result.SurfaceVariation = std::move(field.SurfaceVariation);
  result.Radius = std::move(field.Radii);
  result.Valid = std::move(field.Valid);
  result.Invalid = field.InvalidCount;
  result.Outliers = field.OutlierCount;
  result.Aborted = aborted;
  return !aborted;
}

} // namespace meshfree
