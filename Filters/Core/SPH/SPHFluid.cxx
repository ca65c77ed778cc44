// SPH fluid core, part 2: neighbour lists, density and forces, leap-frog stepping (the model is described in
// SPHFluid.h). Part 1, the setup and initial state, is SPHSetup.cxx.
#include "SPH/SPHFluid.h"

#include "Common/Parallel.h"
#include "SPH/SPHDensity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace meshfree
{
namespace
{
constexpr double StabilityLambda = 0.4;   // largest CFL factor a fixed step may use before it is reduced
constexpr double SurfaceThreshold = 0.25; // |grad c| h above which a particle is on the surface
constexpr Index ParallelThreshold = 4096; // below: one thread (a fork-join would cost more than the work)
}

void SPHFluid::BuildNeighborLists(const SPHState& state, bool withBoundary)
{
  const Index n = state.Size();
  const double* x = state.Position.data();
  // Fluid neighbours: one batched query over the grid's cells (the 27 candidate cells of a cell are gathered
  // once for all its particles), rows in the order of a per-particle query, the particle itself left out.
  this->Grid.FindWithinRadiusForAllPoints(this->H, this->FluidStart, this->FluidNeighbors, true);
  this->BoundaryStart.assign(n + 1, 0);
  const bool boundary = withBoundary && this->BoundaryCount > 0;
  if (!boundary)
  {
    this->BoundaryNeighbors.clear();
    return;
  }
  // Wall dummies: a radius query per particle near a wall. The particles near a wall are not spread evenly
  // over the (Morton) order, so the work is handed out dynamically; each thread appends its rows to its own
  // buffer, and the rows are then copied into place in particle order (the lists do not depend on the schedule).
  const int threads = MaxThreads();
  this->ThreadBoundary.resize(threads);
  for (std::vector<std::int32_t>& wall : this->ThreadBoundary)
  {
    wall.clear();
  }
  std::vector<std::vector<Index>> threadIds(threads);
  this->BoundaryRowStart.resize(n);
  this->BoundaryRowThread.resize(n);
  Index* rowStart = this->BoundaryRowStart.data();
  std::int32_t* rowThread = this->BoundaryRowThread.data();
  Index* counts = this->BoundaryStart.data() + 1;
  ParallelFor(
    n, 512,
    [&](Index begin, Index end) {
      const int t = ThreadIndex();
      std::vector<std::int32_t>& wall = this->ThreadBoundary[t];
      std::vector<Index>& ids = threadIds[t];
      for (Index i = begin; i < end; ++i)
      {
        if (this->NearBoundary(x + 3 * i))
        {
          this->BoundaryGrid.FindWithinRadius(x + 3 * i, this->H, ids);
          rowStart[i] = static_cast<Index>(wall.size());
          rowThread[i] = t;
          for (Index b : ids)
          {
            wall.push_back(static_cast<std::int32_t>(b));
          }
          counts[i] = static_cast<Index>(ids.size());
        }
      }
    },
    ParallelThreshold);
  for (Index i = 0; i < n; ++i)
  {
    this->BoundaryStart[i + 1] += this->BoundaryStart[i];
  }
  this->BoundaryNeighbors.resize(this->BoundaryStart[n]);
  const Index* start = this->BoundaryStart.data();
  std::int32_t* rows = this->BoundaryNeighbors.data();
  ParallelFor(
    n, 4096,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        if (start[i + 1] > start[i])
        {
          const std::int32_t* from = this->ThreadBoundary[rowThread[i]].data() + rowStart[i];
          std::copy(from, from + (start[i + 1] - start[i]), rows + start[i]);
        }
      }
    },
    ParallelThreshold);
}

