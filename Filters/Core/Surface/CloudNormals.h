// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Everything "Meshless Normals" computes for a cloud: consistently oriented unit normals
 *        (SurfaceNormals.h, NormalOrientation.h), the mean curvature and, on request, the points moved onto
 *        their MLS surface (MLS projection, denoising as PCL's MovingLeastSquares does).
 *
 * Curvature is the mean curvature, in 1 / length, positive where the surface is convex with respect to the
 * oriented normals (outward: positive on a sphere), exact on spheres. Without projection it comes from the
 * normals' own neighbourhoods: each normal's jet is fitted a second time with u^2, v^2 completed to
 * u^2 + h^2 / 2, v^2 + h^2 / 2 (a sphere in any frame is such a jet: exact on spheres; SurfaceNormals.h
 * NormalOptions::MeanCurvature), the curvature of that implicit surface at the point is signed along the oriented
 * normal and averaged over the orientation graph's neighbours (24 rounds; neighbours whose normals differ by more
 * than 60 degrees left out, and outliers), which takes out most of the noise of the jets' 256-point subsets. It
 * costs 10-20 % of the normals' time (1-2 of 8-9 CPU s at 1M points; the sphere fits that gave the curvature
 * before cost as much as the normals and their orientation: 4.5-7.5 CPU s). Measured (BenchCloudNormals
 * --accuracy 1, sphere r 0.5 and torus 1 / 0.25, mean / p99 relative error against the exact mean curvature, the
 * sphere fits' in brackets): exact data, 200k points: sphere 1e-15 / 3e-15 (2e-6 / 7e-6), torus 0.5 / 1.8 %
 * (1.4 / 7.2 %); noise 0.1 % of the diagonal, 1M points: sphere 3.4 / 11.2 % (6.5 / 16.0 %), torus
 * 3.7 / 13.2 % (6.6 / 18.0 %); 200k points at noise 0.1, 0.3, 0.5 %: sphere 1.3 / 4.3, 1.7 / 5.5, 2.0 / 6.8 %
 * (3.5 / 9.5, 7.6 / 14.2, 10.3 / 19.1 %), torus 2.5 / 9.1, 4.9 / 15.0, 6.5 / 18.7 % (3.8 / 11.1, 7.6 / 19.0,
 * 10.5 / 26.3 %).
 * Projection moves each point onto the algebraic sphere fitted at it (PointSetSurface.h) and refits there
 * (ProjectionIterations times, at most one fit support away); the normal and the curvature (that sphere's,
 * 1 / radius) are then those at the projected point. ComputeCurvature off skips the curvature jets.
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
  bool ComputeCurvature = true; // off: no curvature jets (nor sphere fits unless ProjectPoints), Curvature stays 0
  bool ProjectPoints = false;
  int ProjectionIterations = 2;
  double SupportScale = 2.0; // the projection's sphere fits: as SurfaceOptions
  double NoiseScale = 2.0;
  // The grid's frame (NeighborGrid::SetFrame): a distributed cloud's process lays its piece and halo over the whole
  // cloud's cells (bounds and number of valid points), so that its queries list points as a serial run does.
  bool Framed = false;
  double FrameBounds[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
  Index FramePoints = 0;
};

struct CloudNormalsResult
{
  std::vector<double> Normals;          // 3 per point, unit, oriented; 0 where invalid
  std::vector<double> Curvature;        // mean curvature (1 / length); 0 where invalid or no fit succeeded
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
  double Shortfall = -HUGE_VAL;         // distributed: how far beyond the complete part of the local cloud a
                                        // query reached (Distribution.h; > 0: widen the halo by it and rerun)
  bool Aborted = false;
};

/// n points (3 per point); reference normals (3 per point) or null. Returns false when aborted.
bool ComputeCloudNormals(const double* xyz, Index n, const double* referenceNormals, const CloudNormalsOptions& options,
  CloudNormalsResult& result, const ProgressCallback& progress = ProgressCallback());

} // namespace meshfree

#endif
