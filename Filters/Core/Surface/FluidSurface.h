// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::FluidSurface
 * @brief The free surface of a particle fluid as a level set of its SPH colour field.
 *
 *   c(x) = sum_j V_j W(|x - x_j|, H)          (thesis 2.3 with A = 1; Mueller et al. 2003 §5)
 *
 * is 1 inside the fluid and 0 outside; the surface is c = Level (default 0.5) and the field handed to the
 * contouring is f = Level - c (negative inside), grad f = -grad c. W is the Wendland C2 kernel normalised in
 * 3D with support H. Volumes: V_j = m_j / rho_j when the caller gives them; otherwise one volume for every
 * particle, V0 = the median over particles of 1 / sum_k W(|x_j - x_k|, H) (the inverse number density of the
 * bulk, taken on a sample of particles; per-particle inverse densities would inflate the sparse outer layer and
 * push the surface outwards).
 * With V0 the particles' volume is N V0, and c = 0.5 sits, for a flat free surface, where the continuous
 * fluid of that volume ends (the midpoint rule of the layers' sum), so Level 0.5 encloses the particles'
 * volume up to O(H^2 curvature).
 *
 * Anisotropic kernels (Yu & Turk 2013, research/surface.md §1): each particle's kernel is stretched along
 * its neighbours' principal directions, W_j(r) = det(G_j) P(|G_j r|), G_j = (1/h) R diag(1/s) R^T from the
 * weighted covariance of its neighbours within 2 x spacing (singular values s clamped to >= s_max / kr,
 * isotropic where fewer than Nmin neighbours), scaled to the volume of the isotropic kernel, and centred at the
 * Laplacian-smoothed position x_j + lambda (xbar_j - x_j). Flat surfaces stay flat and thin sheets thin.
 *
 * Distributed (a Distribution d: the grid holds a process' particles and their halo, framed by the whole cloud):
 * the sample is the whole cloud's 2,048 particles whose positions hash lowest (Common/Distribution.h's
 * CloudSample, serially too), each evaluated by its owner and gathered, so H and V0 are the serial ones; the
 * kernels of the halo's particles are computed like the own ones' (they read neighbours within twice the
 * spacing), the query radius's maxima are taken over every process, the total volume summed over them.
 */
#ifndef meshfree_FluidSurface_h
#define meshfree_FluidSurface_h

#include "Common/Kernels.h"
#include "Common/Distribution.h"
#include "Common/NeighborGrid.h"
#include "Surface/ImplicitField.h"

#include <vector>

namespace meshfree
{

struct FluidSurfaceOptions
{
  double SupportRadius = 0.0; // H; 0: twice the particle spacing
  double Level = 0.5;
  bool Anisotropic = false;
  double AnisotropyRatio = 4.0; // kr: largest / smallest principal stretch
  double Smoothing = 0.3;       // lambda of the smoothed kernel centres (anisotropic only; 0.9 shrank a ball by 6 %)
  int MinimumNeighbors = 25;    // Nmin: fewer neighbours keep the kernel isotropic (anisotropic only)
};

class FluidSurface : public ImplicitField
{
public:
  /// The particles: `grid` built over them; volumes (V_j, caller's order) or null. Computes the kernel
  /// radius, the volumes and, when asked, the anisotropic kernels. False when there are no valid particles.
  bool SetParticles(const NeighborGrid& grid, const double* volumes, const FluidSurfaceOptions& options,
    const Distribution* d = nullptr);
  /// Distributed: how far the sample's queries reached beyond the complete part of the local cloud (<= 0:
  /// complete; -infinity serially).
  double Shortfall() const { return this->SampleShortfall; }

  bool Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& scratch) const override;

  /// The colour field c(x) (without the level).
  double Colour(const double x[3], FieldScratch& scratch) const;

  double SupportRadius() const { return this->H; }
  /// Particle spacing, cube root of the bulk volume per particle.
  double Spacing() const { return this->ParticleSpacing; }
  /// Sum of the particles' volumes.
  double TotalVolume() const { return this->Volume; }

private:
  const NeighborGrid* Grid = nullptr;
  FluidSurfaceOptions Options;
  Kernel Unit;               // Wendland 3D, support 1: W(r, H) = Unit.Value(r / H) / H^3
  double H = 0.0;
  double ParticleSpacing = 0.0;
  double Volume = 0.0;
  double SampleShortfall = -HUGE_VAL;
  double QueryRadius = 0.0;
  std::vector<double> Volumes;    // sorted order, V_j / H^3
  std::vector<double> Centres;    // sorted order, 3 per particle (smoothed when anisotropic)
  std::vector<double> Transforms; // sorted order, 9 per particle: G_j * H (anisotropic only)
  std::vector<double> Determinants; // det(G_j H) (anisotropic only)
};

} // namespace meshfree

#endif