void SPHFluid::ComputeAccelerations(SPHState& state)
{
  const Index n = state.Size();
  if (n == 0)
  {
    return;
  }
  const SPHParameters& p = this->Params;
  this->Grid.Build(state.Position.data(), n, this->H);
  this->BuildNeighborLists(state, true);
  const double* x = state.Position.data();
  const double* v = state.Velocity.data();
  double* rho = state.Density.data();
  double* pressure = state.Pressure.data();
  double* acc = state.Acceleration.data();
  const double h = this->H, h2 = this->H2, m = this->Mass;
  const double poly6 = this->Poly6, densityNorm = this->DensityNorm, gradientNorm = this->GradientNorm;
  const double visc = this->ViscLap;
  const double* bx = this->BoundaryPosition.data();
  const Index* fs = this->FluidStart.data();
  const Index* bs = this->BoundaryStart.data();
  const std::int32_t* fn = this->FluidNeighbors.data();
  const std::int32_t* bn = this->BoundaryNeighbors.data();
  // Per particle, so that the pair loops below multiply instead of divide: p / rho^2 and 1 / rho.
  this->PressureTerm.resize(n);
  this->InverseDensity.resize(n);
  double* pressureTerm = this->PressureTerm.data();
  double* inverseDensity = this->InverseDensity.data();

  // Density (5.32: SPH/SPHDensity.h, the function the CUDA launcher runs too) and pressure (5.40 / Tait).
  SPHDensityConstants densityConstants;
  densityConstants.H = h;
  densityConstants.H2 = h2;
  densityConstants.Mass = m;
  densityConstants.DensityNorm = densityNorm;
  densityConstants.SpikyDensity = this->SpikyDensity ? 1 : 0;
  ParallelFor(
    n, 512,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        rho[i] = SPHParticleDensity(i, x, fs, fn, bx, bs, bn, densityConstants);
        pressure[i] = this->PressureOf(rho[i]);
        pressureTerm[i] = pressure[i] / (rho[i] * rho[i]);
        inverseDensity[i] = 1.0 / rho[i];
      }
    },
    ParallelThreshold);

  // Pressure of the dummies next to the fluid, extrapolated from their fluid neighbours with the hydrostatic
  // increase (Adami, Hu & Adams 2012, eq. 27 for static walls): p_b = (sum_f p_f W + g . sum_f rho_f (x_b - x_f) W)
  // / sum_f W, and their density from the equation of state.
  const double g[3] = { p.Gravity[0], p.Gravity[1], p.Gravity[2] };
  const Index nb = this->BoundaryCount;
  if (nb > 0)
  {
    this->BoundaryPressureTerm.assign(nb, 0.0);
    this->BoundaryActive.assign(nb, 0);
    const Index total = bs[n];
    ParallelFor(
      total, 1024,
      [&](Index begin, Index end) {
        for (Index s = begin; s < end; ++s)
        {
          this->BoundaryActive[bn[s]] = 1; // same value from every thread
        }
      },
      ParallelThreshold);
    double* pbTerm = this->BoundaryPressureTerm.data();
    const char* active = this->BoundaryActive.data();
    std::vector<std::vector<Index>> threadIds(MaxThreads());
    ParallelFor(
      nb, 256,
      [&](Index begin, Index end) {
        std::vector<Index>& ids = threadIds[ThreadIndex()];
        for (Index b = begin; b < end; ++b)
        {
          if (!active[b])
          {
            continue;
          }
          const double* xb = bx + 3 * b;
          this->Grid.FindWithinRadius(xb, h, ids);
          double sumW = 0.0, sumP = 0.0, sumG = 0.0;
          for (Index f : ids)
          {
            const double* xf = x + 3 * f;
            const double r[3] = { xb[0] - xf[0], xb[1] - xf[1], xb[2] - xf[2] };
            const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            if (r2 < h2)
            {
              const double w = this->DensityShape(r2);
              sumW += w;
              sumP += pressure[f] * w;
              sumG += rho[f] * (g[0] * r[0] + g[1] * r[1] + g[2] * r[2]) * w;
            }
          }
          const double pb = sumW > 0.0 ? std::max(0.0, (sumP + sumG) / sumW) : 0.0;
          const double rhoB = this->DensityOf(pb);
          pbTerm[b] = pb / (rhoB * rhoB); // the pair force's p_b / rho_b^2, once per dummy
        }
      },
      n >= ParallelThreshold ? 0 : nb + 1);
  }
  const double* pbTerm = this->BoundaryPressureTerm.data();

  // Forces: pressure (5.37, symmetric), viscosity (5.46), colour-field surface tension, gravity.
  const double mu = p.Viscosity, sigma = p.SurfaceTension;
  const bool viscous = mu > 0.0, tension = sigma > 0.0;
  const int d = p.Dimension;
  // Monaghan's artificial viscosity: Pi_ij = -alpha c0 hs (v_ij . r_ij) / (rho_bar (r^2 + 0.01 hs^2)) for
  // approaching pairs, hs = h / 2 the smoothing length of the support radius h.
  const double hs = 0.5 * h;
  const double avFactor = p.ArtificialViscosity * this->C0 * hs, avEps = 0.01 * hs * hs;
  const bool artificial = avFactor > 0.0;
  const double pressureFactor = m * gradientNorm, viscousFactor = mu * m * visc;
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        const double* xi = x + 3 * i;
        const double* vi = v + 3 * i;
        const double rhoI = rho[i], inverseI = inverseDensity[i];
        const double termI = pressureTerm[i];
        double ap[3] = { 0.0, 0.0, 0.0 }, av[3] = { 0.0, 0.0, 0.0 }, normal[3] = { 0.0, 0.0, 0.0 };
        double colourLaplacian = 0.0;
        // Colour field c = sum_j V_j W_poly6: grad W = gradient r, lap W = -6 poly6 q (d q - 4 r^2), q = h^2 - r^2.
        auto addColour = [&](double volume, const double r[3], double r2) {
          const double q = h2 - r2;
          const double gradient = -6.0 * poly6 * q * q;
          normal[0] += volume * gradient * r[0];
          normal[1] += volume * gradient * r[1];
          normal[2] += volume * gradient * r[2];
          colourLaplacian += volume * -6.0 * poly6 * q * (d * q - 4.0 * r2);
        };
        for (Index s = fs[i]; s < fs[i + 1]; ++s)
        {
          const Index j = fn[s];
          const double* xj = x + 3 * j;
          const double r[3] = { xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2] };
          const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
          if (!(r2 < h2))
          {
            continue;
          }
          const double dist = std::sqrt(r2);
          if (dist > 0.0)
          {
            // -m (p_i/rho_i^2 + p_j/rho_j^2) grad W, grad W = -gradientNorm shape(r) r
            double pair = termI + pressureTerm[j];
            if (artificial)
            {
              const double* vj = v + 3 * j;
              const double vr = (vi[0] - vj[0]) * r[0] + (vi[1] - vj[1]) * r[1] + (vi[2] - vj[2]) * r[2];
              pair += vr < 0.0 ? -avFactor * vr / (0.5 * (rhoI + rho[j]) * (r2 + avEps)) : 0.0;
            }
            const double coefficient = pressureFactor * pair * this->GradientShape(r2, dist);
            ap[0] += coefficient * r[0];
            ap[1] += coefficient * r[1];
            ap[2] += coefficient * r[2];
          }
          if (viscous)
          {
            const double coefficient = viscousFactor * (h - dist) * inverseI * inverseDensity[j];
            const double* vj = v + 3 * j;
            av[0] += coefficient * (vj[0] - vi[0]);
            av[1] += coefficient * (vj[1] - vi[1]);
            av[2] += coefficient * (vj[2] - vi[2]);
          }
          if (tension)
          {
            addColour(m * inverseDensity[j], r, r2);
          }
        }
        for (Index s = bs[i]; s < bs[i + 1]; ++s)
        {
          const Index b = bn[s];
          const double* xb = bx + 3 * b;
          const double r[3] = { xi[0] - xb[0], xi[1] - xb[1], xi[2] - xb[2] };
          const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
          if (!(r2 < h2))
          {
            continue;
          }
          const double dist = std::sqrt(r2);
          if (dist > 0.0)
          {
            // Symmetric pair force with the dummy's extrapolated pressure (its density from the EOS).
            // No artificial viscosity against the wall: with a particle sliding along it, the dummies ahead are
            // approached and those behind are not, so the term would act as wall friction (free slip wanted).
            const double pair = termI + pbTerm[b];
            const double coefficient = pressureFactor * pair * this->GradientShape(r2, dist);
            ap[0] += coefficient * r[0];
            ap[1] += coefficient * r[1];
            ap[2] += coefficient * r[2];
          }
          if (tension)
          {
            addColour(m / p.RestDensity, r, r2); // walls count as fluid (neutral wetting): no surface along them
          }
        }
        double* ai = acc + 3 * i;
        ai[0] = ap[0] + av[0] + g[0];
        ai[1] = ap[1] + av[1] + g[1];
        ai[2] = ap[2] + av[2] + g[2];
        if (tension)
        {
          const double length = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
          if (length * h > SurfaceThreshold)
          {
            const double factor = -sigma * colourLaplacian * inverseI / length;
            ai[0] += factor * normal[0];
            ai[1] += factor * normal[1];
            ai[2] += factor * normal[2];
          }
        }
        if (d == 2)
        {
          ai[1] = 0.0;
        }
      }
    },
    ParallelThreshold);
}

