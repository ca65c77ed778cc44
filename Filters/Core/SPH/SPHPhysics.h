// The per-particle arithmetic of the SPH fluid (SPHFluid.h describes the model), shared by the CPU loops of
// SPHFluid.cxx and the CUDA kernels of cuda/SPHDevice.cu: one source, so that both give the same bits.
//
// Everything here is inline MESHFREE_HD code on raw pointers and the POD SPHConstants (copied to the device by
// value). Sums are per-pair accumulators: the CPU feeds them its CSR neighbour rows, the device the particles of
// the grid cells in the same order; the accumulation order is the caller's, the arithmetic of each pair is here.
// Only +, -, *, / and sqrt are used, which are correctly rounded on both sides (the device code is built with
// --fmad=false, the host code has no FMA contraction); the Tait inverse's seventh root is a Newton iteration on
// those (SPHSeventhRoot), not pow, whose last bit may differ between glibc and CUDA's libdevice.
#ifndef MeshFree_SPH_SPHPhysics_h
#define MeshFree_SPH_SPHPhysics_h

#include "Common/HostDevice.h"
#include "SPH/SPHDensity.h"

#include <cmath>

namespace meshfree
{

/// Everything the per-particle passes need besides the particle arrays (plain data). Filled by SPHFluid::Setup().
struct SPHConstants
{
  int Dimension = 3;     ///< 3, or 2 (y accelerations zeroed)
  int Tait = 0;          ///< equation of state: 1 Tait, 0 Ideal
  int SpikyDensity = 0;  ///< density kernel: 1 spiky (h - r)^3, 0 poly6 (h^2 - r^2)^3
  int SpikyGradient = 0; ///< pressure-force gradient: 1 spiky, 0 poly6
  int Walls = 0;         ///< 1: the closed container DomainBounds
  int Viscous = 0;       ///< Viscosity > 0
  int Tension = 0;       ///< SurfaceTension > 0
  int Artificial = 0;    ///< ArtificialFactor > 0
  double H = 0.0;        ///< support radius h
  double H2 = 0.0;       ///< h^2
  double Mass = 0.0;     ///< particle mass m
  double RestDensity = 0.0;
  double K = 0.0;     ///< Ideal: k; Tait: c0^2
  double C0 = 0.0;    ///< sqrt(K)
  double TaitB = 0.0; ///< rho0 K / 7
  double Nu = 0.0;    ///< kinematic viscosity mu / rho0
  double DensityNorm = 0.0;
  double GradientNorm = 0.0;
  double Poly6 = 0.0;   ///< colour field kernel, lattice-normalised
  double ViscLap = 0.0; ///< lap W_visc = ViscLap (h - r)
  double SurfaceTension = 0.0;
  double PressureFactor = 0.0;    ///< m GradientNorm
  double ViscousFactor = 0.0;     ///< mu m ViscLap
  double ArtificialFactor = 0.0;  ///< alpha c0 hs, hs = h / 2
  double ArtificialEpsilon = 0.0; ///< 0.01 hs^2
  double SurfaceThreshold = 0.25; ///< |grad c| h above which a particle is on the surface
  double Gravity[3] = { 0.0, 0.0, 0.0 };
  double DomainBounds[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
  double WallMargin = 0.0;                                     ///< particles are kept this far inside the walls
  double ObstacleBox[6] = { 0.0, -1.0, 0.0, -1.0, 0.0, -1.0 }; ///< bounds of the obstacle samples (empty: none)
};

/// The density sum's constants (SPH/SPHDensity.h) of these.
MESHFREE_HD inline SPHDensityConstants SPHDensityConstantsOf(const SPHConstants& c)
{
  SPHDensityConstants d;
  d.H = c.H;
  d.H2 = c.H2;
  d.Mass = c.Mass;
  d.DensityNorm = c.DensityNorm;
  d.SpikyDensity = c.SpikyDensity;
  return d;
}

/// Equation of state, clamped at 0: Ideal p = K (rho - rho0), Tait p = B ((rho/rho0)^7 - 1) (the power as products).
MESHFREE_HD inline double SPHPressureOf(double rho, const SPHConstants& c)
{
  double pressure;
  if (c.Tait)
  {
    const double ratio = rho / c.RestDensity;
    const double r2 = ratio * ratio;
    pressure = c.TaitB * (r2 * r2 * r2 * ratio - 1.0);
  }
  else
  {
    pressure = c.K * (rho - c.RestDensity);
  }
  return pressure > 0.0 ? pressure : 0.0; // clamped: see SPHFluid.h
}

/// z^(1/7) for z >= 1 with +, *, / only, so that host and device give the same bits (pow's last bit differs
/// between glibc and CUDA): Newton's iteration for y^7 = z, y <- (6 y + z / y^6) / 7, from y0 = 1 + (z - 1) / 7,
/// which is >= z^(1/7) (Bernoulli's inequality); y^7 - z is convex for y > 0, so the iterates decrease
/// monotonically to the root, and the loop stops when rounding stops the decrease. Within 2 ulp of
/// pow(z, 1.0 / 7.0) (70 % of 2e6 samples in [1, 201] equal); a handful of iterations for the densities of a
/// weakly compressible fluid (z = (rho/rho0)^7 <= 2 for rho <= 1.1 rho0), at most 200 (reached only for z > 1e13).
MESHFREE_HD inline double SPHSeventhRoot(double z)
{
  double y = 1.0 + (z - 1.0) / 7.0;
  for (int k = 0; k < 200; ++k)
  {
    const double y3 = y * y * y;
    const double next = (6.0 * y + z / (y3 * y3)) / 7.0;
    if (!(next < y))
    {
      break;
    }
    y = next;
  }
  return y;
}

/// Inverse of the equation of state for p >= 0. Tait: rho0 (1 + p / B)^(1/7) (SPHSeventhRoot).
MESHFREE_HD inline double SPHDensityOf(double pressure, const SPHConstants& c)
{
  if (c.Tait)
  {
    return c.RestDensity * SPHSeventhRoot(1.0 + pressure / c.TaitB);
  }
  return c.RestDensity + pressure / c.K;
}

/// What the pair loops read of a particle: p / rho^2 and 1 / rho (multiplications instead of divisions there).
MESHFREE_HD inline void SPHParticleTerms(
  double rho, const SPHConstants& c, double* pressure, double* pressureTerm, double* inverseDensity)
{
  *pressure = SPHPressureOf(rho, c);
  *pressureTerm = *pressure / (rho * rho);
  *inverseDensity = 1.0 / rho;
}

/// Shape of the pressure-force gradient: grad W = -GradientNorm SPHGradientShape(r^2, r) r_vec.
MESHFREE_HD inline double SPHGradientShape(double r2, double r, double h, double h2, int spiky)
{
  if (spiky)
  {
    return (h - r) * (h - r) / r;
  }
  const double q = h2 - r2;
  return q * q;
}

/// Whether a particle at x may have wall dummies (or obstacle dummies) within h: near a wall or near the
/// obstacles' box. Only such particles look up dummies.
MESHFREE_HD inline bool SPHNearBoundary(const double* x, const SPHConstants& c)
{
  const double h = c.H;
  if (c.Walls)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (a == 1 && c.Dimension == 2)
      {
        continue;
      }
      if (x[a] - c.DomainBounds[2 * a] < h || c.DomainBounds[2 * a + 1] - x[a] < h)
      {
        return true;
      }
    }
  }
  const double* o = c.ObstacleBox;
  return x[0] > o[0] - h && x[0] < o[1] + h && x[1] > o[2] - h && x[1] < o[3] + h && x[2] > o[4] - h && x[2] < o[5] + h;
}

