// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Everything "Meshless Normals" computes for a cloud: consistently oriented unit normals
 *        (SurfaceNormals.h, NormalOrientation.h), the mean curvature and, on request, the points moved onto
 *        their MLS surface (MLS projection, denoising as PCL's MovingLeastSquares does).
 *
 * Curvature is the mean curvature of the algebraic sphere fitted at the point (PointSetSurface.h):
 * 1 / radius, positive where the surface is convex (outward normals), in 1 / length; exact on spheres.
 * Projection moves each point onto the sphere fitted at it and refits there (ProjectionIterations times,
 * at most one fit support away); the normal and curvature are then those at the projected point.
 * The curvature's fits cost about as much as the normals and their orientation together (their support
 * is twice the normals' where noise sets it): ComputeCurvature off skips them.
 * Orientation: reference normals when given (the input's own `Normals`), else propagation or a viewpoint.
 */
#ifndef meshfree_CloudNormals_h
#define meshfree_CloudNormals_h

#include "Common/Progress.h"
#include "Surface/NormalOrientation.h"
#include "Surface/SurfaceNormals.h"

#include <vector>

namespace meshfree
{

struct CloudNormalsOptions
{
  NormalOptions Neighborhood;
  OrientationMode Orientation = OrientationMode::Propagation; // Reference needs ReferenceNormals
  double Viewpoint[3] = { 0.0, 0.0, 0.0 };
  bool ComputeCurvature = true; // off: no sphere fits (unless ProjectPoints), Curvature stays 0
  bool ProjectPoints = false;
  int ProjectionIterations = 2;
  double SupportScale = 2.0; // fits for curvature and projection: as SurfaceOptions
  double NoiseScale = 2.0;
};

struct CloudNormalsResult
{
  std::vector<double> Normals;          // 3 per point, unit, oriented; 0 where invalid
  std::vector<double> Curvature;        // mean curvature (1 / length); 0 where no sphere could be fitted
  std::vector<double> SurfaceVariation; // l0 / (l0 + l1 + l2) of the PCA
  std::vector<double> Confidence;       // orientation confidence, see NormalOrientation.h
  std::vector<double> Radius;           // neighbourhood radius of the normal
  std::vector<unsigned char> Valid;
  std::vector<double> Points;           // the projected points (ProjectPoints), else the input's
  CloudScale Scale;
  OrientationReport Orientation;
  Index Invalid = 0;                    // points without a normal (NaN coordinates, degenerate neighbourhoods)
  Index Projected = 0;
  Index Outliers = 0;                   // flagged by SurfaceNormals.h: kept, but left out of the fits
  Index Duplicates = 0;                 // exact duplicates: computed once, copied (UniqueCloud.h)
  bool Aborted = false;
};

/// n points (3 per point); reference normals (3 per point) or null. Returns false when aborted.
bool ComputeCloudNormals(const double* xyz, Index n, const double* referenceNormals, const CloudNormalsOptions& options,
  CloudNormalsResult& result, const ProgressCallback& progress = ProgressCallback());

} // namespace meshfree

#endif