void SPHFluid::Enforce(SPHState& state, Index begin, Index end) const
{
  const SPHParameters& p = this->Params;
  const bool obstacles = !this->ObstaclePosition.empty();
  std::vector<Index> nearest(1);
  std::vector<double> nearestD2(1);
  for (Index i = begin; i < end; ++i)
  {
    double* x = &state.Position[3 * i];
    double* v = &state.Velocity[3 * i];
    if (p.Walls)
    {
      for (int a = 0; a < 3; ++a)
      {
        if (a == 1 && p.Dimension == 2)
        {
          continue;
        }
        const double low = p.DomainBounds[2 * a] + this->WallMargin;
        const double high = p.DomainBounds[2 * a + 1] - this->WallMargin;
        if (x[a] < low)
        {
          x[a] = low;
          v[a] = std::max(v[a], 0.0);
        }
        else if (x[a] > high)
        {
          x[a] = high;
          v[a] = std::min(v[a], 0.0);
        }
      }
    }
    if (obstacles && this->NearObstacle(x) && this->ObstacleGrid.FindKNearest(x, 1, nearest, nearestD2) == 1)
    {
      const double* s = &this->ObstaclePosition[3 * nearest[0]];
      const double* nrm = &this->ObstacleNormal[3 * nearest[0]];
      const double depth = (x[0] - s[0]) * nrm[0] + (x[1] - s[1]) * nrm[1] + (x[2] - s[2]) * nrm[2];
      if (depth < this->WallMargin)
      {
        const double push = this->WallMargin - depth;
        const double vn = v[0] * nrm[0] + v[1] * nrm[1] + v[2] * nrm[2];
        for (int a = 0; a < 3; ++a)
        {
          x[a] += push * nrm[a];
          v[a] -= vn < 0.0 ? vn * nrm[a] : 0.0;
        }
      }
    }
  }
}