/// Pressure of a wall dummy at x_b, extrapolated from its fluid neighbours f with the hydrostatic increase
/// (Adami, Hu & Adams 2012, eq. 27, static wall): p_b = (sum_f p_f W + g . sum_f rho_f (x_b - x_f) W) / sum_f W,
/// clamped at 0, with W the density kernel's shape (its normalisation cancels). Add() every fluid particle with
/// r = x_b - x_f; Term() gives the pair force's p_b / rho_b^2, rho_b from the inverse equation of state.
struct SPHWallPressure
{
  double SumW = 0.0, SumP = 0.0, SumG = 0.0;

  MESHFREE_HD void Add(const double r[3], double r2, double pressureF, double rhoF, const SPHConstants& c)
  {
    if (r2 < c.H2)
    {
      const double w = SPHDensityShape(r2, c.H, c.H2, c.SpikyDensity);
      const double* g = c.Gravity;
      this->SumW += w;
      this->SumP += pressureF * w;
      this->SumG += rhoF * (g[0] * r[0] + g[1] * r[1] + g[2] * r[2]) * w;
    }
  }
  MESHFREE_HD double Pressure() const
  {
    if (!(this->SumW > 0.0))
    {
      return 0.0;
    }
    const double p = (this->SumP + this->SumG) / this->SumW;
    return p > 0.0 ? p : 0.0;
  }
  MESHFREE_HD double Term(const SPHConstants& c) const
  {
    const double pb = this->Pressure();
    const double rhoB = SPHDensityOf(pb, c);
    return pb / (rhoB * rhoB);
  }
};

