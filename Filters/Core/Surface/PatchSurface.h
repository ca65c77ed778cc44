// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::PatchSurface
 * @brief The WLS surface: a partition of unity of local weighted least-squares fits (Ohtake et al. 2003,
 *        "Multi-level partition of unity implicits", single level; thesis 3.16-3.21 for PU-WLS).
 *
 * Patches: one per occupied cell of a coarse grid of edge rho/2 (rho the median fit support of the cloud):
 * its centre c is the mean of the cell's points, its frame (t1, t2, n) has n = the mean of their outward
 * normals. Over the points within rho of c, weighted by Wendland(|p - c| / rho), it fits the height
 * h = g(u, v) of degree 2 in the frame's coordinates (u, v, h) = ((p - c) . (t1, t2, n)) / rho - shifted and
 * scaled, solved by the equilibrated rank-revealing moment solve of LocalFit.h (SolveMoment); degenerate fits
 * fall back to degree 1, then 0, then the patch is dropped. Its local field is the height above the fitted
 * graph, divided by sqrt(1 + |grad g|^2) (a first-order distance):
 *
 *   Q_c(x) = rho (h - g(u, v)) / sqrt(1 + g_u^2 + g_v^2),     f(x) = sum_c w_c(x) Q_c(x) / sum_c w_c(x),
 *
 * w_c = Wendland(|x - c| / rho). The fit is done once per patch, not per evaluation point: evaluation visits
 * the few patches within rho instead of every neighbour point, which makes WLS cheaper than MLS; a quadric
 * per patch also follows curvature without the plane's O(kappa rho^2) bias. Undefined where no patch reaches.
 *
 * Thin parts: where a sheet is thinner than rho, the patches of its two sides reach the same points, and
 * blending a side's distance (0 on it) with the other side's (minus the thickness there) moved both faces
 * outward (a slab 0.06 thick, rho 0.09: faces 6.8 sigma off, volume +6 %). The patches whose normal is more
 * than 120 degrees from the heaviest patch's are the other side: each side is blended on its own and the heavier
 * one taken (inside the sheet both are negative, so the switch adds no zero; the MLS fit splits its neighbours
 * the same way, PointSetSurface.h).
 */
#ifndef meshfree_PatchSurface_h
#define meshfree_PatchSurface_h

#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"
#include "Surface/ImplicitField.h"

#include <vector>

namespace meshfree
{

class PatchSurface : public ImplicitField
{
public:
  /// The cloud as for PointSetSurface::SetCloud(): grid, unit outward normals and fit supports (caller's
  /// order; points with a zero normal or radius are ignored). Distributed (d, as PointSetSurface::SetCloud()): the
  /// patch radius is the whole cloud's median support and the patches' cells the frame's, so the patches near a
  /// process' own points are the serial ones.
  void SetCloud(const NeighborGrid& grid, const double* normals, const double* radii, const Distribution* d = nullptr);

  bool Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& scratch) const override;

  Index NumberOfPatches() const { return static_cast<Index>(this->Radius.size()); }

private:
  NeighborGrid Centres;          // the patches' centres
  std::vector<double> Frames;    // 9 per patch, rows t1, t2, n (patch order = Centres' input order)
  std::vector<double> Heights;   // 6 coefficients per patch: 1, u, v, u^2, uv, v^2 (scaled coordinates)
  std::vector<double> Radius;    // rho per patch
  std::vector<double> Positions; // 3 per patch
  double QueryRadius = 0.0;
};

} // namespace meshfree

#endif
