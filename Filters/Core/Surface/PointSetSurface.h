// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::PointSetSurface
 * @brief The MLS point-set surface of an oriented cloud: algebraic point-set surfaces (APSS, Guennebaud &
 *        Gross 2007), a moving fit of an algebraic sphere to the points and their normals.
 *
 * At an evaluation point x, with neighbours p_i, unit normals n_i and weights w_i = theta(|p_i - x| / h_i)
 * (Wendland, per-point support h_i), in coordinates d_i = (p_i - x) / H (shifted to x and scaled by the query
 * radius H, so clouds far from the origin or at extreme scales lose nothing) and normalised weights
 * w~_i = w_i / sum w:
 *
 *   s(d) = u0 + u_l . d + u_q |d|^2,
 *   u_q = 1/2 (sum w~ d.n - (sum w~ d).(sum w~ n)) / (sum w~ |d|^2 - |sum w~ d|^2)
 *   u_l = sum w~ n - 2 u_q sum w~ d,       u0 = -u_l . sum w~ d - u_q sum w~ |d|^2
 *
 * (research/surface.md §1). The field is the signed distance from x to that sphere, in the form that stays
 * stable as the sphere flattens into a plane (u_q -> 0):
 *
 *   f(x) = H * 2 u0 / (|u_l| + sqrt(|u_l|^2 - 4 u0 u_q)),
 *
 * negative inside (the normals point outward), with the sphere's gradient u_l / |u_l| as its direction. The
 * sphere reproduces spheres and planes exactly. Its mean curvature at the surface is 2 u_q / (|u_l| H)
 * (positive where the surface is convex).
 *
 * Fallback chain: a support whose spread vanishes (all neighbours on one point) gives the plane u_q = 0;
 * fewer than MinimumNeighbors weighted neighbours, normals that cancel (|u_l| tiny: both sides of a thin
 * sheet) or a negative discriminant far from the surface give "undefined", never a made-up value.
 * Neighbours whose normal opposes the support's mean normal (the far side of a sheet thinner than the
 * support) are dropped before the fit (RIMLS's normal term, research §4 "Thin features").
 *
 * Neighbour queries in tiers: the supports of a scan spread widely (bunny: median 1.9e-3, 90th percentile
 * 2.4e-3, largest 5.8e-3), and one query with the largest support gathered about 9 times the points that carry
 * weight. The samples are split at the 50th, 90th and 99th percentiles of their supports, each tier in a grid
 * of its own queried with its largest support, when that gathers clearly fewer points than one query (a cloud
 * of uniform density keeps the single query). The same samples, the same weights.
 */
#ifndef meshfree_PointSetSurface_h
#define meshfree_PointSetSurface_h

#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"
#include "Surface/ImplicitField.h"

#include <vector>

namespace meshfree
{

/// The algebraic sphere fitted at one point, in world units.
struct SphereFit
{
  double Distance = 0.0;   // signed distance from the evaluation point to the sphere (negative inside)
  double Direction[3] = { 0.0, 0.0, 1.0 }; // unit gradient of the sphere at the evaluation point
  double Curvature = 0.0;  // mean curvature of the sphere (1 / radius, + convex), 0 for a plane
  int Neighbors = 0;       // weighted neighbours used
};

class PointSetSurface : public ImplicitField
{
public:
  /// The cloud: `grid` built over n points, their unit outward normals and support radii h_i (both in the
  /// caller's point order; copied into the grid's sorted order). Points without a valid normal (a zero or
  /// non-finite vector) or radius are ignored.
  /// Distributed (d, Common/Distribution.h): the grid holds a process' points and their halo, framed by the whole
  /// cloud; the tiers are the whole cloud's (their percentiles over every process' points, their grids framed by
  /// every process' tier points), so that a fit lists its neighbours as the serial run does.
  void SetCloud(const NeighborGrid& grid, const double* normals, const double* radii, const Distribution* d = nullptr);

  /// Fits need at least this many weighted neighbours (default 6).
  void SetMinimumNeighbors(int count) { this->MinimumNeighbors = count < 3 ? 3 : count; }

  /// The sphere fitted at x. False where undefined (see the class comment).
  bool Fit(const double x[3], SphereFit& fit, FieldScratch& scratch) const;

  /// f(x) = the fitted sphere's signed distance; the gradient is its unit direction, so Project() is the MLS
  /// projection (move onto the sphere fitted at x, refit there, repeat).
  bool Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& scratch) const override;

  /// Largest support radius of the cloud (the neighbour query's radius).
  double MaximumRadius() const { return this->QueryRadius; }

  /// The narrowest tier's radius (the median support, or the largest with a single tier): every sample within
  /// it of x is in the scratch after Fit().
  double NarrowRadius() const { return this->NearRadius; }

private:
  /// The neighbours of x in the fit's support (both tiers) into scratch.Positions / Dist2 (sorted positions of
  /// the cloud's grid).
  void Gather(const double x[3], FieldScratch& scratch) const;
  const NeighborGrid* Grid = nullptr;
  struct Tier
  {
    NeighborGrid Grid;          // the samples whose support is in this tier
    std::vector<Index> Positions; // Grid's sorted position -> the cloud grid's sorted position
    double Radius = 0.0;        // the tier's largest support
  };
  std::vector<Tier> Tiers;      // empty: one query of the cloud's grid with the largest support
  double NearRadius = 0.0;
  std::vector<double> Normals; // sorted order, 3 per point
  std::vector<double> InverseRadii; // sorted order; +inf for ignored points
  double QueryRadius = 0.0;
  int MinimumNeighbors = 6;
};

} // namespace meshfree

#endif
