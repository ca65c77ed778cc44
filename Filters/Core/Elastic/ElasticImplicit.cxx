// SPDX-License-Identifier: BSD-3-Clause
// Implicit integration of the meshless elastic solid: linearised backward Euler (M - dt^2 K) v+ = M v + dt F
// [4.31-4.42], solved matrix-free by Jacobi-preconditioned conjugate gradients.
#include "Common/Parallel.h"
#include "Elastic/ElasticMath.h"
#include "Elastic/ElasticSolid.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace meshfree
{

// Walls inside the implicit solve (Baraff & Witkin's constraint filter): a phyxel lying on a wall that the step
// would push into it gets S = I - n n^T, which removes the normal component of its velocity from the CG
// solution. Without it the solve sees a free fall and only the post-step projection stops the bottom layer,
// so large steps squash the body.
void ElasticSolid::WallFilter(const double* x, const double* push, std::vector<double>& S) const
{
  const ElasticSettings& s = this->Config;
  const Index n = this->N;
  S.assign(9 * n, 0.0);
  const double radius = 0.5 * this->ContactDistance, tol = 1e-6 * radius;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = s.ContainerBounds[2 * a] + radius;
    hi[a] = s.ContainerBounds[2 * a + 1] - radius;
  }
  const double cx = 0.5 * (s.ContainerBounds[0] + s.ContainerBounds[1]);
  const double cy = 0.5 * (s.ContainerBounds[2] + s.ContainerBounds[3]);
  const double R = 0.5 * std::min(s.ContainerBounds[1] - s.ContainerBounds[0],
                          s.ContainerBounds[3] - s.ContainerBounds[2]) - radius;
  for (Index i = 0; i < n; ++i)
  {
    double* M = &S[9 * i];
    M[0] = M[4] = M[8] = 1.0;
    if (s.Container == ElasticContainer::None)
    {
      continue;
    }
    const double* p = x + 3 * i;
    const double* b = push + 3 * i;
    auto remove = [M](const double nrm[3]) {
      for (int a = 0; a < 3; ++a)
      {
        for (int c = 0; c < 3; ++c)
        {
          M[a * 3 + c] -= nrm[a] * nrm[c];
        }
      }
    };
    const int firstAxis = s.Container == ElasticContainer::Box ? 0 : 2;
    for (int a = firstAxis; a < 3; ++a)
    {
      double nrm[3] = { 0.0, 0.0, 0.0 };
      nrm[a] = 1.0;
      if ((p[a] <= lo[a] + tol && b[a] <= 0.0) || (p[a] >= hi[a] - tol && b[a] >= 0.0))
      {
        remove(nrm);
      }
    }
    if (s.Container == ElasticContainer::Cylinder)
    {
      const double rx = p[0] - cx, ry = p[1] - cy, r = std::sqrt(rx * rx + ry * ry);
      if (r > 0.0 && r >= R - tol && rx * b[0] + ry * b[1] >= 0.0)
      {
        const double nrm[3] = { rx / r, ry / r, 0.0 };
        remove(nrm);
      }
    }
  }
}

// out = -H dx, the change of the internal forces for a displacement dx, with H a positive semi-definite
// projection of the stiffness -dF/dx at the configuration whose deformation gradients Fs are given:
// dP = dF S+ + F dS + k_v (cof F : dF) cof F with S+ the positive part of the stress (the geometric stiffness
// of compressed phyxels and the (det F - 1) d cof F term are indefinite and left out). The hourglass energy is
// quadratic, so its part is exact.
void ElasticSolid::ApplyHessian(
  const std::vector<double>& Fs, const std::vector<double>& Splus, const double* dx, std::vector<double>& out) const
{
  const Index n = this->N;
  const int k = this->K;
  const double lambda = this->LameLambda, mu = this->LameMu, kv = this->Config.VolumeStiffness;
  const bool hourglass = this->Config.HourglassStiffness > 0.0;
  std::vector<double>& packet = this->Packet;
  std::vector<double>& self = this->SelfForce;
  std::vector<double>& edge = this->EdgeForce;
  packet.resize(9 * n);
  self.resize(3 * n);
  edge.resize(hourglass ? 3 * static_cast<size_t>(n) * k : 0);
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        double dC[27], dF[9];
        this->Fit(dx, i, dC, dF);
        const double* P = &this->NullProjector[i * 9];
        for (int a = 0; a < 9; ++a)
        {
          dF[a] -= P[a]; // the gradient of dx alone
        }
        const double* F = &Fs[9 * i];
        const double* Sp = &Splus[9 * i];
        double FtdF[9], dS[9], Cof[9];
        for (int a = 0; a < 3; ++a)
        {
          for (int b = 0; b < 3; ++b)
          {
            FtdF[a * 3 + b] = F[a] * dF[b] + F[3 + a] * dF[3 + b] + F[6 + a] * dF[6 + b];
          }
        }
        const double tr = FtdF[0] + FtdF[4] + FtdF[8];
        for (int a = 0; a < 3; ++a)
        {
          for (int b = 0; b < 3; ++b)
          {
            dS[a * 3 + b] = mu * (FtdF[a * 3 + b] + FtdF[b * 3 + a]) + (a == b ? lambda * tr : 0.0);
          }
        }
        elastic::Cofactor(F, Cof);
        double cdF = 0.0;
        for (int a = 0; a < 9; ++a)
        {
          cdF += Cof[a] * dF[a];
        }
        double* G = &packet[9 * i];
        for (int a = 0; a < 3; ++a)
        {
          for (int b = 0; b < 3; ++b)
          {
            double v = kv * cdF * Cof[a * 3 + b];
            for (int c = 0; c < 3; ++c)
            {
              v += dF[a * 3 + c] * Sp[c * 3 + b] + F[a * 3 + c] * dS[c * 3 + b];
            }
            G[a * 3 + b] = this->Volume[i] * v;
          }
        }
        const double* ds = &this->SelfShape[3 * i];
        double own[3] = { 0.0, 0.0, 0.0 };
        if (hourglass)
        {
          this->ResidualForces(dx, i, dC, &edge[3 * static_cast<size_t>(i) * k], own);
        }
        for (int a = 0; a < 3; ++a)
        {
          self[3 * i + a] = own[a] - (G[a * 3] * ds[0] + G[a * 3 + 1] * ds[1] + G[a * 3 + 2] * ds[2]);
        }
      }
    },
    kElasticParallel + 1);
  this->GatherForces(packet, self, edge, out);
}

