// SPH fluid core, part 1: parameters, kernels and their lattice corrections, boundary particles and the initial
// state (the model is described in SPHFluid.h). Part 2, the time stepping, is SPHFluid.cxx.
#include "SPH/SPHFluid.h"

#include "SPH/SPHBoundary.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace meshfree
{
namespace
{
constexpr double Pi = 3.141592653589793238462643383279502884;
constexpr Index MaximumParticles = 100000000;
constexpr double StabilityLambda = 0.4; // as in SPHFluid.cxx: the largest stable CFL factor
constexpr double MaximumSupport = 20.0;  // largest SmoothingLength / ParticleSpacing accepted

bool Finite(const double* v, int n)
{
  for (int i = 0; i < n; ++i)
  {
    if (!std::isfinite(v[i]))
    {
      return false;
    }
  }
  return true;
}

// Number of lattice nodes of spacing dx filling [lo, hi] (nodes at lo + (i + 1/2) dx).
Index LatticeCount(double lo, double hi, double dx)
{
  const double n = std::floor((hi - lo) / dx + 0.5);
  return n > 0.0 ? static_cast<Index>(n) : 0;
}
}

double SPHFluid::AutoStiffness(const SPHParameters& p)
{
  double g[3] = { p.Gravity[0], p.Dimension == 2 ? 0.0 : p.Gravity[1], p.Gravity[2] };
  double gNorm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  if (!(gNorm > 0.0))
  {
    g[0] = g[1] = 0.0;
    g[2] = gNorm = 9.81;
  }
  double height = 0.0; // extent of the fluid block along gravity
  for (int a = 0; a < 3; ++a)
  {
    height += std::fabs(g[a] / gNorm) * std::max(0.0, p.FluidBounds[2 * a + 1] - p.FluidBounds[2 * a]);
  }
  height = std::max(height, p.ParticleSpacing);
  // Ideal: bottom compression g H / k <= 1 %  <=>  k >= 100 g H. Tait: c0 >= 10 sqrt(g H)  <=>  c0^2 >= 100 g H.
  return 100.0 * gNorm * height;
}

void SPHFluid::GetLatticeCorrections(double c[3]) const
{
  c[0] = this->DensityCorrection;
  c[1] = this->GradientCorrection;
  c[2] = this->ViscCorrection;
}

void SPHFluid::Setup(const SPHParameters& parameters, const std::vector<double>& obstacleTriangles)
{
  const SPHParameters& p = parameters;
  this->WarningList.clear();
  this->Error.clear();
  this->ReducedStepCount = 0;
  this->UnconvergedStepCount = 0;
  this->InvalidateFields();
  auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  if (p.Dimension != 2 && p.Dimension != 3)
  {
    fail("Dimension must be 2 or 3");
  }
  if (!(p.ParticleSpacing > 0.0) || !std::isfinite(p.ParticleSpacing))
  {
    fail("ParticleSpacing must be a positive number");
  }
  if (!(p.RestDensity > 0.0) || !std::isfinite(p.RestDensity))
  {
    fail("RestDensity must be a positive number");
  }
  if (!(p.SmoothingLength >= 0.0) || !std::isfinite(p.SmoothingLength))
  {
    fail("SmoothingLength must be 0 (automatic) or positive");
  }
  if (!(p.GasStiffness >= 0.0) || !std::isfinite(p.GasStiffness))
  {
    fail("GasStiffness must be 0 (automatic) or positive");
  }
  if (!(p.Viscosity >= 0.0) || !std::isfinite(p.Viscosity) || !(p.SurfaceTension >= 0.0) ||
    !std::isfinite(p.SurfaceTension))
  {
    fail("Viscosity and SurfaceTension must be >= 0");
  }
  if (!(p.ArtificialViscosity >= 0.0) || !std::isfinite(p.ArtificialViscosity))
  {
    fail("ArtificialViscosity must be >= 0");
  }
  if (p.ArtificialViscosity > 1.0)
  {
    this->WarningList.push_back("ArtificialViscosity above 1 makes the fluid very viscous (0.01 to 0.1 is usual)");
  }
  if (!(p.TimeStep > 0.0) || !std::isfinite(p.TimeStep) || !(p.CFLNumber >= 0.0) || !std::isfinite(p.CFLNumber))
  {
    fail("TimeStep must be positive and CFLNumber >= 0");
  }
  if (!Finite(p.Gravity, 3) || !Finite(p.FluidBounds, 6) || !Finite(p.DomainBounds, 6))
  {
    fail("Gravity, FluidBounds and DomainBounds must be finite");
  }
  if (p.Walls)
  {
    for (int a = 0; a < 3; ++a)
    {
      if ((a != 1 || p.Dimension == 3) && !(p.DomainBounds[2 * a + 1] > p.DomainBounds[2 * a]))
      {
        fail("DomainBounds must satisfy min < max on every axis of the simulation");
      }
    }
  }
  if (p.CFLNumber > MaximumCFLNumber(p.Solver))
  {
    std::ostringstream s;
    if (p.Solver == SPHSolver::DFSPH)
    {
      s << "CFLNumber " << p.CFLNumber << " is above 1, the largest DFSPH step (no particle moves more than 0.4 "
        << "support radii a step): every step is limited to 0.4 h / v_max (and to TimeStep)";
    }
    else
    {
      s << "CFLNumber " << p.CFLNumber << " is above " << StabilityLambda
        << ", the stability limit of the leap-frog step: every step is limited to " << StabilityLambda
        << " x the stable step (and to TimeStep)";
    }
    this->WarningList.push_back(s.str());
  }
  if (p.Kernels == SPHKernelPair::Mueller)
  {
    this->WarningList.push_back("KernelPair 'Mueller' (poly6 density, spiky gradient, as in the thesis) does not "
                                "conserve energy: the fluid gains energy unless the viscosity is large; 'Spiky' "
                                "is the physically consistent choice");
  }
  if (p.Solver != SPHSolver::WCSPH && p.Solver != SPHSolver::DFSPH)
  {
    fail("Solver must be WCSPH (0) or DFSPH (1)");
  }
  if (p.Solver == SPHSolver::DFSPH)
  {
    if (!(p.DensityTolerance >= 0.0) || !std::isfinite(p.DensityTolerance) || !(p.DivergenceTolerance >= 0.0) ||
      !std::isfinite(p.DivergenceTolerance))
    {
      fail("DensityTolerance and DivergenceTolerance must be finite and >= 0 (percent)");
    }
    if (p.MaximumIterations < 1)
    {
      fail("MaximumIterations must be at least 1");
    }
    if (p.DensityTolerance == 0.0 || p.DivergenceTolerance == 0.0)
    {
      this->WarningList.push_back("a DFSPH tolerance of 0 cannot be reached in floating point: every such solve "
                                  "runs MaximumIterations iterations (0.01 % density, 0.1 % divergence are usual)");
    }
    if (p.DensityTolerance > 1.0)
    {
      this->WarningList.push_back("DensityTolerance above 1 % lets the DFSPH fluid compress visibly (0.01 to 0.1 % "
                                  "is usual)");
    }
  }
  if (!(p.BoundarySpacingFactor > 0.0) || p.ReorderInterval < 1 || p.MaximumStepsPerInterval < 1)
  {
    fail("invalid internal SPH parameters");
  }
  this->Params = p;
  if (p.Dimension == 2)
  {
    this->Params.Gravity[1] = 0.0;
  }
  const int d = p.Dimension;
  const double dx = p.ParticleSpacing;
  this->H = p.SmoothingLength > 0.0 ? p.SmoothingLength : 2.0 * dx;
  this->H2 = this->H * this->H;
  {
    // The fluid lattice, refused here (before the wall shell is allocated) rather than in InitialState().
    double total = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      if (!(a == 1 && d == 2))
      {
        total *= std::max(0.0, std::floor((p.FluidBounds[2 * a + 1] - p.FluidBounds[2 * a]) / dx + 0.5));
      }
    }
    if (total > static_cast<double>(MaximumParticles))
    {
      std::ostringstream s;
      s << "FluidBounds / ParticleSpacing would create " << total << " particles (more than " << MaximumParticles
        << ")";
      fail(s.str());
    }
  }
  if (this->H > MaximumSupport * dx)
  {
    std::ostringstream s;
    s << "SmoothingLength " << this->H << " is " << this->H / dx << " particle spacings; at most " << MaximumSupport
      << " are supported (neighbour counts and wall layers grow as (h/dx)^d; 1.5 to 6, default 2, is sensible)";
    fail(s.str());
  }
  if (p.Walls)
  {
    // The wall shell holds about prod(n_a + 2 L) - prod(n_a) dummies (L = h/dx layers): refuse before
    // allocating what cannot fit.
    const double layersD = std::ceil(this->H / dx);
    double outer = 1.0, inner = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      if (a == 1 && d == 2)
      {
        continue;
      }
      const double cells = std::max(1.0, std::floor((p.DomainBounds[2 * a + 1] - p.DomainBounds[2 * a]) / dx + 0.5));
      outer *= cells + 2.0 * layersD;
      inner *= cells;
    }
    if (!(outer - inner <= static_cast<double>(MaximumParticles)))
    {
      std::ostringstream s;
      s << "DomainBounds / ParticleSpacing would need " << outer - inner << " wall particles (more than "
        << MaximumParticles << "): the container is too large for this spacing";
      fail(s.str());
    }
  }
  if (this->H < 1.5 * dx || this->H > 6.0 * dx)
  {
    std::ostringstream s;
    s << "SmoothingLength " << this->H << " is " << this->H / dx
      << " particle spacings; 1.5 to 6 (default 2) keeps neighbour counts sensible";
    this->WarningList.push_back(s.str());
  }
  this->Mass = p.RestDensity * std::pow(dx, d);
  this->K = p.GasStiffness > 0.0 ? p.GasStiffness : AutoStiffness(p);
  this->C0 = std::sqrt(this->K);
  this->TaitB = p.RestDensity * this->K / 7.0;
  this->Nu = p.Viscosity / p.RestDensity;
  this->WallMargin = 0.1 * dx;

  // Continuous normalisations (5.27, 5.41, 5.49 in 3D; their 2D counterparts), then the lattice factors.
  const double h = this->H;
  const double spikyNorm = d == 3 ? 15.0 / (Pi * std::pow(h, 6)) : 10.0 / (Pi * std::pow(h, 5));
  this->Poly6 = d == 3 ? 315.0 / (64.0 * Pi * std::pow(h, 9)) : 4.0 / (Pi * std::pow(h, 8));
  this->ViscLap = d == 3 ? 45.0 / (Pi * std::pow(h, 6)) : 40.0 / (Pi * std::pow(h, 5));
  this->SpikyDensity = p.Kernels == SPHKernelPair::Spiky;
  this->SpikyGradient = p.Kernels != SPHKernelPair::Poly6;
  this->DensityNorm = this->SpikyDensity ? spikyNorm : this->Poly6;
  this->GradientNorm = this->SpikyGradient ? 3.0 * spikyNorm : 6.0 * this->Poly6;
  {
    const int reach = static_cast<int>(std::ceil(h / dx));
    const double volume = std::pow(dx, d);
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, sc = 0.0;
    for (int k = -reach; k <= reach; ++k)
    {
      for (int j = (d == 3 ? -reach : 0); j <= (d == 3 ? reach : 0); ++j)
      {
        for (int i = -reach; i <= reach; ++i)
        {
          const double x = i * dx, y = j * dx, z = k * dx;
          const double r2 = x * x + y * y + z * z;
          if (!(r2 < this->H2))
          {
            continue;
          }
          const double r = std::sqrt(r2);
          s0 += volume * this->DensityNorm * this->DensityShape(r2);
          sc += volume * this->Poly6 * (this->H2 - r2) * (this->H2 - r2) * (this->H2 - r2);
          if (r2 > 0.0)
          {
            s1 += volume * this->GradientNorm * this->GradientShape(r2, r) * x * x; // sum V (x_j - x_i)_x dW/dx_i
            s2 += volume * r2 * this->ViscLap * (h - r);
          }
        }
      }
    }
    // Density response of the discrete lattice to a uniaxial compression along gravity (1 in the continuum):
    // the hydrostatic start compresses by the strain that gives the wanted density, not the continuum's.
    {
      int axis = 2;
      for (int a = 0; a < 3; ++a)
      {
        axis = std::fabs(this->Params.Gravity[a]) > std::fabs(this->Params.Gravity[axis]) ? a : axis;
      }
      const double strain = 1e-3;
      double compressed = 0.0;
      for (int k = -reach - 1; k <= reach + 1; ++k)
      {
        for (int j = (d == 3 ? -reach - 1 : 0); j <= (d == 3 ? reach + 1 : 0); ++j)
        {
          for (int i = -reach - 1; i <= reach + 1; ++i)
          {
            double x[3] = { i * dx, j * dx, k * dx };
            x[axis] *= 1.0 - strain;
            const double r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
            if (r2 < this->H2)
            {
              compressed += volume * this->DensityNorm * this->DensityShape(r2);
            }
          }
        }
      }
      this->CompressionResponse = s0 > 0.0 ? (compressed / s0 - 1.0) / strain : 1.0;
      if (!(this->CompressionResponse > 0.1))
      {
        this->CompressionResponse = 1.0;
      }
    }
    this->DensityCorrection = s0 > 0.0 ? 1.0 / s0 : 1.0;
    this->GradientCorrection = s1 > 0.0 ? 1.0 / s1 : 1.0;
    this->ViscCorrection = s2 > 0.0 ? 2.0 * d / s2 : 1.0;
    this->DensityNorm *= this->DensityCorrection;
    this->GradientNorm *= this->GradientCorrection;
    this->ViscLap *= this->ViscCorrection;
    this->Poly6 *= sc > 0.0 ? 1.0 / sc : 1.0; // colour field
    // DFSPH: sum_j |m grad W_ij|^2 of an interior lattice particle (sum_j m grad W_ij vanishes there), the scale
    // below which a particle's factor alpha is set to 0 (too few neighbours to be pushed by pressure).
    double lattice = 0.0, strength = 0.0;
    for (int k = -reach; k <= reach; ++k)
    {
      for (int j = (d == 3 ? -reach : 0); j <= (d == 3 ? reach : 0); ++j)
      {
        for (int i = -reach; i <= reach; ++i)
        {
          const double r2 = (i * i + j * j + k * k) * dx * dx;
          if (r2 > 0.0 && r2 < this->H2)
          {
            const double g = this->Mass * this->GradientNorm * this->GradientShape(r2, std::sqrt(r2));
            lattice += g * g * r2;
            strength += g * r2;
          }
        }
      }
    }
    this->LatticeFactorSum = lattice;
    // ... and sum_j m GradientNorm shape(r_ij) r_ij^2 of that particle: the normalisation of the gradient strength
    // gamma_i of the DFSPH Pressure output (SPHDivergenceFree.cxx, "Pressure output"), 1 on the lattice.
    this->LatticeGradientStrength = strength;
  }

  // Boundary (dummy) particles: a shell behind the container walls and a layer inside every obstacle, as
  // thick as the support; obstacle surfaces are also sampled for the crossing test (SPHBoundary.h).
  const int layers = static_cast<int>(std::ceil(h / dx));
  this->BoundaryPosition.clear();
  this->ObstaclePosition.clear();
  this->ObstacleNormal.clear();
  if (p.Walls)
  {
    BoxWallLayers(p.DomainBounds, d, dx, layers, this->BoundaryPosition);
  }
  if (!obstacleTriangles.empty())
  {
    const double bs = dx * p.BoundarySpacingFactor;
    std::vector<double> xyz, normals;
    SampleTriangles(obstacleTriangles, bs, xyz, normals);
    for (std::size_t i = 0; i < xyz.size(); i += 3)
    {
      if (d == 2)
      {
        // 2D: the section of the surface by the plane y = 0, normals projected into it.
        const double ny = normals[i + 1];
        const double inPlane = std::sqrt(std::max(0.0, 1.0 - ny * ny));
        if (std::fabs(xyz[i + 1]) > 0.5 * bs || inPlane < 1e-3)
        {
          continue;
        }
        this->ObstaclePosition.insert(this->ObstaclePosition.end(), { xyz[i], 0.0, xyz[i + 2] });
        this->ObstacleNormal.insert(
          this->ObstacleNormal.end(), { normals[i] / inPlane, 0.0, normals[i + 2] / inPlane });
      }
      else
      {
        this->ObstaclePosition.insert(this->ObstaclePosition.end(), xyz.begin() + i, xyz.begin() + i + 3);
        this->ObstacleNormal.insert(this->ObstacleNormal.end(), normals.begin() + i, normals.begin() + i + 3);
      }
    }
    if (this->ObstaclePosition.empty())
    {
      this->WarningList.push_back("the Obstacles surface has no usable triangles (in 2D: none crosses y = 0)");
    }
  }
  this->ObstacleGrid.Build(this->ObstaclePosition.data(), static_cast<Index>(this->ObstaclePosition.size() / 3));
  if (!this->ObstaclePosition.empty())
  {
    this->ObstacleGrid.GetBounds(this->ObstacleBox);
    const double origin[3] = { p.FluidBounds[0], p.FluidBounds[2], p.FluidBounds[4] };
    ObstacleLayers(this->ObstaclePosition, this->ObstacleNormal, this->ObstacleGrid, origin, dx, h, d,
      this->BoundaryPosition);
  }
  else
  {
    this->ObstacleBox[0] = this->ObstacleBox[2] = this->ObstacleBox[4] = 0.0;
    this->ObstacleBox[1] = this->ObstacleBox[3] = this->ObstacleBox[5] = -1.0;
  }
  this->BoundaryCount = static_cast<Index>(this->BoundaryPosition.size() / 3);
  this->BoundaryGrid.Build(this->BoundaryPosition.data(), this->BoundaryCount, h);
  this->FillConstants();
}

