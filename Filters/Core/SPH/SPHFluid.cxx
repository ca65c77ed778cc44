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
constexpr Index ParallelThreshold = 4096; // below: one thread (a fork-join would cost more than the work)
constexpr double kLandingSlack = 1e-9;    // a step this close (relative) to the remaining time lands on the target
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
  this->InvalidateFields();
  const Index n = state.Size();
  if (n == 0)
  {
    return;
  }
  this->Grid.SetCellsByPosition(false); // the particles' own order: the CUDA integrator rebuilds it (SPHDevice.h)
  this->Grid.Build(state.Position.data(), n, this->H);
  this->BuildNeighborLists(state, true);
  const double* x = state.Position.data();
  const double* v = state.Velocity.data();
  double* rho = state.Density.data();
  double* pressure = state.Pressure.data();
  double* acc = state.Acceleration.data();
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
  const SPHConstants& c = this->Physics;
  const SPHDensityConstants densityConstants = SPHDensityConstantsOf(c);
  ParallelFor(
    n, 512,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        rho[i] = SPHParticleDensity(i, x, fs, fn, bx, bs, bn, densityConstants);
        SPHParticleTerms(rho[i], c, pressure + i, pressureTerm + i, inverseDensity + i);
      }
    },
    ParallelThreshold);

  // Pressure of the dummies next to the fluid, extrapolated from their fluid neighbours (SPHWallPressure), and
  // their density from the equation of state.
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
    PerThread<std::vector<Index>> threadIds;
    ParallelFor(
      nb, 256,
      [&](Index begin, Index end) {
        std::vector<Index>& ids = threadIds.Local();
        for (Index b = begin; b < end; ++b)
        {
          if (!active[b])
          {
            continue;
          }
          const double* xb = bx + 3 * b;
          this->Grid.FindWithinRadius(xb, c.H, ids);
          SPHWallPressure wall;
          for (Index f : ids)
          {
            const double* xf = x + 3 * f;
            const double r[3] = { xb[0] - xf[0], xb[1] - xf[1], xb[2] - xf[2] };
            const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            wall.Add(r, r2, pressure[f], rho[f], c);
          }
          pbTerm[b] = wall.Term(c); // the pair force's p_b / rho_b^2, once per dummy
        }
      },
      n >= ParallelThreshold ? 0 : nb + 1);
  }
  const double* pbTerm = this->BoundaryPressureTerm.data();

  // Forces: pressure (5.37, symmetric), viscosity (5.46), colour-field surface tension, gravity (SPHAcceleration).
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        SPHAcceleration a(x + 3 * i, v + 3 * i, rho[i], inverseDensity[i], pressureTerm[i]);
        for (Index s = fs[i]; s < fs[i + 1]; ++s)
        {
          const Index j = fn[s];
          a.Fluid(x + 3 * j, v + 3 * j, rho[j], inverseDensity[j], pressureTerm[j], c);
        }
        for (Index s = bs[i]; s < bs[i + 1]; ++s)
        {
          const Index b = bn[s];
          a.Wall(bx + 3 * b, pbTerm[b], c);
        }
        a.Finish(acc + 3 * i, c);
      }
    },
    ParallelThreshold);
}

Index SPHFluid::ObstacleSample(const double* x, std::vector<Index>& ids, std::vector<double>& d2, double& depth) const
{
  const int found = this->ObstacleGrid.FindKNearest(x, 8, ids, d2);
  Index best = -1;
  for (int j = 0; j < found && d2[j] == d2[0]; ++j)
  {
    const double* s = &this->ObstaclePosition[3 * ids[j]];
    const double* n = &this->ObstacleNormal[3 * ids[j]];
    const double d = (x[0] - s[0]) * n[0] + (x[1] - s[1]) * n[1] + (x[2] - s[2]) * n[2];
    if (best < 0 || d > depth)
    {
      best = ids[j];
      depth = d;
    }
  }
  return best;
}