void SPHFluid::Reorder(SPHState& state)
{
  const Index n = state.Size();
  this->Grid.Build(state.Position.data(), n, this->H);
  const std::vector<Index>& order = this->Grid.SortedOrder();
  if (static_cast<Index>(order.size()) != n)
  {
    return;
  }
  auto permute3 = [&](std::vector<double>& a) {
    std::vector<double> b(a.size());
    ParallelFor(
      n, 8192,
      [&](Index begin, Index end) {
        for (Index s = begin; s < end; ++s)
        {
          b[3 * s] = a[3 * order[s]];
          b[3 * s + 1] = a[3 * order[s] + 1];
          b[3 * s + 2] = a[3 * order[s] + 2];
        }
      },
      ParallelThreshold);
    a.swap(b);
  };
  permute3(state.Position);
  permute3(state.Velocity);
  permute3(state.Acceleration);
  std::vector<std::int64_t> id(n);
  for (Index s = 0; s < n; ++s)
  {
    id[s] = state.Id[order[s]];
  }
  state.Id.swap(id);
  // Density and pressure are recomputed by the next force evaluation.
}

double SPHFluid::StableTimeStep(const SPHState& state, double lambda) const
{
  const Index n = state.Size();
  struct Extremes
  {
    double V2 = 0.0, A2 = 0.0, Rho = 0.0;
    bool Finite = true;
  };
  Extremes identity;
  identity.Rho = this->Params.RestDensity;
  const Extremes e = ParallelReduce(
    n, 4096, identity,
    [&](Index begin, Index end) {
      Extremes m = identity;
      for (Index i = begin; i < end; ++i)
      {
        const double* v = &state.Velocity[3 * i];
        const double* a = &state.Acceleration[3 * i];
        const double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        const double a2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
        m.Finite = m.Finite && std::isfinite(v2) && std::isfinite(a2) && std::isfinite(state.Density[i]);
        m.V2 = std::max(m.V2, v2);
        m.A2 = std::max(m.A2, a2);
        m.Rho = std::max(m.Rho, state.Density[i]);
      }
      return m;
    },
    [](Extremes x, const Extremes& y) {
      x.V2 = std::max(x.V2, y.V2);
      x.A2 = std::max(x.A2, y.A2);
      x.Rho = std::max(x.Rho, y.Rho);
      x.Finite = x.Finite && y.Finite;
      return x;
    },
    ParallelThreshold);
  const double v2max = e.V2, a2max = e.A2, rhoMax = e.Rho;
  const bool finite = e.Finite;
  if (!finite)
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  double c = this->C0;
  if (this->Params.EquationOfState == SPHEquationOfState::Tait)
  {
    const double ratio = rhoMax / this->Params.RestDensity; // c^2 = dp/drho = c0^2 (rho/rho0)^6
    c *= ratio * ratio * ratio;
  }
  const double h = this->H;
  double dt = h / (c + std::sqrt(v2max));
  const double amax = std::sqrt(a2max);
  if (amax > 0.0)
  {
    dt = std::min(dt, std::sqrt(h / amax));
  }
  if (this->Nu > 0.0)
  {
    dt = std::min(dt, 0.125 * h * h / this->Nu);
  }
  return lambda * dt;
}

