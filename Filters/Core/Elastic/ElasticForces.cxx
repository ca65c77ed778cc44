// SPDX-License-Identifier: BSD-3-Clause
// Meshless elastic solid: deformation gradient from the MLS fit, Green strain, Hooke stress, and the elastic,
// volume and hourglass forces in the momentum-conserving packet form (see ElasticSolid.h).
#include "Common/Parallel.h"
#include "Elastic/ElasticMath.h"
#include "Elastic/ElasticSolid.h"

#include <algorithm>
#include <cmath>

namespace meshfree
{
using namespace elastic;

void HookeStress(double lambda, double mu, const double e[6], double s[6])
{
  const double tr = e[0] + e[1] + e[2];
  for (int a = 0; a < 3; ++a)
  {
    s[a] = lambda * tr + 2.0 * mu * e[a]; // [4.6-4.7]
    s[a + 3] = 2.0 * mu * e[a + 3];
  }
}

double VonMisesStress(const double s[6])
{
  const double d = (s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) + (s[2] - s[0]) * (s[2] - s[0]);
  return std::sqrt(0.5 * d + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

void ElasticSolid::Fit(const double* x, Index i, double C[27], double F[9]) const
{
  const int k = this->K, nb = this->Basis;
  for (int a = 0; a < 3 * nb; ++a)
  {
    C[a] = 0.0;
  }
  const double* xi = x + 3 * i;
  for (int t = 0; t < k; ++t)
  {
    const Index j = this->Neighbor[i * k + t];
    if (j < 0)
    {
      break;
    }
    const double* D = &this->Shape[(i * k + t) * nb];
    const double u[3] = { x[3 * j] - xi[0], x[3 * j + 1] - xi[1], x[3 * j + 2] - xi[2] };
    for (int a = 0; a < 3; ++a)
    {
      for (int m = 0; m < nb; ++m)
      {
        C[a * nb + m] += u[a] * D[m];
      }
    }
  }
  // F = I + grad u^T [4.2, 4.13]: the linear coefficients, back in physical units, plus the identity on
  // directions the neighbourhood does not span.
  const double invR = this->InvRadius[i];
  const double* P = &this->NullProjector[i * 9];
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      F[a * 3 + b] = C[a * nb + b] * invR + P[a * 3 + b];
    }
  }
}

void ElasticSolid::DeformationGradient(const double* x, Index i, double F[9]) const
{
  double C[27];
  this->Fit(x, i, C, F);
}

void ElasticSolid::ResidualForces(const double* x, Index i, const double C[27], double* edge, double self[3]) const
{
  const int k = this->K, nb = this->Basis;
  const double kappa = this->Hourglass[i], invR = this->InvRadius[i];
  self[0] = self[1] = self[2] = 0.0;
  for (int t = 0; t < k; ++t)
  {
    const Index j = this->Neighbor[i * k + t];
    if (j < 0)
    {
      break;
    }
    const double* X = &this->RestOffset[(i * k + t) * 3];
    double q[3] = { X[0] * invR, X[1] * invR, X[2] * invR }, p[9];
    elastic::Basis(q, p);
    const double kw = kappa * this->Weight[i * k + t];
    for (int a = 0; a < 3; ++a)
    {
      double predicted = 0.0;
      for (int m = 0; m < nb; ++m)
      {
        predicted += C[a * nb + m] * p[m];
      }
      const double e = kw * ((x[3 * j + a] - x[3 * i + a]) - predicted);
      edge[t * 3 + a] = e;
      self[a] += e;
    }
  }
}

void ElasticSolid::ComputePackets(const double* x, std::vector<double>& packet, std::vector<double>& Fout,
  std::vector<double>& selfForce, std::vector<double>& edge) const
{
  const Index n = this->N;
  const int k = this->K;
  const double lambda = this->LameLambda, mu = this->LameMu, kv = this->Config.VolumeStiffness;
  const bool plastic = !this->Current.PlasticStrain.empty();
  const bool hourglass = this->Config.HourglassStiffness > 0.0;
  packet.resize(9 * n);
  Fout.resize(9 * n);
  selfForce.resize(3 * n);
  edge.resize(hourglass ? 3 * static_cast<size_t>(n) * k : 0);
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        double C[27], F[9];
        this->Fit(x, i, C, F);
        double E[6], S[6], Sm[9], Cof[9];
        GreenStrain(F, E);
        if (plastic)
        {
          for (int a = 0; a < 6; ++a)
          {
            E[a] -= this->Current.PlasticStrain[6 * i + a];
          }
        }
        HookeStress(lambda, mu, E, S);
        SymToMat(S, Sm);
        Cofactor(F, Cof);
        const double volumeTerm = kv * (Det3(F) - 1.0); // [4.24-4.25]
        double* G = &packet[9 * i];
        for (int a = 0; a < 3; ++a)
        {
          for (int b = 0; b < 3; ++b)
          {
            const double FS = F[a * 3] * Sm[b] + F[a * 3 + 1] * Sm[3 + b] + F[a * 3 + 2] * Sm[6 + b];
            G[a * 3 + b] = this->Volume[i] * (FS + volumeTerm * Cof[a * 3 + b]); // v_i P_i [4.23]
          }
        }
        const double* ds = &this->SelfShape[3 * i];
        double self[3] = { 0.0, 0.0, 0.0 };
        if (hourglass)
        {
          this->ResidualForces(x, i, C, &edge[3 * static_cast<size_t>(i) * k], self);
        }
        for (int a = 0; a < 3; ++a)
        {
          selfForce[3 * i + a] = self[a] - (G[a * 3] * ds[0] + G[a * 3 + 1] * ds[1] + G[a * 3 + 2] * ds[2]);
        }
        for (int a = 0; a < 9; ++a)
        {
          Fout[9 * i + a] = F[a];
        }
      }
    },
    kElasticParallel + 1);
}