void SPHFluid::FillConstants()
{
  const SPHParameters& p = this->Params;
  SPHConstants& c = this->Physics;
  c = SPHConstants();
  c.Dimension = p.Dimension;
  c.Tait = p.EquationOfState == SPHEquationOfState::Tait ? 1 : 0;
  c.SpikyDensity = this->SpikyDensity ? 1 : 0;
  c.SpikyGradient = this->SpikyGradient ? 1 : 0;
  c.Walls = p.Walls ? 1 : 0;
  c.H = this->H;
  c.H2 = this->H2;
  c.Mass = this->Mass;
  c.RestDensity = p.RestDensity;
  c.K = this->K;
  c.C0 = this->C0;
  c.TaitB = this->TaitB;
  c.Nu = this->Nu;
  c.DensityNorm = this->DensityNorm;
  c.GradientNorm = this->GradientNorm;
  c.Poly6 = this->Poly6;
  c.ViscLap = this->ViscLap;
  c.SurfaceTension = p.SurfaceTension;
  c.Viscous = p.Viscosity > 0.0 ? 1 : 0;
  c.Tension = p.SurfaceTension > 0.0 ? 1 : 0;
  c.PressureFactor = this->Mass * this->GradientNorm;
  c.ViscousFactor = p.Viscosity * this->Mass * this->ViscLap;
  // Monaghan's artificial viscosity: Pi_ij = -alpha c0 hs (v_ij . r_ij) / (rho_bar (r^2 + 0.01 hs^2)) for
  // approaching pairs, hs = h / 2 the smoothing length of the support radius h.
  const double hs = 0.5 * this->H;
  c.ArtificialFactor = p.ArtificialViscosity * this->C0 * hs;
  c.ArtificialEpsilon = 0.01 * hs * hs;
  c.Artificial = c.ArtificialFactor > 0.0 ? 1 : 0;
  c.SurfaceThreshold = 0.25;
  for (int a = 0; a < 3; ++a)
  {
    c.Gravity[a] = p.Gravity[a];
  }
  for (int a = 0; a < 6; ++a)
  {
    c.DomainBounds[a] = p.DomainBounds[a];
    c.ObstacleBox[a] = this->ObstacleBox[a];
  }
  c.WallMargin = this->WallMargin;
  this->Device.reset(); // the device copy of the constants and dummies is made again on the next device run
}