SPHFluid::Status SPHFluid::Advance(SPHState& state, double targetTime, const ProgressFunction& progress)
{
  const SPHParameters& p = this->Params;
  const double start = state.Time;
  if (!(targetTime >= start) || !std::isfinite(targetTime))
  {
    this->Error = "the target time lies before the state's time";
    return Status::Failed;
  }
  const Index n = state.Size();
  long steps = 0;
  while (state.Time < targetTime)
  {
    const double remaining = targetTime - state.Time;
    if (n == 0)
    {
      state.Time = targetTime;
      break;
    }
    double dt;
    if (p.CFLNumber > 0.0)
    {
      dt = std::min(p.TimeStep, this->StableTimeStep(state, std::min(p.CFLNumber, StabilityLambda)));
    }
    else
    {
      const double stable = this->StableTimeStep(state, StabilityLambda);
      dt = p.TimeStep;
      if (dt > stable)
      {
        dt = stable;
        ++this->ReducedStepCount;
      }
    }
    if (!(dt > 0.0) || !std::isfinite(dt))
    {
      std::ostringstream s;
      s << "the simulation became unstable (non-finite velocity, acceleration or density) at t = " << state.Time;
      this->Error = s.str();
      return Status::Failed;
    }
    bool last = false;
    if (dt >= remaining)
    {
      dt = remaining;
      last = true;
    }
    else if (dt > 0.5 * remaining)
    {
      dt = 0.5 * remaining; // two equal steps rather than a sliver at the end
    }
    if (remaining / dt > static_cast<double>(p.MaximumStepsPerInterval - steps))
    {
      std::ostringstream s;
      s << "the time step collapsed to " << dt << " s at t = " << state.Time << ": reaching t = " << targetTime
        << " would take more than " << p.MaximumStepsPerInterval
        << " steps (is GasStiffness or the velocity absurdly large?)";
      this->Error = s.str();
      return Status::Failed;
    }

    // Kick - drift (with the wall and obstacle projection).
    const double half = 0.5 * dt;
    ParallelFor(
      n, 2048,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          double* x = &state.Position[3 * i];
          double* v = &state.Velocity[3 * i];
          const double* a = &state.Acceleration[3 * i];
          for (int c = 0; c < 3; ++c)
          {
            v[c] += half * a[c];
            x[c] += dt * v[c];
          }
        }
        this->Enforce(state, begin, end);
      },
      ParallelThreshold);
    if (state.Steps % p.ReorderInterval == 0)
    {
      this->Reorder(state);
    }
    this->ComputeAccelerations(state);
    // Kick.
    ParallelFor(
      3 * n, 16384,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          state.Velocity[i] += half * state.Acceleration[i];
        }
      },
      ParallelThreshold);
    state.Time = last ? targetTime : state.Time + dt;
    ++state.Steps;
    ++steps;
    if (progress && (steps & 15) == 0 && !progress((state.Time - start) / (targetTime - start)))
    {
      return Status::Aborted;
    }
  }
  return Status::Ok;
}