void ElasticSolid::GatherForces(const std::vector<double>& packet, const std::vector<double>& selfForce,
  const std::vector<double>& edge, std::vector<double>& f) const
{
  const Index n = this->N;
  const int k = this->K, nb = this->Basis;
  const bool hourglass = !edge.empty();
  f.resize(3 * n);
  ParallelFor(
    n, 512,
    [&](Index begin, Index end) {
      for (Index j = begin; j < end; ++j)
      {
        double acc[3] = { selfForce[3 * j], selfForce[3 * j + 1], selfForce[3 * j + 2] };
        for (Index r = this->ReverseStart[j]; r < this->ReverseStart[j + 1]; ++r)
        {
          const Index e = this->ReverseEntry[r];
          const Index i = e / k;
          const double* G = &packet[9 * i];
          const double* D = &this->Shape[e * nb];
          const double invR = this->InvRadius[i];
          const double d[3] = { D[0] * invR, D[1] * invR, D[2] * invR };
          for (int a = 0; a < 3; ++a)
          {
            acc[a] -= G[a * 3] * d[0] + G[a * 3 + 1] * d[1] + G[a * 3 + 2] * d[2];
            if (hourglass)
            {
              acc[a] -= edge[3 * e + a];
            }
          }
        }
        f[3 * j] = acc[0];
        f[3 * j + 1] = acc[1];
        f[3 * j + 2] = acc[2];
      }
    },
    kElasticParallel + 1);
}

void ElasticSolid::ComputeInternalForces(const double* x, std::vector<double>& f) const
{
  this->ComputePackets(x, this->Packet, this->DefGrad, this->SelfForce, this->EdgeForce);
  this->GatherForces(this->Packet, this->SelfForce, this->EdgeForce, f);
}

double ElasticSolid::InternalEnergy(const double* x) const
{
  const Index n = this->N;
  const int k = this->K;
  const bool plastic = !this->Current.PlasticStrain.empty();
  double energy = 0.0;
  energy += ParallelReduce(
    n, 256, decltype(energy)(0),
    [&](Index begin, Index end) {
      decltype(energy) energy = 0; // this block's part
      for (Index i = begin; i < end; ++i)
      {
        double C[27], F[9], E[6];
        this->Fit(x, i, C, F);
        GreenStrain(F, E);
        if (plastic)
        {
          for (int a = 0; a < 6; ++a)
          {
            E[a] -= this->Current.PlasticStrain[6 * i + a];
          }
        }
        const double tr = E[0] + E[1] + E[2];
        const double EE = Norm6(E);
        const double J1 = Det3(F) - 1.0;
        const double psi =
          0.5 * this->LameLambda * tr * tr + this->LameMu * EE * EE + 0.5 * this->Config.VolumeStiffness * J1 * J1;
        double hg = 0.0;
        if (this->Hourglass[i] > 0.0)
        {
          std::vector<double> edge(3 * k);
          double self[3];
          this->ResidualForces(x, i, C, edge.data(), self);
          // edge = kappa w r, so sum |edge|^2 / (kappa w) = kappa sum w |r|^2
          for (int t = 0; t < k && this->Neighbor[i * k + t] >= 0; ++t)
          {
            const double kw = this->Hourglass[i] * this->Weight[i * k + t];
            if (kw > 0.0)
            {
              for (int a = 0; a < 3; ++a)
              {
                hg += edge[3 * t + a] * edge[3 * t + a] / kw;
              }
            }
          }
        }
        energy += this->Volume[i] * psi + 0.5 * hg;
      }
      return energy;
    },
    [](decltype(energy) a, decltype(energy) b) { return a + b; }, kElasticParallel + 1);
  return energy;
}

void ElasticSolid::ComputeDeformation(std::vector<double>& Fs, std::vector<double>& strain,
  std::vector<double>& stress, std::vector<double>& detF) const
{
  const Index n = this->N;
  Fs.resize(9 * n);
  strain.resize(6 * n);
  stress.resize(6 * n);
  detF.resize(n);
  const double* x = this->Current.Position.data();
  const bool plastic = !this->Current.PlasticStrain.empty();
  ParallelFor(
    n, 256,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        double* F = &Fs[9 * i];
        this->DeformationGradient(x, i, F);
        double* E = &strain[6 * i];
        GreenStrain(F, E);
        double Ee[6];
        for (int a = 0; a < 6; ++a)
        {
          Ee[a] = E[a] - (plastic ? this->Current.PlasticStrain[6 * i + a] : 0.0);
        }
        HookeStress(this->LameLambda, this->LameMu, Ee, &stress[6 * i]);
        detF[i] = Det3(F);
      }
    },
    kElasticParallel + 1);
}
} // namespace meshfree
