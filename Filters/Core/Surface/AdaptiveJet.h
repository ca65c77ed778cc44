// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief The normal at a point of a noisy surface cloud from the neighbourhood radius that minimises its error:
 *        jet fits over growing radii, the radius chosen by the intersection of confidence intervals.
 *
 * A normal estimated over a radius R errs by noise and by bias. The noise tilts it by about
 * sigma / (R sqrt(N)) (N neighbours), falling with R; the bias rises with R: O(kappa R) for a plane fit (PCA) on
 * an unevenly sampled patch, O(R^2) for a degree-2 jet (Cazals & Pouget 2005), and O(1) once the neighbourhood
 * reaches across a sharp edge. The best R balances the two and differs from point to point (Mitra, Nguyen &
 * Guibas 2004 derive it from the curvature, which is itself unknown). Lepski's method finds it without knowing
 * the bias: estimate over radii R_0 < R_1 < ... (a geometric series, Shells of them), each with its standard
 * deviation s_j from the least-squares covariance, and keep growing while the confidence intervals
 * [a_j - Gamma s_j, a_j + Gamma s_j] of all radii so far still intersect (the ICI rule, Goldenshluger &
 * Nemirovski 1997; Katkovnik 1999). Growing stops where the bias starts to exceed the noise: at an edge, a
 * strongly curved part or a change of the sampling.
 *
 * The estimate at each radius is a degree-2 jet: the height h of the neighbours (the point itself left out)
 * over a plane through the point, fitted by h = a0 + a1 u + a2 v + a3 u^2 + a4 uv + a5 v^2 in coordinates
 * shifted to the point and scaled by the largest radius; the normal is n - a1 t1 - a2 t2. The plane (n, t1, t2)
 * is the PCA of the neighbours within FrameRadius: all radii share it, so their slopes (a1, a2) are comparable
 * and the intervals are taken per slope. Their variances are sigma^2 (M^-1)_11 and _22 (M the jet's moment
 * matrix), sigma the cloud's noise along the normal. The neighbours are sorted into shells by a counting sort,
 * and each shell's moments are added to the last radius' ones: the cost is that of the neighbours up to the
 * chosen radius plus one shell.
 */
#ifndef meshfree_AdaptiveJet_h
#define meshfree_AdaptiveJet_h

#include "Common/NeighborGrid.h"

#include <vector>

namespace meshfree
{

struct AdaptiveJetOptions
{
  double Noise = 0.0;        // sigma: the cloud's noise along the normal (world units)
  double Gamma = 2.0;        // interval half-width in standard deviations
  double FrameRadius = 0.0;  // the PCA plane's radius
  double SmallestRadius = 0.0; // the first radius tried (at least the NeighborCount-th neighbour's distance)
  double LargestRadius = 0.0;  // the last radius tried (the query's radius)
  double Ratio = 1.189207115002721; // between consecutive radii: 2^(1/4)
};

struct AdaptiveJetResult
{
  double Normal[3] = { 0.0, 0.0, 0.0 };
  double Eigenvalues[3] = { 0.0, 0.0, 0.0 }; // of the PCA at the chosen radius, ascending, world units squared
  double Radius = 0.0;   // the chosen radius
  double Residual = 0.0; // distance from the point to its neighbours' jet at the chosen radius
  bool Valid = false;
};

/// Per-thread scratch of AdaptiveJetNormal (reused from point to point: no allocation once grown).
struct AdaptiveJetScratch
{
  std::vector<unsigned char> Shell;
  std::vector<Index> Sorted;
};

/// The normal at x from the neighbours at sorted positions pos (squared distances r2, all within
/// options.LargestRadius) of `sorted`.
AdaptiveJetResult AdaptiveJetNormal(const double* sorted, const std::vector<Index>& pos, const std::vector<double>& r2,
  const double x[3], const AdaptiveJetOptions& options, AdaptiveJetScratch& scratch);

} // namespace meshfree

#endif