/// The acceleration of particle i: pressure pair force (symmetric, 5.37) with Monaghan's artificial viscosity
/// between fluid particles, viscosity (5.46), the colour-field surface tension (walls count as fluid), gravity.
/// Construct with particle i's data, Fluid() every fluid neighbour j != i, Wall() every dummy b (both with
/// r = x_i - x_j; pairs at r^2 >= h^2 are ignored), then Finish().
struct SPHAcceleration
{
  const double* Xi;
  const double* Vi;
  double RhoI, InverseI, TermI;
  double Ap[3] = { 0.0, 0.0, 0.0 }, Av[3] = { 0.0, 0.0, 0.0 }, Normal[3] = { 0.0, 0.0, 0.0 };
  double ColourLaplacian = 0.0;

  MESHFREE_HD SPHAcceleration(const double* xi, const double* vi, double rhoI, double inverseI, double termI)
    : Xi(xi)
    , Vi(vi)
    , RhoI(rhoI)
    , InverseI(inverseI)
    , TermI(termI)
  {
  }

  /// Colour field c = sum_j V_j W_poly6: grad W = gradient r, lap W = -6 poly6 q (d q - 4 r^2), q = h^2 - r^2.
  MESHFREE_HD void Colour(double volume, const double r[3], double r2, const SPHConstants& c)
  {
    const double q = c.H2 - r2;
    const double gradient = -6.0 * c.Poly6 * q * q;
    this->Normal[0] += volume * gradient * r[0];
    this->Normal[1] += volume * gradient * r[1];
    this->Normal[2] += volume * gradient * r[2];
    this->ColourLaplacian += volume * -6.0 * c.Poly6 * q * (c.Dimension * q - 4.0 * r2);
  }

