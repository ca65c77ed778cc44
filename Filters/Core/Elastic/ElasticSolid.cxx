// SPDX-License-Identifier: BSD-3-Clause
// Meshless elastic solid (Mueller et al. 2004): model set-up, strain/stress, forces, symplectic Euler.
// The model is described in ElasticSolid.h; the implicit integrator is in ElasticImplicit.cxx.
#include "Elastic/ElasticSolid.h"
#include "Common/Parallel.h"
#include "Elastic/ElasticMath.h"

#include <Eigen/Dense>

#include <algorithm>
#include <random>
#include <cmath>
#include <limits>
#include <sstream>

namespace meshfree
{

bool ElasticSolid::Initialize(
  const std::vector<double>& rest, double bodyVolume, const ElasticSettings& s, std::string& message)
{
  std::ostringstream msg;
  this->N = 0;
  this->Config = s;
  const double E = s.YoungModulus, nu = s.PoissonRatio;
  if (!(E > 0.0) || !std::isfinite(E))
  {
    message = "YoungModulus must be a finite positive number (Pa).";
    return false;
  }
  if (!(nu > -1.0 && nu < 0.5))
  {
    message = "PoissonRatio must lie in (-1, 0.5): at 0.5 the material is incompressible and Hooke's law "
              "(lambda = E nu / ((1 + nu)(1 - 2 nu))) is undefined.";
    return false;
  }
  // Each setting by its property name: positive (or non-negative) and finite.
  const struct
  {
    const char* Name;
    double Value;
    bool ZeroAllowed;
  } checks[] = { { "Density", s.Density, false }, { "SupportScale", s.SupportScale, false },
    { "StableStepFactor", s.StableStepFactor, false }, { "VolumeStiffness", s.VolumeStiffness, true },
    { "HourglassStiffness", s.HourglassStiffness, true }, { "Damping", s.Damping, true },
    { "PlasticYield", s.PlasticYield, true }, { "PlasticCreep", s.PlasticCreep, true },
    { "PlasticMaxStrain", s.PlasticMaxStrain, true } };
  for (const auto& c : checks)
  {
    if (!std::isfinite(c.Value) || !(c.ZeroAllowed ? c.Value >= 0.0 : c.Value > 0.0))
    {
      msg << c.Name << " must be a finite " << (c.ZeroAllowed ? "non-negative" : "positive") << " number, not "
          << c.Value << ".";
      message = msg.str();
      return false;
    }
  }
  const Index n = static_cast<Index>(rest.size() / 3);
  for (double c : rest)
  {
    if (!std::isfinite(c))
    {
      message = "phyxel rest positions must be finite.";
      return false;
    }
  }
  if (n == 0)
  {
    message = "no phyxels: the shape holds no lattice point at this PhyxelSpacing.";
    return false;
  }
  this->LameLambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  this->LameMu = E / (2.0 * (1.0 + nu));
  this->N = n;
  this->Rest = rest;

  // Neighbours: the k nearest others plus every phyxel tied with the k-th distance, so that regular lattices
  // keep symmetric neighbourhoods (a tie broken by index makes them lopsided, and then a uniform strain is no
  // longer in equilibrium inside the body). At most 3k are kept.
  this->Basis = s.GradientBasis == 1 ? 3 : 9;
  const int minimum = this->Basis == 9 ? 18 : 1; // a quadratic fit needs two layers on every side
  const int kWanted = static_cast<int>(std::min<Index>(std::max(minimum, s.NeighborCount), n - 1));
  std::vector<std::vector<Index>> lists(n);
  std::vector<std::vector<double>> lengths(n);
  std::vector<double> nearest(n, 0.0);
  {
    NeighborGrid grid;
    grid.Build(rest.data(), n);
    PerThread<std::vector<Index>> idsPerThread;
    PerThread<std::vector<double>> d2PerThread;
    ParallelFor(
      n, 256,
      [&](Index begin, Index end) {
        std::vector<Index>& ids = idsPerThread.Local();
        std::vector<double>& d2 = d2PerThread.Local();
        for (Index i = begin; i < end; ++i)
        {
          const int found = grid.FindKNearest(&rest[3 * i], kWanted + 1, ids, d2);
          if (found < 2)
          {
            continue;
          }
          const double reach = std::sqrt(d2[std::min(found - 1, kWanted)]) * (1.0 + 1e-9);
          grid.FindWithinRadiusSorted(&rest[3 * i], reach, ids, d2);
          for (size_t t = 0; t < ids.size() && static_cast<int>(lists[i].size()) < 3 * kWanted; ++t)
          {
            if (ids[t] != i)
            {
              lists[i].push_back(ids[t]);
              lengths[i].push_back(std::sqrt(d2[t]));
            }
          }
          nearest[i] = lengths[i].empty() ? 0.0 : lengths[i][0];
        }
      },
      kElasticParallel + 1);
  }
  int k = 1;
  for (const auto& l : lists)
  {
    k = std::max<int>(k, static_cast<int>(l.size()));
  }
  this->K = k;

  this->Neighbor.assign(static_cast<size_t>(n) * k, -1);
  this->RestOffset.assign(static_cast<size_t>(n) * k * 3, 0.0);
  this->Weight.assign(static_cast<size_t>(n) * k, 0.0);
  this->Shape.assign(static_cast<size_t>(n) * k * this->Basis, 0.0);
  this->InvRadius.assign(n, 1.0);
  this->SelfShape.assign(static_cast<size_t>(n) * 3, 0.0);
  this->NullProjector.assign(static_cast<size_t>(n) * 9, 0.0);
  this->MeanDistance.assign(n, 0.0);
  this->Hourglass.assign(n, 0.0);
  std::vector<double> weightSum(n, 0.0);
  Index illConditioned = 0;

  illConditioned += ParallelReduce(
    n, 1024, decltype(illConditioned)(0),
    [&](Index begin, Index end) {
      decltype(illConditioned) illConditioned = 0; // this block's part
      for (Index i = begin; i < end; ++i)
      {
        const int found = static_cast<int>(lists[i].size());
        double sum = 0.0;
        for (int t = 0; t < found; ++t)
        {
          this->Neighbor[i * k + t] = lists[i][t];
          sum += lengths[i][t];
        }
        const double rbar = found > 0 ? sum / found : 0.0;
        this->MeanDistance[i] = rbar;
        if (!(rbar > 0.0))
        {
          // Isolated or fully coincident phyxel: no gradient information at all.
          for (int a = 0; a < 3; ++a)
          {
            this->NullProjector[i * 9 + a * 4] = 1.0;
          }
          ++illConditioned;
          continue;
        }
        const Kernel kernel(s.Kernel, 3, s.SupportScale * rbar);
        const double invR = 1.0 / rbar;
        this->InvRadius[i] = invR;
        const int nb = this->Basis;
        Eigen::Matrix3d A = Eigen::Matrix3d::Zero(); // linear moment matrix [4.12], scaled by 1/rbar
        Eigen::Matrix<double, 9, 9> M = Eigen::Matrix<double, 9, 9>::Zero();
        double wsum = 0.0;
        for (int t = 0; t < found; ++t)
        {
          const Index j = this->Neighbor[i * k + t];
          double X[3], q[3], p[9];
          for (int a = 0; a < 3; ++a)
          {
            X[a] = rest[3 * j + a] - rest[3 * i + a];
            this->RestOffset[(i * k + t) * 3 + a] = X[a];
            q[a] = X[a] * invR;
          }
          const double w = kernel.Value(std::sqrt(X[0] * X[0] + X[1] * X[1] + X[2] * X[2]));
          this->Weight[i * k + t] = w;
          wsum += w;
          elastic::Basis(q, p);
          const Eigen::Map<const Eigen::Vector3d> qv(q);
          A += w * qv * qv.transpose();
          if (nb == 9)
          {
            const Eigen::Map<const Eigen::Matrix<double, 9, 1>> pv(p);
            M += w * pv * pv.transpose();
          }
        }
        weightSum[i] = wsum;
        // Linear part: symmetric eigen-decomposition (the SVD of this PSD matrix), pseudo-inverse, null space.
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
        const Eigen::Vector3d ev = eig.eigenvalues();
        const double top = std::max(ev.cwiseAbs().maxCoeff(), 0.0);
        Eigen::Matrix3d Ainv = Eigen::Matrix3d::Zero();
        Eigen::Matrix3d Null = Eigen::Matrix3d::Zero();
        bool singular = false;
        for (int a = 0; a < 3; ++a)
        {
          const Eigen::Vector3d e = eig.eigenvectors().col(a);
          if (top > 0.0 && ev[a] > 1e-6 * top)
          {
            Ainv += e * e.transpose() / ev[a];
          }
          else
          {
            Null += e * e.transpose();
            singular = true;
          }
        }
        illConditioned += singular ? 1 : 0;
        // Quadratic fit when its moment matrix is well conditioned, else the linear one for this phyxel.
        Eigen::Matrix<double, 9, 9> Minv = Eigen::Matrix<double, 9, 9>::Zero();
        bool quadratic = false;
        if (nb == 9 && !singular)
        {
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig9(M);
          const double lo = eig9.eigenvalues().minCoeff(), hi = eig9.eigenvalues().maxCoeff();
          if (hi > 0.0 && lo > 1e-6 * hi)
          {
            quadratic = true;
            Minv =
              eig9.eigenvectors() * eig9.eigenvalues().cwiseInverse().asDiagonal() * eig9.eigenvectors().transpose();
          }
        }
        double dself[3] = { 0.0, 0.0, 0.0 };
        for (int t = 0; t < found; ++t)
        {
          const double w = this->Weight[i * k + t];
          double q[3], p[9];
          for (int a = 0; a < 3; ++a)
          {
            q[a] = this->RestOffset[(i * k + t) * 3 + a] * invR;
          }
          elastic::Basis(q, p);
          double* D = &this->Shape[(i * k + t) * nb];
          if (quadratic)
          {
            const Eigen::Map<const Eigen::Matrix<double, 9, 1>> pv(p);
            const Eigen::Matrix<double, 9, 1> d = Minv * pv * w;
            for (int m = 0; m < 9; ++m)
            {
              D[m] = d[m];
            }
          }
          else
          {
            const Eigen::Map<const Eigen::Vector3d> qv(q);
            const Eigen::Vector3d d = Ainv * qv * w;
            for (int m = 0; m < nb; ++m)
            {
              D[m] = m < 3 ? d[m] : 0.0;
            }
          }
          for (int a = 0; a < 3; ++a)
          {
            dself[a] -= D[a] * invR; // d_ii = -sum_j d_ij, in physical units
          }
        }
        for (int a = 0; a < 3; ++a)
        {
          this->SelfShape[i * 3 + a] = dself[a];
          for (int b = 0; b < 3; ++b)
          {
            this->NullProjector[i * 9 + a * 3 + b] = Null(a, b);
          }
        }
      }
      return illConditioned;
    },
    [](decltype(illConditioned) a, decltype(illConditioned) b) { return a + b; }, kElasticParallel + 1);
  this->IllConditioned = illConditioned;

  // Masses m_i = s rbar_i^3 rho [4.15], s from the body's volume; volumes m_i / rho [4.22].
  double meanNearest = 0.0, cubeSum = 0.0;
  for (Index i = 0; i < n; ++i)
  {
    meanNearest += nearest[i];
  }
  meanNearest = n > 0 ? meanNearest / n : 0.0;
  for (Index i = 0; i < n; ++i)
  {
    if (!(this->MeanDistance[i] > 0.0))
    {
      this->MeanDistance[i] = meanNearest > 0.0 ? meanNearest : 1.0;
    }
    cubeSum += std::pow(this->MeanDistance[i], 3);
  }
  if (!(bodyVolume > 0.0))
  {
    const double a = meanNearest > 0.0 ? meanNearest : this->MeanDistance[0];
    bodyVolume = static_cast<double>(n) * a * a * a;
  }
  this->Mass.resize(n);
  this->Volume.resize(n);
  for (Index i = 0; i < n; ++i)
  {
    this->Volume[i] = bodyVolume * std::pow(this->MeanDistance[i], 3) / cubeSum;
    this->Mass[i] = s.Density * this->Volume[i];
    const double r = this->MeanDistance[i];
    this->Hourglass[i] =
      weightSum[i] > 0.0 ? s.HourglassStiffness * E * this->Volume[i] / (r * r * weightSum[i]) : 0.0;
  }

  // Reverse adjacency: who uses j as a neighbour (gathering forces without write races).
  this->ReverseStart.assign(n + 1, 0);
  for (Index e = 0; e < n * k; ++e)
  {
    if (this->Neighbor[e] >= 0)
    {
      ++this->ReverseStart[this->Neighbor[e] + 1];
    }
  }
  for (Index i = 0; i < n; ++i)
  {
    this->ReverseStart[i + 1] += this->ReverseStart[i];
  }
  this->ReverseEntry.assign(this->ReverseStart[n], 0);
  std::vector<Index> fill(this->ReverseStart.begin(), this->ReverseStart.end() - 1);
  for (Index e = 0; e < n * k; ++e)
  {
    if (this->Neighbor[e] >= 0)
    {
      this->ReverseEntry[fill[this->Neighbor[e]]++] = e;
    }
  }

  this->IsFixed.assign(n, 0);
  Index fixedCount = 0;
  for (Index i = 0; i < n; ++i)
  {
    bool inside = true;
    for (int a = 0; a < 3; ++a)
    {
      const double c = rest[3 * i + a];
      inside = inside && c >= s.FixedBounds[2 * a] && c <= s.FixedBounds[2 * a + 1];
    }
    this->IsFixed[i] = inside ? 1 : 0;
    fixedCount += inside ? 1 : 0;
  }

  // Surface phyxels: the centroid of their rest neighbours is off-centre (zero for interior lattice phyxels).
  this->SurfacePhyxels.clear();
  for (Index i = 0; i < n; ++i)
  {
    double c[3] = { 0.0, 0.0, 0.0 };
    int count = 0;
    for (int t = 0; t < k && this->Neighbor[i * k + t] >= 0; ++t, ++count)
    {
      for (int a = 0; a < 3; ++a)
      {
        c[a] += this->RestOffset[(i * k + t) * 3 + a];
      }
    }
    const double offset = count > 0 ? std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / count : 1.0;
    if (count < 6 || offset > 0.1 * this->MeanDistance[i])
    {
      this->SurfacePhyxels.push_back(i);
    }
  }

  // Contact: Lennard-Jones [4.26] with alpha = the phyxel spacing, strength and cap relative to E.
  this->ContactDistance = meanNearest > 0.0 ? meanNearest : this->MeanDistance[0];
  const double alpha = this->ContactDistance;
  this->ContactBeta = s.ContactStrength > 0.0 ? s.ContactStrength : 0.02 * E * alpha * alpha * alpha;
  this->ContactCap = E * alpha * alpha;

  this->EstimateStableStep();
  this->Current.Time = 0.0;
  this->Current.Position = rest;
  this->Current.Velocity.assign(3 * n, 0.0);
  this->Current.PlasticStrain.assign(s.PlasticYield > 0.0 ? 6 * n : 0, 0.0);
  this->Steps = 0;
  this->TotalCGIterations = 0;
  this->UnconvergedSteps = 0;
  this->WorstResidual = 0.0;

  if (illConditioned > 0)
  {
    msg << illConditioned << " of " << n
        << " phyxels have coplanar, collinear or missing neighbours: their displacement gradient is "
           "taken as zero across the missing directions (pseudo-inverse of the moment matrix).";
  }
  if (fixedCount == n && n > 0)
  {
    msg << (msg.tellp() > 0 ? " " : "") << "FixedBounds pins every phyxel: nothing moves.";
  }
  message = msg.str();
  return true;
}

void ElasticSolid::Reset(const double initialVelocity[3])
{
  this->Current.Time = 0.0;
  this->Current.Position = this->Rest;
  this->Current.Velocity.assign(3 * this->N, 0.0);
  for (Index i = 0; i < this->N; ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->Current.Velocity[3 * i + a] = this->IsFixed[i] ? 0.0 : initialVelocity[a];
    }
  }
  std::fill(this->Current.PlasticStrain.begin(), this->Current.PlasticStrain.end(), 0.0);
}