bool SPHFluid::NearBoundary(const double* x) const
{
  return SPHNearBoundary(x, this->Physics);
}

bool SPHFluid::NearObstacle(const double* x) const
{
  const double h = this->H;
  const double* o = this->ObstacleBox;
  return x[0] > o[0] - h && x[0] < o[1] + h && x[1] > o[2] - h && x[1] < o[3] + h && x[2] > o[4] - h &&
    x[2] < o[5] + h;
}

SPHState SPHFluid::InitialState()
{
  const SPHParameters& p = this->Params;
  const double dx = p.ParticleSpacing;
  SPHState state;
  Index count[3];
  double total = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    count[a] = (a == 1 && p.Dimension == 2) ? 1 : LatticeCount(p.FluidBounds[2 * a], p.FluidBounds[2 * a + 1], dx);
    total *= static_cast<double>(count[a]);
  }
  if (total > static_cast<double>(MaximumParticles))
  {
    std::ostringstream s;
    s << "FluidBounds / ParticleSpacing would create " << total << " particles (more than " << MaximumParticles
      << ")";
    throw std::invalid_argument(s.str());
  }
  if (total == 0.0)
  {
    this->WarningList.push_back("FluidBounds hold no lattice node of ParticleSpacing: the fluid has no particles");
  }
  Index outside = 0;
  std::vector<Index> nearest(8);
  std::vector<double> nearestD2(8);
  // A node outside the obstacles' bounding box cannot be inside one: only nodes within 10 spacings of that box take
  // the nearest-sample normal test (ObstacleSample: ties between samples of several faces, at edges and corners, go
  // to the plane that puts the node farthest outside, whatever the order of the triangles). Within the 10 spacings
  // the test drops some nodes in the plane of a face just beyond an edge, which the validated obstacle results
  // include.
  double obstacleBox[6] = { 0.0, -1.0, 0.0, -1.0, 0.0, -1.0 };
  const double grow = 10.0 * dx;
  for (std::size_t q = 0; q < this->ObstaclePosition.size(); q += 3)
  {
    for (int a = 0; a < 3; ++a)
    {
      const double v = this->ObstaclePosition[q + a];
      obstacleBox[2 * a] = q == 0 ? v - grow : std::min(obstacleBox[2 * a], v - grow);
      obstacleBox[2 * a + 1] = q == 0 ? v + grow : std::max(obstacleBox[2 * a + 1], v + grow);
    }
  }
  const bool flat = p.Dimension == 2; // y is ignored in 2D
  const auto nearObstacles = [&obstacleBox, flat](const double* x) {
    return x[0] >= obstacleBox[0] && x[0] <= obstacleBox[1] &&
      (flat || (x[1] >= obstacleBox[2] && x[1] <= obstacleBox[3])) && x[2] >= obstacleBox[4] && x[2] <= obstacleBox[5];
  };
  for (Index k = 0; k < count[2]; ++k)
  {
    for (Index j = 0; j < count[1]; ++j)
    {
      for (Index i = 0; i < count[0]; ++i)
      {
        const double x[3] = { p.FluidBounds[0] + (i + 0.5) * dx,
          p.Dimension == 2 ? 0.0 : p.FluidBounds[2] + (j + 0.5) * dx, p.FluidBounds[4] + (k + 0.5) * dx };
        bool keep = true;
        for (int a = 0; a < 3 && p.Walls; ++a)
        {
          if (!(a == 1 && p.Dimension == 2) &&
            (x[a] < p.DomainBounds[2 * a] + this->WallMargin || x[a] > p.DomainBounds[2 * a + 1] - this->WallMargin))
          {
            keep = false;
          }
        }
        double depth = 0.0;
        if (keep && !this->ObstaclePosition.empty() && nearObstacles(x) &&
          this->ObstacleSample(x, nearest, nearestD2, depth) >= 0)
        {
          keep = depth > 0.5 * dx;
        }
        if (!keep)
        {
          ++outside;
          continue;
        }
        state.Position.insert(state.Position.end(), x, x + 3);
        state.Id.push_back(static_cast<std::int64_t>(state.Id.size()));
      }
    }
  }
  if (outside > 0)
  {
    std::ostringstream s;
    s << outside << " of " << static_cast<Index>(total)
      << " particles of FluidBounds lie outside DomainBounds or inside an obstacle and were left out";
    this->WarningList.push_back(s.str());
  }
  const Index n = state.Size();
  // Hydrostatic start: the block is compressed along gravity as a column at rest would be (what a tank holds
  // before its gate opens), so that the release does not begin with a pressure wave. Linearised EOS:
  // rho(s) = rho0 (1 + g s / k) at depth s, and mass conservation maps depth d to d' with d' + g d'^2/(2k) = d.
  const double* g = p.Gravity;
  const double gNorm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  if (gNorm > 0.0 && n > 0)
  {
    const double up[3] = { -g[0] / gNorm, -g[1] / gNorm, -g[2] / gNorm };
    double top = -std::numeric_limits<double>::max();
    for (int corner = 0; corner < 8; ++corner)
    {
      const double c[3] = { p.FluidBounds[corner & 1], p.FluidBounds[2 + ((corner >> 1) & 1)],
        p.FluidBounds[4 + ((corner >> 2) & 1)] };
      top = std::max(top, c[0] * up[0] + c[1] * up[1] + c[2] * up[2]);
    }
    // DFSPH: the fluid is incompressible, the block starts on its lattice.
    const double ratio =
      p.Solver == SPHSolver::DFSPH ? 0.0 : gNorm / (this->K * this->CompressionResponse);
    auto compress = [ratio](double depth) {
      return ratio > 0.0 ? 2.0 * depth / (std::sqrt(1.0 + 2.0 * ratio * depth) + 1.0) : depth;
    };
    double deepest = 0.0;
    if (p.Solver == SPHSolver::DFSPH)
    {
      state.DensityStiffness.assign(n, 0.0);
    }
    for (Index i = 0; i < n; ++i)
    {
      const double* x = &state.Position[3 * i];
      const double depth = top - (x[0] * up[0] + x[1] * up[1] + x[2] * up[2]);
      deepest = std::max(deepest, depth);
      if (p.Solver == SPHSolver::DFSPH)
      {
        // DFSPH: the hydrostatic kappa = p / rho = |g| depth, the warm start of the first density solve (the
        // pressure the tank holds before its gate opens).
        state.DensityStiffness[i] = gNorm * std::max(depth, 0.0);
      }
    }
    const double settle = deepest - compress(deepest); // the deepest particles keep their place
    for (Index i = 0; i < n; ++i)
    {
      double* x = &state.Position[3 * i];
      const double depth = top - (x[0] * up[0] + x[1] * up[1] + x[2] * up[2]);
      const double shift = (depth - compress(depth)) - settle; // <= 0: towards the bottom
      for (int a = 0; a < 3; ++a)
      {
        x[a] += shift * up[a];
      }
    }
  }
  state.Velocity.assign(3 * n, 0.0);
  state.Acceleration.assign(3 * n, 0.0);
  state.Density.assign(n, p.RestDensity);
  state.Pressure.assign(n, 0.0);
  if (p.Solver == SPHSolver::DFSPH)
  {
    this->DivergenceFreeOutput(state);
  }
  else
  {
    this->ComputeAccelerations(state);
  }
  return state;
}

} // namespace meshfree