std::vector<int> SPHFluid::NeighborCounts(const SPHState& state)
{
  const Index n = state.Size();
  std::vector<int> counts(n, 0);
  if (n == 0)
  {
    return counts;
  }
  this->Grid.Build(state.Position.data(), n, this->H);
  std::vector<std::vector<Index>> threadIds(MaxThreads());
  std::vector<std::vector<double>> threadDistances(MaxThreads());
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      std::vector<Index>& ids = threadIds[ThreadIndex()];
      std::vector<double>& d2 = threadDistances[ThreadIndex()];
      for (Index i = begin; i < end; ++i)
      {
        // Strictly inside the support, as the sums count them.
        Index c = 0;
        const double* xi = &state.Position[3 * i];
        this->Grid.FindWithinRadius(xi, this->H, ids, &d2);
        for (std::size_t k = 0; k < ids.size(); ++k)
        {
          c += (ids[k] != i && d2[k] < this->H2) ? 1 : 0;
        }
        counts[i] = static_cast<int>(c);
      }
    },
    ParallelThreshold);
  return counts;
}

SPHStatistics SPHFluid::Statistics(const SPHState& state, double mass)
{
  SPHStatistics s;
  const Index n = state.Size();
  s.MinDensity = n > 0 ? std::numeric_limits<double>::max() : 0.0;
  s.MaxDensity = 0.0;
  for (Index i = 0; i < n; ++i)
  {
    const double* v = &state.Velocity[3 * i];
    const double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    for (int a = 0; a < 3; ++a)
    {
      s.Momentum[a] += mass * v[a];
    }
    s.KineticEnergy += 0.5 * mass * v2;
    s.MaxSpeed = std::max(s.MaxSpeed, std::sqrt(v2));
    s.MinDensity = std::min(s.MinDensity, state.Density[i]);
    s.MaxDensity = std::max(s.MaxDensity, state.Density[i]);
    s.Finite = s.Finite && std::isfinite(v2) && std::isfinite(state.Position[3 * i]) &&
      std::isfinite(state.Position[3 * i + 1]) && std::isfinite(state.Position[3 * i + 2]) &&
      std::isfinite(state.Density[i]) && std::isfinite(state.Pressure[i]);
  }
  return s;
}

} // namespace meshfree
