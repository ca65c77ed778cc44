// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Normals of a point cloud sampled from a surface: degree-2 jets over a neighbourhood whose radius
 *        balances the noise against the curvature and the creases, then a consistent orientation
 *        (NormalOrientation.h).
 *
 * Normal: the jet of Cazals & Pouget (2005): the neighbours' heights over their PCA plane (coordinates shifted
 * to the point and scaled by the radius) fitted by h = a0 + a1 u + a2 v + a3 u^2 + a4 uv + a5 v^2, the normal
 * n - a1 t1 - a2 t2; exact on quadrics, where PCA is biased. Over at most 256 of the neighbours, spread over the
 * neighbourhood (the cost stays bounded where the noise asks for thousands). Where the radius holds on average far
 * more points than that (noise large against the spacing: about 1000 at 1M and 10M points of a noisy scan), the
 * jets are fitted over one of K = floor(that / 250) thinned clouds that partition every grid cell's points (dealt in
 * turn along them; positions only: independent of the order and the split of the cloud), each in a grid of its
 * own, the cloud chosen by a hash of the point's position (neighbours fit different subsets, so the curvature's
 * smoothing still averages independent noise), so that a query filters 1 / K of the candidates
 * (SurfaceNormals.cxx, BuildThinnedClouds). SurfaceVariation
 * l0 / (l0 + l1 + l2) of the PCA (Pauly et al. 2002): 0 on a plane, 1/3 for isotropic scatter.
 *
 * Neighbourhood (CloudScale::NormalRadius, one radius R* per cloud, at least r_k at each point). The noise
 * tilts a jet's slopes by about 2 sigma h / (sqrt(pi) R^2) (h the spacing, sigma the noise along the normal);
 * the bias grows with R (third-order terms, and across creases). On a sample of 2048 points (the points whose
 * coordinates hash lowest, Common/Distribution.h's CloudSample: the same sample whatever the order and split of
 * the cloud): sigma is the
 * median root mean square misfit of the jets (exact data: ~0, so R* = r_k), R* the radius that keeps the
 * noise's tilt below 0.0025 rad (rounds of radius -> misfit -> radius, as a neighbourhood smaller than the noise
 * hides it; Mitra, Nguyen & Guibas 2004 choose the radius the same way), capped at 0.9 / the median curvature
 * of the jets, at about 1000 neighbours, and shrunk while more than 20 % of the sample's jets misfit beyond
 * 1.25 sigma and beyond 1.25 x their local noise (they reach across creases). The local noise is the misfit of the
 * jet over the neighbours within half its radius (corrected for the jet's six coefficients): a crease's misfit grows
 * with the radius (about twice from R / 2 to R for a V), noise's does not. Without it a range scan's noise, which
 * grows with the square of the range and spans several times its median over one view, made its noisier half
 * count as creases (the radius fell to r_k and SharpFeatures replaced those normals: CGAL's jet over 112
 * neighbours was 2-5 times better on the virtual scans; now the default beats it on each). Measured (150k points,
 * torus/sphere/cube at noise 0-1.2 % of the diagonal, and the four virtual scans): better than the best of PCA over
 * 18, 112, 450 nearest and CGAL's jet over 18 and 112 on every cloud.
 * SupportRadius > 0 replaces all of this with one fixed radius; AdaptToNoise off keeps r_k.
 *
 * Sharp features: a point whose jet misfits its neighbours by more than 1.25 sigma (and 1 % of R) and by more than
 * 1.25 x its local noise (above) reaches across a crease; it takes the normal of the neighbour (within R, and within 0.2 rad / the median curvature)
 * whose jet fits best and passes through the point: the neighbourhood on its side of the crease. Points in the crease itself (no such side) take a jet
 * over the smallest neighbourhood the noise allows.
 *
 * CloudScale::Noise and ::Radius (the noise radius with TiltTolerance, from the PCA spread) size the implicit
 * fits (FitSupports) as before, and the outliers' residual is measured at that smaller radius.
 *
 * MeanCurvature (NormalOptions::MeanCurvature, for CloudNormals.h's Curvature): each jet is fitted a second time
 * over the same neighbours and frame with u^2 and v^2 completed to u^2 + h^2 / 2 and v^2 + h^2 / 2 (a sphere in any
 * frame is h = a0 + a1 u + a2 v + c (u^2 + v^2 + h^2): exact on spheres, where the plain jet's mean curvature is
 * off by about (kappa R)^2 / 4), and the mean curvature of that implicit surface at the point is kept, signed
 * along the normal as estimated. Its sums are sums of their own: the normals are the same bits either way.
 *
 * Order independence: every neighbour choice breaks distance ties by position (NeighborGrid::NeighborBefore)
 * and every sum runs in the grid's cell order: a permuted input gives the same bits.
 *
 * Distributed (NormalOptions::Processes): each process estimates its own points over its piece and halo (a grid
 * framed by the whole cloud, so that its queries list points as the serial grid does), the sample's figures are
 * gathered, the medians are exact selections over all processes, and the halo points' estimates (normals, radii,
 * misfits, the graph) come from their owners before the crease pass, the outliers and the orientation read them:
 * the same bits as the serial run, as long as the halo holds every point a query reaches (NormalField::Shortfall).
 *
 * Invalid normals (zero vector, Valid 0): points with NaN/Inf coordinates, and points whose neighbourhood
 * has fewer than 3 points or is collinear (l1 ~ 0). Exact duplicates of a point do not count as its
 * neighbours (they would shrink r_k without adding any sampling).
 *
 * Outliers: a point whose r_k is over 3 x the mean r_k of its nearest neighbours (alone in its surroundings;
 * a sparse region of a scan has sparse neighbours too), or farther from the quadric fitted to its neighbourhood
 * (at max(r_k, CloudScale::Radius), in the frame of the point's own jet's normal) than 6 x the median of that distance
 * (about 4 sigma for Gaussian noise; with a floor of 5 % of the radius for exact data) keeps its normal but is
 * flagged, and the implicit fits leave it out (FitSupports gives it no support).
 */
#ifndef meshfree_SurfaceNormals_h
#define meshfree_SurfaceNormals_h

#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"
#include "Common/Progress.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace meshfree
{

struct NormalOptions
{
  int NeighborCount = 20;       // the smallest neighbourhood: this many nearest other points
  double SupportRadius = 0.0;   // > 0: one fixed radius for every point (no adaptation)
  bool AdaptToNoise = true;     // the normals' jets over CloudScale::NormalRadius (else r_k)
  bool WideNormals = true;      // false: jets over the fits' noise radius (CloudScale::Radius), no crease pass
                                // (Meshless Surface: wide jets take in both sides of parts thinner than them)
  double TiltTolerance = 0.05;  // radians: the implicit fits' noise radius (CloudScale::Radius)
  int GraphDegree = 8;          // nearest neighbours kept for the orientation graph
  bool MeanCurvature = false;   // NormalField::MeanCurvature from each normal's jet (a second, sphere-exact jet
                                // over the same neighbours; the normals are the same bits either way)
  const Distribution* Processes = nullptr; // a cloud split among processes (Common/Distribution.h): the grid
                                // holds this process' points and their halo, framed by the whole cloud
                                // (NeighborGrid::SetFrame); own points are estimated, the halo's come from
                                // their owners; statistics are the whole cloud's. Null: serial.
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
  double SampleShortfall = -HUGE_VAL; // distributed: Shortfall() of the sample points' queries (<= 0: complete)
};

struct NormalField
{
  std::vector<double> Normals;          // 3 per point, unit (unoriented until OrientNormals); 0 when invalid
  std::vector<double> Radii;            // neighbourhood radius used at each point: max(r_k, NormalRadius)
  std::vector<double> NeighborDistance; // r_k: distance to the NeighborCount-th nearest other point
  std::vector<double> SurfaceVariation; // l0 / (l0 + l1 + l2)
  std::vector<double> MeanCurvature;    // NormalOptions::MeanCurvature only (else empty): the mean curvature of
                                        // the point's sphere-exact jet, 1 / length, positive where the surface
                                        // bends away from Normals as estimated (before OrientNormals); 0 if none
  std::vector<double> Residual;         // distance from the point to its neighbours' jet (at max(r_k, Radius))
  std::vector<double> JetNormals;       // 3 per point where a sharp feature gave some point a neighbour's normal
                                        // (Normals holds that donor's): every point's own jet normal; else empty.
                                        // OrientNormals propagates over these and then turns each donor normal
                                        // to agree with its point's, and frees them
  std::vector<unsigned char> Outlier;   // residual > max(6 x median residual, 5 % of r_k): left out of fits
  std::vector<unsigned char> Valid;
  detail::Buffer<std::int32_t> Graph;   // GraphDegree nearest other points per point (-1 pads)
  int GraphDegree = 0;
  CloudScale Scale;
  Index InvalidCount = 0;        // over this process' own points (all when serial)
  Index OutlierCount = 0;
  double Shortfall = -HUGE_VAL;  // distributed: the largest Shortfall() of an own point's query (<= 0: complete)
};

/// Normals of the points the grid was built over (grid.NumberOfPoints(), in their original order). Returns
/// false when aborted or when no normal could be estimated; the field is sized and defined in any case.
bool EstimateNormals(const NeighborGrid& grid, const NormalOptions& options, NormalField& field,
  const ProgressCallback& progress = ProgressCallback());

/// The fits' sums (the jets' and the frames' moments) are accumulated with AVX2 when the CPU has it (chosen at run
/// time; bit-identical to the portable code). SetNormalKernelsVectorized(false) forces the portable code, e.g. to
/// compare the two; call it while no estimate runs. Returns whether the vector kernels are in use.
bool SetNormalKernelsVectorized(bool enable);

/// The scale of the cloud (also computed by EstimateNormals): spacing, noise and the radius noise asks for.
CloudScale EstimateCloudScale(const NeighborGrid& grid, const NormalOptions& options);

/// Support radii of the implicit fits over an estimated field: supportScale x r_k (bridges the gaps of
/// random sampling) but at least noiseScale x the noise radius (averages the noise), or supportScale x the
/// fixed radius when one was given; 0 for invalid points. Capped at three times their median, so that a few
/// isolated points (outliers, the noise's tails) do not widen every neighbour query. `median` receives it.
/// Distributed (d): the median is the whole cloud's.
std::vector<double> FitSupports(const NormalField& field, double supportScale, double noiseScale, bool fixedRadius,
  double& median, const Distribution* d = nullptr);

} // namespace meshfree

#endif