void SPHFluid::Enforce(SPHState& state, Index begin, Index end) const
{
  const bool obstacles = !this->ObstaclePosition.empty();
  std::vector<Index> nearest(8);
  std::vector<double> nearestD2(8);
  for (Index i = begin; i < end; ++i)
  {
    double* x = &state.Position[3 * i];
    double* v = &state.Velocity[3 * i];
    SPHWallClamp(x, v, this->Physics);
    double depth = 0.0;
    const Index sample = obstacles && this->NearObstacle(x) ? this->ObstacleSample(x, nearest, nearestD2, depth) : -1;
    if (sample >= 0)
    {
      const double* nrm = &this->ObstacleNormal[3 * sample];
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
  this->InvalidateFields();
  const Index n = state.Size();
  this->Grid.SetCellsByPosition(false); // the particles' own order: the CUDA integrator rebuilds it (SPHDevice.h)
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
  auto permute1 = [&](std::vector<double>& a) {
    if (static_cast<Index>(a.size()) != n)
    {
      return;
    }
    std::vector<double> b(n);
    for (Index s = 0; s < n; ++s)
    {
      b[s] = a[order[s]];
    }
    a.swap(b);
  };
  permute1(state.DensityStiffness); // DFSPH's warm start (empty for WCSPH)
  permute1(state.DivergenceStiffness);
  permute1(this->PressureImpulse); // DFSPH: the pressure impulse summed over the Advance() call's steps so far
  // Density and pressure are recomputed by the next force evaluation.
}

SPHExtremes SPHFluid::Extremes(const SPHState& state) const
{
  const Index n = state.Size();
  SPHExtremes identity;
  identity.Rho = this->Params.RestDensity;
  return ParallelReduce(
    n, 4096, identity,
    [&](Index begin, Index end) {
      SPHExtremes m = identity;
      for (Index i = begin; i < end; ++i)
      {
        m.Add(&state.Velocity[3 * i], &state.Acceleration[3 * i], state.Density[i]);
      }
      return m;
    },
    [](SPHExtremes x, const SPHExtremes& y) {
      x.Merge(y);
      return x;
    },
    ParallelThreshold);
}

double SPHFluid::StableTimeStep(const SPHState& state, double lambda) const
{
  return SPHStableStep(this->Extremes(state), lambda, this->Physics);
}

bool SPHFluid::ChooseStep(const SPHExtremes& e, double time, double targetTime, long steps, double& dt, bool& last)
{
  const SPHParameters& p = this->Params;
  if (p.CFLNumber > 0.0)
  {
    dt = std::min(p.TimeStep, SPHStableStep(e, std::min(p.CFLNumber, StabilityLambda), this->Physics));
  }
  else
  {
    const double stable = SPHStableStep(e, StabilityLambda, this->Physics);
    dt = p.TimeStep;
    if (dt > stable)
    {
      dt = stable;
      ++this->ReducedStepCount;
    }
  }
  return this->LandStep(time, targetTime, steps, dt, last);
}

bool SPHFluid::LandStep(double time, double targetTime, long steps, double& dt, bool& last)
{
  const SPHParameters& p = this->Params;
  const double remaining = targetTime - time;
  if (!(dt > 0.0) || !std::isfinite(dt))
  {
    std::ostringstream s;
    s << "the simulation became unstable (non-finite velocity, acceleration or density) at t = " << time;
    this->Error = s.str();
    return false;
  }
  last = false;
  // A remainder within rounding of the step is the last step: n fixed steps of dt summed to t + n dt leave a
  // remainder of dt plus a few ulps, which must not become two half steps (kLandingSlack, relative).
  if (dt >= remaining * (1.0 - kLandingSlack))
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
    s << "the time step collapsed to " << dt << " s at t = " << time << ": reaching t = " << targetTime
      << " would take more than " << p.MaximumStepsPerInterval
      << " steps (is GasStiffness or the velocity absurdly large?)";
    this->Error = s.str();
    return false;
  }
  return true;
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
  this->LastBackend = SPHBackend::CPU;
  this->DeviceNote.clear();
  if (p.Solver == SPHSolver::DFSPH)
  {
    if (this->RequestedBackend == SPHBackend::CUDA)
    {
      this->DeviceNote = "the DFSPH solver runs on the CPU only";
    }
    return this->AdvanceDivergenceFree(state, targetTime, progress);
  }
  if (this->RequestedBackend == SPHBackend::CUDA)
  {
    bool declined = false;
    const Status status = this->AdvanceOnDevice(state, targetTime, progress, declined);
    if (!declined)
    {
      this->LastBackend = SPHBackend::CUDA;
      return status;
    }
  }
  const Index n = state.Size();
  long steps = 0;
  while (state.Time < targetTime)
  {
    if (n == 0)
    {
      state.Time = targetTime;
      break;
    }
    double dt;
    bool last;
    if (!this->ChooseStep(this->Extremes(state), state.Time, targetTime, steps, dt, last))
    {
      return Status::Failed;
    }

    // Kick - drift (with the wall and obstacle projection).
    const double half = 0.5 * dt;
    ParallelFor(
      n, 2048,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          SPHKickDrift(&state.Position[3 * i], &state.Velocity[3 * i], &state.Acceleration[3 * i], half, dt);
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
          SPHKick(&state.Velocity[i], &state.Acceleration[i], half);
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
  this->InvalidateFields();
  const Index n = state.Size();
  std::vector<int> counts(n, 0);
  if (n == 0)
  {
    return counts;
  }
  this->Grid.SetCellsByPosition(false); // the particles' own order: the CUDA integrator rebuilds it (SPHDevice.h)
  this->Grid.Build(state.Position.data(), n, this->H);
  PerThread<std::vector<Index>> threadIds;
  PerThread<std::vector<double>> threadDistances;
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      std::vector<Index>& ids = threadIds.Local();
      std::vector<double>& d2 = threadDistances.Local();
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
