// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Normals of a point cloud sampled from a surface: local PCA over a neighbourhood that follows the
 *        sampling density AND the noise, then a consistent orientation (NormalOrientation.h).
 *
 * Normal (Hoppe et al. 1992): the eigenvector of the smallest eigenvalue l0 of the neighbours' covariance,
 * computed in coordinates shifted to the point and scaled by the support radius. SurfaceVariation
 * l0 / (l0 + l1 + l2) (Pauly et al. 2002): 0 on a plane, 1/3 for isotropic scatter.
 *
 * Neighbourhood. A fixed neighbour count fails when the noise sigma is comparable to the spacing (k = 20 gives
 * 28 degrees of error at 1M points, sigma = 0.005; research/surface.md §0.2). For k neighbours in a disc of
 * radius R (k = pi R^2 / h^2, h the spacing) the normal's tilt from noise is about 2 sigma h / (sqrt(pi) R^2)
 * (research §1, first order), so keeping it below TiltTolerance needs R^2 >= 2 sigma h / (sqrt(pi) tau).
 * Each point's radius is max(r_k, R_noise): r_k the distance to its NeighborCount-th neighbour (density), and
 * R_noise from the cloud's noise, estimated on a sample of points by the spread along the normal,
 * sqrt(l0), at the radius being chosen - three rounds of (radius -> noise -> radius), since a too small
 * neighbourhood hides the noise (Mitra, Nguyen & Guibas 2004 choose the radius the same way).
 * SupportRadius > 0 replaces all of this with one fixed radius.
 *
 * Invalid normals (zero vector, Valid 0): points with NaN/Inf coordinates, and points whose neighbourhood
 * has fewer than 3 points or is collinear (l1 ~ 0). Exact duplicates of a point do not count as its
 * neighbours (they would shrink r_k without adding any sampling).
 *
 * Outliers: a point whose r_k is over 3 x the mean r_k of its nearest neighbours (alone in its surroundings;
 * a sparse region of a scan has sparse neighbours too), or farther from the quadric fitted to its neighbourhood
 * than 6 x the median of that distance
 * (about 4 sigma for Gaussian noise; with a floor of 5 % of the radius for exact data) keeps its normal but is
 * flagged, and the implicit fits leave it out (FitSupports gives it no support).
 */
#ifndef meshfree_SurfaceNormals_h
#define meshfree_SurfaceNormals_h

#include "Common/NeighborGrid.h"
#include "Common/Progress.h"

#include <cstdint>
#include <vector>

namespace meshfree
{

struct NormalOptions
{
  int NeighborCount = 20;       // the smallest neighbourhood: this many nearest other points
  double SupportRadius = 0.0;   // > 0: one fixed radius for every point (no adaptation)
  bool AdaptToNoise = true;     // widen the radius until the noise tilts normals by < TiltTolerance
  double TiltTolerance = 0.05;  // radians
  int GraphDegree = 8;          // nearest neighbours kept for the orientation graph
};

/// The cloud's sampling scale, from a sample of its points (medians).
struct CloudScale
{
  double Spacing = 0.0; // distance between neighbouring samples on the surface, r_k sqrt(pi / k)
  double Noise = 0.0;   // spread of the points about the surface, sqrt(l0) at the chosen radius
  double Radius = 0.0;  // the fits' noise radius: noise tilt < TiltTolerance (0 when the density decides)
  double FitNoise = 0.0;     // the median root mean square misfit of the normals' jets (sigma along the normal)
  double Curvature = 0.0;    // the median larger principal curvature of the normals' jets
  double NormalRadius = 0.0; // the normals' jet radius (0 when the density decides), see the file comment
};

struct NormalField
{
  std::vector<double> Normals;          // 3 per point, unit (unoriented until OrientNormals); 0 when invalid
  std::vector<double> Radii;            // neighbourhood radius used at each point: max(r_k, noise radius)
  std::vector<double> NeighborDistance; // r_k: distance to the NeighborCount-th nearest other point
  std::vector<double> SurfaceVariation; // l0 / (l0 + l1 + l2)
  std::vector<double> Residual;         // distance from the point to its neighbourhood's fitted quadric
  std::vector<unsigned char> Outlier;   // residual > max(6 x median residual, 5 % of r_k): left out of fits
  std::vector<unsigned char> Valid;
  std::vector<std::int32_t> Graph;      // GraphDegree nearest other points per point (-1 pads)
  int GraphDegree = 0;
  CloudScale Scale;
  Index InvalidCount = 0;
  Index OutlierCount = 0;
};

/// Normals of the points the grid was built over (grid.NumberOfPoints(), in their original order). Returns
/// false when aborted or when no normal could be estimated; the field is sized and defined in any case.
bool EstimateNormals(const NeighborGrid& grid, const NormalOptions& options, NormalField& field,
  const ProgressCallback& progress = ProgressCallback());

/// The scale of the cloud (also computed by EstimateNormals): spacing, noise and the radius noise asks for.
CloudScale EstimateCloudScale(const NeighborGrid& grid, const NormalOptions& options);

/// Support radii of the implicit fits over an estimated field: supportScale x r_k (bridges the gaps of
/// random sampling) but at least noiseScale x the noise radius (averages the noise), or supportScale x the
/// fixed radius when one was given; 0 for invalid points. Capped at three times their median, so that a few
/// isolated points (outliers, the noise's tails) do not widen every neighbour query. `median` receives it.
std::vector<double> FitSupports(
  const NormalField& field, double supportScale, double noiseScale, bool fixedRadius, double& median);

} // namespace meshfree

#endif