  /// Fluid neighbour j at xj with velocity vj, density rhoJ, 1 / rhoJ and p_j / rho_j^2.
  MESHFREE_HD void Fluid(
    const double* xj, const double* vj, double rhoJ, double inverseJ, double termJ, const SPHConstants& c)
  {
    const double* xi = this->Xi;
    const double* vi = this->Vi;
    const double r[3] = { xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2] };
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if (!(r2 < c.H2))
    {
      return;
    }
    const double dist = sqrt(r2);
    if (dist > 0.0)
    {
      // -m (p_i/rho_i^2 + p_j/rho_j^2 + Pi_ij) grad W, grad W = -GradientNorm shape(r) r
      double pair = this->TermI + termJ;
      if (c.Artificial)
      {
        const double vr = (vi[0] - vj[0]) * r[0] + (vi[1] - vj[1]) * r[1] + (vi[2] - vj[2]) * r[2];
        pair += vr < 0.0 ? -c.ArtificialFactor * vr / (0.5 * (this->RhoI + rhoJ) * (r2 + c.ArtificialEpsilon)) : 0.0;
      }
      // A zero pair term (both pressures 0 and no artificial viscosity: DFSPH's non-pressure pass for every pair
      // moving apart, WCSPH at the free surface) would add +-0 to Ap, which is never -0: skipping it keeps the bits.
      if (pair != 0.0)
      {
        const double coefficient = c.PressureFactor * pair * SPHGradientShape(r2, dist, c.H, c.H2, c.SpikyGradient);
        this->Ap[0] += coefficient * r[0];
        this->Ap[1] += coefficient * r[1];
        this->Ap[2] += coefficient * r[2];
      }
    }
    if (c.Viscous)
    {
      const double coefficient = c.ViscousFactor * (c.H - dist) * this->InverseI * inverseJ;
      this->Av[0] += coefficient * (vj[0] - vi[0]);
      this->Av[1] += coefficient * (vj[1] - vi[1]);
      this->Av[2] += coefficient * (vj[2] - vi[2]);
    }
    if (c.Tension)
    {
      this->Colour(c.Mass * inverseJ, r, r2, c);
    }
  }

  /// Fluid() of a pair with zero pressures (DFSPH's non-pressure accelerations) from its pair-list entry instead of
  /// the positions: g = G_ij = k r with k = PressureFactor shape(|r|) (-m grad W, lattice-corrected), viscous = h - |r|
  /// and artificial = 1 / (k (|r|^2 + ArtificialEpsilon)) (0 where k = 0), so that Monaghan's term
  /// -ArtificialFactor (v_ij . r) / (rho_bar (r^2 + eps)) G_ij is -ArtificialFactor (v_ij . g) artificial / rho_bar g.
  /// No surface tension (it needs r itself: Fluid()).
  MESHFREE_HD void NonPressure(const double g[3], double viscous, double artificial, const double* vj, double rhoJ,
    double inverseJ, const SPHConstants& c)
  {
    const double* vi = this->Vi;
    const double dv[3] = { vi[0] - vj[0], vi[1] - vj[1], vi[2] - vj[2] };
    if (c.Artificial)
    {
      // Approaching pairs only (v_ij . r < 0), without a branch: which pairs approach is close to random, and a
      // receding pair adds +-0, which leaves Ap as it is.
      const double vg = dv[0] * g[0] + dv[1] * g[1] + dv[2] * g[2];
      const double approach = vg < 0.0 ? -vg : 0.0; // a max, not fmax (a library call here)
      const double pair = c.ArtificialFactor * approach * artificial / (0.5 * (this->RhoI + rhoJ));
      this->Ap[0] += pair * g[0];
      this->Ap[1] += pair * g[1];
      this->Ap[2] += pair * g[2];
    }
    if (c.Viscous)
    {
      const double coefficient = c.ViscousFactor * viscous * this->InverseI * inverseJ;
      this->Av[0] -= coefficient * dv[0];
      this->Av[1] -= coefficient * dv[1];
      this->Av[2] -= coefficient * dv[2];
    }
  }

  /// Wall dummy at xb whose extrapolated pressure gives p_b / rho_b^2 = termB (SPHWallPressure). No artificial
  /// viscosity against walls (it would act as wall friction: SPHFluid.h).
  MESHFREE_HD void Wall(const double* xb, double termB, const SPHConstants& c)
  {
    const double* xi = this->Xi;
    const double r[3] = { xi[0] - xb[0], xi[1] - xb[1], xi[2] - xb[2] };
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if (!(r2 < c.H2))
    {
      return;
    }
    const double dist = sqrt(r2);
    if (dist > 0.0)
    {
      const double pair = this->TermI + termB;
      const double coefficient = c.PressureFactor * pair * SPHGradientShape(r2, dist, c.H, c.H2, c.SpikyGradient);
      this->Ap[0] += coefficient * r[0];
      this->Ap[1] += coefficient * r[1];
      this->Ap[2] += coefficient * r[2];
    }
    if (c.Tension)
    {
      this->Colour(c.Mass / c.RestDensity, r, r2, c); // neutral wetting: no surface along walls
    }
  }

  /// The acceleration: pair forces + viscosity + gravity, the surface tension where |grad c| h exceeds the
  /// threshold, y zeroed in 2D.
  MESHFREE_HD void Finish(double* ai, const SPHConstants& c) const
  {
    const double* g = c.Gravity;
    ai[0] = this->Ap[0] + this->Av[0] + g[0];
    ai[1] = this->Ap[1] + this->Av[1] + g[1];
    ai[2] = this->Ap[2] + this->Av[2] + g[2];
    if (c.Tension)
    {
      const double* n = this->Normal;
      const double length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (length * c.H > c.SurfaceThreshold)
      {
        const double factor = -c.SurfaceTension * this->ColourLaplacian * this->InverseI / length;
        ai[0] += factor * n[0];
        ai[1] += factor * n[1];
        ai[2] += factor * n[2];
      }
    }
    if (c.Dimension == 2)
    {
      ai[1] = 0.0;
    }
  }
};