double ElasticSolid::StableTimeStep() const
{
  return this->StableStep;
}

// Two estimates of the symplectic Euler limit dt < 2/omega_max, the smaller wins:
// - the wave-speed rule dt = C r_min / c, c^2 = (lambda + 2 mu + k_v + 4 alpha E) / rho (research/elastic.md 3.4);
// - dt = C * 2 / omega_max with omega_max^2 the largest eigenvalue of M^-1 K at rest, by power iteration on the
//   linearised forces (30 force evaluations). It catches irregular neighbourhoods and the quadratic fit, whose
//   shape vectors can be larger than 1/r. C = StableStepFactor (0.4) leaves room for stiffening under large
//   deformation, contacts and the power iteration approaching omega_max from below.
void ElasticSolid::EstimateStableStep()
{
  const ElasticSettings& s = this->Config;
  const Index n = this->N;
  if (n == 0)
  {
    this->StableStep = 0.0;
    return;
  }
  const double M = this->LameLambda + 2.0 * this->LameMu + s.VolumeStiffness;
  const double c = std::sqrt((M + 4.0 * s.HourglassStiffness * s.YoungModulus) / s.Density);
  const double rmin = *std::min_element(this->MeanDistance.begin(), this->MeanDistance.end());
  const double wave = s.StableStepFactor * rmin / c;
  std::vector<double> identity(9 * n, 0.0), none(9 * n, 0.0), x(3 * n), y;
  for (Index i = 0; i < n; ++i)
  {
    identity[9 * i] = identity[9 * i + 4] = identity[9 * i + 8] = 1.0;
  }
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (Index c3 = 0; c3 < 3 * n; ++c3)
  {
    x[c3] = this->IsFixed[c3 / 3] ? 0.0 : unit(rng);
  }
  double omega2 = 0.0;
  for (int it = 0; it < 30; ++it)
  {
    this->ApplyHessian(identity, none, x.data(), y); // y = -K x
    double xKx = 0.0, xMx = 0.0, norm = 0.0;
    for (Index c3 = 0; c3 < 3 * n; ++c3)
    {
      const double m = this->Mass[c3 / 3];
      xKx -= x[c3] * y[c3];
      xMx += m * x[c3] * x[c3];
      y[c3] = this->IsFixed[c3 / 3] ? 0.0 : -y[c3] / m; // M^-1 K x
      norm += y[c3] * y[c3];
    }
    omega2 = std::max(omega2, xMx > 0.0 ? xKx / xMx : 0.0);
    if (!(norm > 0.0) || !std::isfinite(norm))
    {
      break;
    }
    norm = 1.0 / std::sqrt(norm);
    for (Index c3 = 0; c3 < 3 * n; ++c3)
    {
      x[c3] = y[c3] * norm;
    }
  }
  const double spectral = omega2 > 0.0 ? s.StableStepFactor * 2.0 / std::sqrt(omega2) : wave;
  this->StableStep = std::min(wave, spectral);
}

} // namespace meshfree