int ElasticSolid::StepImplicit(double dt, double& residual, double tolerance, int maxIterations)
{
  const Index n = this->N;
  double* x = this->Current.Position.data();
  double* v = this->Current.Velocity.data();
  this->ComputeInternalForces(x, this->Force);
  // The scale of the right-hand side M v + dt (f_int + f_other), for the CG stopping test: its terms' norms
  // added, not the norm of their sum, which vanishes at equilibrium (a hanging body: f_int = -M g, v = 0),
  // where a test relative to it would ask for ever more digits of a near-zero velocity.
  std::vector<double> internal(this->Force.begin(), this->Force.begin() + 3 * n);
  this->AddContactForces(x, this->Force);
  this->AddExternalForces(this->Force);
  const std::vector<double> Fs = this->DefGrad; // kept: ApplyHessian reuses the scratch buffers
  // Positive part of the elastic stress S at every phyxel (geometric stiffness kept semi-definite).
  std::vector<double> Splus(9 * n);
  const bool plastic = !this->Current.PlasticStrain.empty();
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        const double* F = &Fs[9 * i];
        Eigen::Matrix3d Fm;
        for (int a = 0; a < 3; ++a)
        {
          for (int b = 0; b < 3; ++b)
          {
            Fm(a, b) = F[a * 3 + b];
          }
        }
        Eigen::Matrix3d E = 0.5 * (Fm.transpose() * Fm - Eigen::Matrix3d::Identity());
        if (plastic)
        {
          const double* p = &this->Current.PlasticStrain[6 * i];
          Eigen::Matrix3d P;
          P << p[0], p[3], p[5], p[3], p[1], p[4], p[5], p[4], p[2];
          E -= P;
        }
        Eigen::Matrix3d S = this->LameLambda * E.trace() * Eigen::Matrix3d::Identity() + 2.0 * this->LameMu * E;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
        eig.computeDirect(S);
        const Eigen::Vector3d ev = eig.eigenvalues().cwiseMax(0.0);
        const Eigen::Matrix3d Sp = eig.eigenvectors() * ev.asDiagonal() * eig.eigenvectors().transpose();
        for (int a = 0; a < 3; ++a)
        {
          for (int b = 0; b < 3; ++b)
          {
            Splus[9 * i + a * 3 + b] = Sp(a, b);
          }
        }
      }
    },
    kElasticParallel + 1);

  // (M (1 + dt damping) + dt^2 H) v+ = M v + dt f  [4.31-4.34]; pinned phyxels keep v = 0.
  const double* g = this->Config.Gravity;
  const double md = 1.0 + dt * this->Config.Damping;
  std::vector<double> b(3 * n), sol(3 * n), r(3 * n), z(3 * n), p(3 * n), Ap(3 * n), diag(3 * n);
  const double stiff = this->LameLambda + 2.0 * this->LameMu + this->Config.VolumeStiffness;
  for (Index i = 0; i < n; ++i)
  {
    // Jacobi preconditioner: mass plus an estimate of the stiffness diagonal.
    double kd = 0.0;
    const double* ds = &this->SelfShape[3 * i];
    kd += this->Volume[i] * stiff * (ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2]);
    for (Index q = this->ReverseStart[i]; q < this->ReverseStart[i + 1]; ++q)
    {
      const Index e = this->ReverseEntry[q];
      const Index owner = e / this->K;
      const double* D = &this->Shape[e * this->Basis];
      const double r2 = this->InvRadius[owner] * this->InvRadius[owner];
      kd += this->Volume[owner] * stiff * r2 * (D[0] * D[0] + D[1] * D[1] + D[2] * D[2]) +
        this->Hourglass[owner] * this->Weight[e];
    }
    for (int a = 0; a < 3; ++a)
    {
      const Index c = 3 * i + a;
      b[c] = this->IsFixed[i] ? 0.0 : this->Mass[i] * v[c] + dt * (this->Force[c] + this->Mass[i] * g[a]);
      sol[c] = this->IsFixed[i] ? 0.0 : v[c];
      diag[c] = this->Mass[i] * md + dt * dt * kd;
    }
  }
  auto apply = [&](const std::vector<double>& in, std::vector<double>& result) {
    this->ApplyHessian(Fs, Splus, in.data(), result);
    ParallelFor(
      n, 4096,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          for (int a = 0; a < 3; ++a)
          {
            const Index c = 3 * i + a;
            result[c] = this->IsFixed[i] ? in[c] : this->Mass[i] * md * in[c] - dt * dt * result[c];
          }
        }
      },
      kElasticParallel + 1);
  };
  std::vector<double> S;
  this->WallFilter(x, b.data(), S);
  auto filter = [&](std::vector<double>& vec) {
    for (Index i = 0; i < n; ++i)
    {
      const double* M = &S[9 * i];
      const double a0 = vec[3 * i], a1 = vec[3 * i + 1], a2 = vec[3 * i + 2];
      vec[3 * i] = M[0] * a0 + M[1] * a1 + M[2] * a2;
      vec[3 * i + 1] = M[3] * a0 + M[4] * a1 + M[5] * a2;
      vec[3 * i + 2] = M[6] * a0 + M[7] * a1 + M[8] * a2;
    }
  };
  filter(sol);
  filter(b);
  apply(sol, Ap);
  double momentum2 = 0.0, internal2 = 0.0, other2 = 0.0, rz = 0.0;
  for (Index i = 0; i < n; ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      const Index c = 3 * i + a;
      if (!this->IsFixed[i])
      {
        const double other = this->Force[c] - internal[c] + this->Mass[i] * g[a];
        momentum2 += this->Mass[i] * v[c] * this->Mass[i] * v[c];
        internal2 += internal[c] * internal[c];
        other2 += other * other;
      }
    }
  }
  const double bnorm = std::sqrt(momentum2) + dt * (std::sqrt(internal2) + std::sqrt(other2));
  for (Index c = 0; c < 3 * n; ++c)
  {
    r[c] = b[c] - Ap[c];
  }
  filter(r);
  for (Index c = 0; c < 3 * n; ++c)
  {
    z[c] = r[c] / diag[c];
    p[c] = z[c];
    rz += r[c] * z[c];
  }
  int it = 0;
  double rnorm = 0.0;
  for (; it < maxIterations; ++it)
  {
    rnorm = 0.0;
    for (Index c = 0; c < 3 * n; ++c)
    {
      rnorm += r[c] * r[c];
    }
    rnorm = std::sqrt(rnorm);
    if (!(rnorm > tolerance * bnorm) || !(bnorm > 0.0))
    {
      break;
    }
    apply(p, Ap);
    filter(Ap);
    double pAp = 0.0;
    for (Index c = 0; c < 3 * n; ++c)
    {
      pAp += p[c] * Ap[c];
    }
    if (!(pAp > 0.0))
    {
      break; // cannot happen for the positive definite system; guards against round-off
    }
    const double alpha = rz / pAp;
    double rzNew = 0.0;
    for (Index c = 0; c < 3 * n; ++c)
    {
      sol[c] += alpha * p[c];
      r[c] -= alpha * Ap[c];
      z[c] = r[c] / diag[c];
      rzNew += r[c] * z[c];
    }
    const double beta = rzNew / rz;
    rz = rzNew;
    for (Index c = 0; c < 3 * n; ++c)
    {
      p[c] = z[c] + beta * p[c];
    }
  }
  residual = bnorm > 0.0 ? rnorm / bnorm : 0.0;
  if (it >= maxIterations && residual > tolerance)
  {
    ++this->UnconvergedSteps;
    this->WorstResidual = std::max(this->WorstResidual, residual);
  }

  ParallelFor(
    n, 4096,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        for (int a = 0; a < 3; ++a)
        {
          const Index c = 3 * i + a;
          v[c] = this->IsFixed[i] ? 0.0 : sol[c];
          x[c] = this->IsFixed[i] ? this->Rest[c] : x[c] + dt * v[c];
        }
      }
    },
    kElasticParallel + 1);
  this->ApplyContainer(x, v);
  this->DefGrad = Fs;
  this->UpdatePlasticity(dt);
  this->Current.Time += dt;
  ++this->Steps;
  this->TotalCGIterations += it;
  return it;
}
} // namespace meshfree