/// First half of a leap-frog step: v += (dt / 2) a, x += dt v.
MESHFREE_HD inline void SPHKickDrift(double* x, double* v, const double* a, double half, double dt)
{
  for (int k = 0; k < 3; ++k)
  {
    v[k] += half * a[k];
    x[k] += dt * v[k];
  }
}

/// The container's guarantee: a particle past a wall (less WallMargin) is put back on that plane and loses its
/// outward velocity. (The obstacle projection, which needs the nearest obstacle sample, is CPU code.)
MESHFREE_HD inline void SPHWallClamp(double* x, double* v, const SPHConstants& c)
{
  if (!c.Walls)
  {
    return;
  }
  for (int a = 0; a < 3; ++a)
  {
    if (a == 1 && c.Dimension == 2)
    {
      continue;
    }
    const double low = c.DomainBounds[2 * a] + c.WallMargin;
    const double high = c.DomainBounds[2 * a + 1] - c.WallMargin;
    if (x[a] < low)
    {
      x[a] = low;
      v[a] = v[a] < 0.0 ? 0.0 : v[a];
    }
    else if (x[a] > high)
    {
      x[a] = high;
      v[a] = 0.0 < v[a] ? 0.0 : v[a];
    }
  }
}

/// Second half of a leap-frog step: v += (dt / 2) a (one component).
MESHFREE_HD inline void SPHKick(double* v, const double* a, double half)
{
  *v += half * *a;
}

/// The maxima the CFL step needs: |v|^2, |a|^2, rho (from RestDensity up), and whether all were finite.
/// Max-reductions: the result does not depend on the order of Add()/Merge().
struct SPHExtremes
{
  double V2 = 0.0, A2 = 0.0, Rho = 0.0;
  int Finite = 1;

  MESHFREE_HD void Add(const double* v, const double* a, double rho)
  {
    const double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    const double a2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    this->Finite = this->Finite && std::isfinite(v2) && std::isfinite(a2) && std::isfinite(rho);
    this->V2 = this->V2 < v2 ? v2 : this->V2;
    this->A2 = this->A2 < a2 ? a2 : this->A2;
    this->Rho = this->Rho < rho ? rho : this->Rho;
  }
  MESHFREE_HD void Merge(const SPHExtremes& y)
  {
    this->V2 = this->V2 < y.V2 ? y.V2 : this->V2;
    this->A2 = this->A2 < y.A2 ? y.A2 : this->A2;
    this->Rho = this->Rho < y.Rho ? y.Rho : this->Rho;
    this->Finite = this->Finite && y.Finite;
  }
};

/// CFL step lambda min(h / (c + v_max), sqrt(h / a_max), 0.125 h^2 / nu), c the sound speed at the largest
/// density (Tait: c0 (rho/rho0)^3); NaN when a value was not finite.
MESHFREE_HD inline double SPHStableStep(const SPHExtremes& e, double lambda, const SPHConstants& c)
{
  if (!e.Finite)
  {
    return NAN;
  }
  double speed = c.C0;
  if (c.Tait)
  {
    const double ratio = e.Rho / c.RestDensity; // c^2 = dp/drho = c0^2 (rho/rho0)^6
    speed *= ratio * ratio * ratio;
  }
  const double h = c.H;
  double dt = h / (speed + sqrt(e.V2));
  const double amax = sqrt(e.A2);
  if (amax > 0.0)
  {
    const double limit = sqrt(h / amax);
    dt = limit < dt ? limit : dt;
  }
  if (c.Nu > 0.0)
  {
    const double limit = 0.125 * h * h / c.Nu;
    dt = limit < dt ? limit : dt;
  }
  return lambda * dt;
}

} // namespace meshfree

#endif
