// SPDX-License-Identifier: BSD-3-Clause
// Time integration of the meshless elastic solid: symplectic Euler [4.28-4.30], contacts [4.26], containers and
// plasticity. The implicit integrator is in ElasticImplicit.cxx.
#include "Common/Parallel.h"
#include "Elastic/ElasticMath.h"
#include "Elastic/ElasticSolid.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{

bool ElasticSolid::AreNeighbors(Index i, Index j) const
{
  const Index* row = &this->Neighbor[i * this->K];
  for (int t = 0; t < this->K && row[t] >= 0; ++t)
  {
    if (row[t] == j)
    {
      return true;
    }
  }
  return false;
}

void ElasticSolid::AddContactForces(const double* x, std::vector<double>& f)
{
  if (!this->Config.Contacts || this->N < 2)
  {
    return;
  }
  const double alpha = this->ContactDistance;
  const double reach = std::pow(2.0, 1.0 / 6.0) * alpha; // LJ minimum: repulsive part only
  const double a6 = std::pow(alpha, 6), a12 = a6 * a6;
  const double beta = this->ContactBeta, cap = this->ContactCap;
  // Only surface phyxels can meet a non-neighbour before the surface itself is crossed: the grid holds them
  // alone (about n^(2/3) of n), which makes contact detection cheap for large bodies.
  const Index m = static_cast<Index>(this->SurfacePhyxels.size());
  this->ContactPositions.resize(3 * m);
  for (Index s = 0; s < m; ++s)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->ContactPositions[3 * s + a] = x[3 * this->SurfacePhyxels[s] + a];
    }
  }
  this->ContactGrid.Build(this->ContactPositions.data(), m, reach);
  PerThread<std::vector<Index>> idsPerThread;
  PerThread<std::vector<double>> d2PerThread;
  ParallelFor(
    m, 256,
    [&](Index begin, Index end) {
      std::vector<Index>& ids = idsPerThread.Local();
      std::vector<double>& d2 = d2PerThread.Local();
      for (Index s = begin; s < end; ++s)
      {
        const Index i = this->SurfacePhyxels[s];
        this->ContactGrid.FindWithinRadius(x + 3 * i, reach, ids, &d2);
        for (size_t t = 0; t < ids.size(); ++t)
        {
          const Index j = this->SurfacePhyxels[ids[t]];
          if (j == i || !(d2[t] > 0.0))
          {
            continue;
          }
          // Rest neighbours are held by elasticity; only the others collide. The criterion is symmetric, so
          // the pair forces are equal and opposite.
          if (this->AreNeighbors(i, j) || this->AreNeighbors(j, i))
          {
            continue;
          }
          const double d = std::sqrt(d2[t]);
          const double d6 = d2[t] * d2[t] * d2[t];
          double L = 4.0 * beta * (12.0 * a12 / (d6 * d6 * d) - 6.0 * a6 / (d6 * d)); // [4.26]
          L = std::min(std::max(L, 0.0), cap);
          for (int a = 0; a < 3; ++a)
          {
            f[3 * i + a] += L * (x[3 * i + a] - x[3 * j + a]) / d;
          }
        }
      }
    },
    kElasticParallel + 1);
}

void ElasticSolid::AddExternalForces(std::vector<double>& f) const
{
  if (this->External.size() == f.size())
  {
    for (size_t c = 0; c < f.size(); ++c)
    {
      f[c] += this->External[c];
    }
  }
}

void ElasticSolid::ApplyContainer(double* x, double* v) const
{
  const ElasticSettings& s = this->Config;
  if (s.Container == ElasticContainer::None)
  {
    return;
  }
  const Index n = this->N;
  const double radius = 0.5 * this->ContactDistance;
  const double e = s.Restitution, mu = s.Friction;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = s.ContainerBounds[2 * a] + radius;
    hi[a] = s.ContainerBounds[2 * a + 1] - radius;
    if (lo[a] > hi[a])
    {
      lo[a] = hi[a] = 0.5 * (s.ContainerBounds[2 * a] + s.ContainerBounds[2 * a + 1]);
    }
  }
  const double cx = 0.5 * (s.ContainerBounds[0] + s.ContainerBounds[1]);
  const double cy = 0.5 * (s.ContainerBounds[2] + s.ContainerBounds[3]);
  const double R = std::max(0.0,
    0.5 * std::min(s.ContainerBounds[1] - s.ContainerBounds[0], s.ContainerBounds[3] - s.ContainerBounds[2]) -
      radius);
  // Reflect the normal velocity with restitution; Coulomb friction removes up to mu |dv_n| tangentially.
  auto collide = [e, mu](double* vel, const double nrm[3]) {
    const double vn = vel[0] * nrm[0] + vel[1] * nrm[1] + vel[2] * nrm[2];
    if (vn >= 0.0)
    {
      return;
    }
    double vt[3];
    for (int a = 0; a < 3; ++a)
    {
      vt[a] = vel[a] - vn * nrm[a];
    }
    const double vtNorm = std::sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]);
    const double keep = vtNorm > 0.0 ? std::max(0.0, 1.0 - mu * (1.0 + e) * (-vn) / vtNorm) : 0.0;
    for (int a = 0; a < 3; ++a)
    {
      vel[a] = keep * vt[a] - e * vn * nrm[a];
    }
  };
  ParallelFor(
    n, 2048,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        double* p = x + 3 * i;
        double* vel = v + 3 * i;
        const int firstAxis = s.Container == ElasticContainer::Box ? 0 : 2;
        for (int a = firstAxis; a < 3; ++a)
        {
          double nrm[3] = { 0, 0, 0 };
          if (p[a] < lo[a])
          {
            p[a] = lo[a];
            nrm[a] = 1.0;
            collide(vel, nrm);
          }
          else if (p[a] > hi[a])
          {
            p[a] = hi[a];
            nrm[a] = -1.0;
            collide(vel, nrm);
          }
        }
        if (s.Container == ElasticContainer::Cylinder)
        {
          const double rx = p[0] - cx, ry = p[1] - cy;
          const double r = std::sqrt(rx * rx + ry * ry);
          if (r > R)
          {
            const double nrm[3] = { r > 0 ? -rx / r : -1.0, r > 0 ? -ry / r : 0.0, 0.0 };
            p[0] = cx - nrm[0] * R;
            p[1] = cy - nrm[1] * R;
            collide(vel, nrm);
          }
        }
      }
    },
    kElasticParallel + 1);
}

