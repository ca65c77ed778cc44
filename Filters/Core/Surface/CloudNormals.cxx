// SPDX-License-Identifier: BSD-3-Clause
#include "Surface/CloudNormals.h"

#include "Common/Parallel.h"
#include "Surface/PointSetSurface.h"
#include "Surface/UniqueCloud.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{

namespace
{
/// The results of the distinct points given to every input point (invalid coordinates: invalid results).
void ExpandDuplicates(const CloudNormalsResult& distinct, const UniqueCloud& unique, Index n, CloudNormalsResult& result)
{
  result.Normals.assign(static_cast<size_t>(3 * n), 0.0);
  result.Curvature.assign(static_cast<size_t>(n), 0.0);
  result.SurfaceVariation.assign(static_cast<size_t>(n), 0.0);
  result.Confidence.assign(static_cast<size_t>(n), 0.0);
  result.Radius.assign(static_cast<size_t>(n), 0.0);
  result.Valid.assign(static_cast<size_t>(n), 0);
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
  result.Aborted = distinct.Aborted;
}
} // namespace

bool ComputeCloudNormals(const double* xyz, Index n, const double* referenceNormals, const CloudNormalsOptions& options,
  CloudNormalsResult& result, const ProgressCallback& progress)
{
  result = CloudNormalsResult();
  result.Points.assign(xyz, xyz + 3 * std::max<Index>(n, 0));
  NeighborGrid grid;
  grid.Build(xyz, n);
  UniqueCloud unique;
  if (MergeDuplicates(grid, xyz, referenceNormals, unique))
  {
    // Computed on the distinct points; every duplicate gets its representative's results.
    CloudNormalsResult distinct;
    const bool done = ComputeCloudNormals(unique.Points.data(), static_cast<Index>(unique.Points.size() / 3),
      referenceNormals ? unique.Normals.data() : nullptr, options, distinct, progress);
    ExpandDuplicates(distinct, unique, n, result);
    return done;
  }
  NormalField field;
  const auto stage = [&progress](double begin, double end) -> ProgressCallback {
    if (!progress)
    {
      return ProgressCallback();
    }
    return [progress, begin, end](double f) { return progress(begin + (end - begin) * f); };
  };
  const bool estimated = EstimateNormals(grid, options.Neighborhood, field, stage(0.0, 0.5));
  result.Scale = field.Scale;
  if (!estimated && progress && !progress(0.5))
  {
    result.Aborted = true;
    return false;
  }
  OrientationOptions orientation;
  orientation.Mode = options.Orientation;
  std::copy(options.Viewpoint, options.Viewpoint + 3, orientation.Viewpoint);
  orientation.Reference = referenceNormals;
  if (orientation.Mode == OrientationMode::Reference && !referenceNormals)
  {
    orientation.Mode = OrientationMode::Propagation;
  }
  result.Orientation = OrientNormals(grid, field, orientation, result.Confidence);
  if (progress && !progress(0.6))
  {
    result.Aborted = true;
    return false;
  }

  // Curvature (and the projection) from the algebraic spheres fitted over the oriented cloud.
  const bool fits = options.ComputeCurvature || options.ProjectPoints;
  double median = 0.0;
  PointSetSurface surface;
  if (fits)
  {
    const std::vector<double> support = FitSupports(field, options.SupportScale, options.NoiseScale,
      options.Neighborhood.SupportRadius > 0.0, median);
    surface.SetCloud(grid, field.Normals.data(), support.data());
  }
  result.Curvature.assign(static_cast<size_t>(n), 0.0);
  // In the grid's (Morton) order: neighbouring points share their neighbours in cache (at 1M points twice as
  // fast as the input's order when that is random).
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  const Index chunk = 65536;
  bool aborted = false;
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
          if (!field.Valid[i])
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
    aborted = progress && !progress(0.6 + 0.4 * static_cast<double>(end) / static_cast<double>(nv));
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