void ElasticSolid::UpdatePlasticity(double dt)
{
  if (this->Current.PlasticStrain.empty() || this->DefGrad.size() != 9 * static_cast<size_t>(this->N))
  {
    return;
  }
  const ElasticSettings& s = this->Config;
  const double creep = std::min(1.0, dt * s.PlasticCreep);
  ParallelFor(
    this->N, 1024,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        const double* F = &this->DefGrad[9 * i];
        double* Ep = &this->Current.PlasticStrain[6 * i];
        double C[6];
        // Green strain of the last force evaluation, minus the plastic part: the elastic strain.
        C[0] = 0.5 * (F[0] * F[0] + F[3] * F[3] + F[6] * F[6] - 1.0);
        C[1] = 0.5 * (F[1] * F[1] + F[4] * F[4] + F[7] * F[7] - 1.0);
        C[2] = 0.5 * (F[2] * F[2] + F[5] * F[5] + F[8] * F[8] - 1.0);
        C[3] = 0.5 * (F[0] * F[1] + F[3] * F[4] + F[6] * F[7]);
        C[4] = 0.5 * (F[1] * F[2] + F[4] * F[5] + F[7] * F[8]);
        C[5] = 0.5 * (F[0] * F[2] + F[3] * F[5] + F[6] * F[8]);
        double norm2 = 0.0;
        for (int a = 0; a < 6; ++a)
        {
          C[a] -= Ep[a];
          norm2 += (a < 3 ? 1.0 : 2.0) * C[a] * C[a];
        }
        if (std::sqrt(norm2) > s.PlasticYield) // Mueller 2004 sec. 5: yield, creep
        {
          double pnorm2 = 0.0;
          for (int a = 0; a < 6; ++a)
          {
            Ep[a] += creep * C[a];
            pnorm2 += (a < 3 ? 1.0 : 2.0) * Ep[a] * Ep[a];
          }
          const double pnorm = std::sqrt(pnorm2);
          if (s.PlasticMaxStrain > 0.0 && pnorm > s.PlasticMaxStrain) // maximum plastic strain
          {
            for (int a = 0; a < 6; ++a)
            {
              Ep[a] *= s.PlasticMaxStrain / pnorm;
            }
          }
        }
      }
    },
    kElasticParallel + 1);
}

void ElasticSolid::StepSymplectic(double dt)
{
  const Index n = this->N;
  double* x = this->Current.Position.data();
  double* v = this->Current.Velocity.data();
  this->ComputeInternalForces(x, this->Force);
  this->AddContactForces(x, this->Force);
  this->AddExternalForces(this->Force);
  const double* g = this->Config.Gravity;
  const double damp = 1.0 / (1.0 + dt * this->Config.Damping);
  ParallelFor(
    n, 4096,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        if (this->IsFixed[i])
        {
          for (int a = 0; a < 3; ++a)
          {
            v[3 * i + a] = 0.0;
            x[3 * i + a] = this->Rest[3 * i + a];
          }
          continue;
        }
        const double invM = 1.0 / this->Mass[i];
        for (int a = 0; a < 3; ++a) // [4.28-4.30]: velocity first, then position with the new velocity
        {
          v[3 * i + a] = (v[3 * i + a] + dt * (this->Force[3 * i + a] * invM + g[a])) * damp;
          x[3 * i + a] += dt * v[3 * i + a];
        }
      }
    },
    kElasticParallel + 1);
  this->ApplyContainer(x, v);
  this->UpdatePlasticity(dt);
  this->Current.Time += dt;
  ++this->Steps;
}

bool ElasticSolid::Advance(double duration, double maxStep, bool implicit, const std::function<bool()>& abort)
{
  if (this->N == 0 || !(duration > 0.0))
  {
    return true;
  }
  double step = maxStep > 0.0 ? maxStep : this->StableTimeStep();
  if (!implicit)
  {
    step = std::min(step, this->StableTimeStep());
  }
  const long count = std::max(1L, static_cast<long>(std::ceil(duration / step - 1e-9)));
  const double dt = duration / count;
  const double start = this->Current.Time;
  for (long s = 0; s < count; ++s)
  {
    if (abort && (s % 16) == 0 && abort())
    {
      return false;
    }
    if (implicit)
    {
      double residual = 0.0;
      this->StepImplicit(dt, residual);
    }
    else
    {
      this->StepSymplectic(dt);
    }
  }
  this->Current.Time = start + duration;
  return true;
}

} // namespace meshfree
