// SPDX-License-Identifier: BSD-3-Clause
// Jet normals over growing radii, the radius chosen by intersecting confidence intervals (AdaptiveJet.h).
#include "Surface/AdaptiveJet.h"

#include "Common/LocalFit.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace meshfree
{

namespace
{
constexpr int MaxShells = 24;
constexpr size_t JetTerms = 6;
constexpr Index MinimumPerTerm = 2; // neighbours per jet coefficient before a radius is tried

/// First and second moments of shifted and scaled offsets d (|d| <= 1), and their count.
struct Moments
{
  double M1[3] = { 0.0, 0.0, 0.0 };
  double M2[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 }; // xx, xy, xz, yy, yz, zz
  Index Count = 0;

  void Add(const double d[3])
  {
    for (int a = 0; a < 3; ++a)
    {
      this->M1[a] += d[a];
    }
    this->M2[0] += d[0] * d[0];
    this->M2[1] += d[0] * d[1];
    this->M2[2] += d[0] * d[2];
    this->M2[3] += d[1] * d[1];
    this->M2[4] += d[1] * d[2];
    this->M2[5] += d[2] * d[2];
    ++this->Count;
  }
  void Add(const Moments& o)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->M1[a] += o.M1[a];
    }
    for (int a = 0; a < 6; ++a)
    {
      this->M2[a] += o.M2[a];
    }
    this->Count += o.Count;
  }
  /// Covariance about the centroid; false when there are fewer than 3 points.
  bool Covariance(Eigen::Matrix3d& C, Eigen::Vector3d& mean) const
  {
    if (this->Count < 3)
    {
      return false;
    }
    const double w = 1.0 / static_cast<double>(this->Count);
    mean = Eigen::Vector3d(this->M1[0] * w, this->M1[1] * w, this->M1[2] * w);
    C(0, 0) = this->M2[0] * w - mean(0) * mean(0);
    C(0, 1) = C(1, 0) = this->M2[1] * w - mean(0) * mean(1);
    C(0, 2) = C(2, 0) = this->M2[2] * w - mean(0) * mean(2);
    C(1, 1) = this->M2[3] * w - mean(1) * mean(1);
    C(1, 2) = C(2, 1) = this->M2[4] * w - mean(1) * mean(2);
    C(2, 2) = this->M2[5] * w - mean(2) * mean(2);
    return true;
  }
};

/// The plane of a covariance: false when the points are collinear or coincident.
bool Plane(const Eigen::Matrix3d& C, Eigen::Vector3d& n, Eigen::Vector3d& t1, Eigen::Vector3d& t2, Eigen::Vector3d& l)
{
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(C);
  l = eig.eigenvalues();
  // The closed-form solver's eigenvalues are accurate to ~1e-9 of the largest: a relative width below 1e-3
  // counts as a line.
  if (!(l(1) > 1e-6 * l(2)) || !(l(2) > 0.0) || !std::isfinite(l(2)))
  {
    return false;
  }
  n = eig.eigenvectors().col(0).normalized();
  t1 = eig.eigenvectors().col(2).normalized();
  t2 = n.cross(t1);
  return n.allFinite() && t2.allFinite();
}
} // namespace

AdaptiveJetResult AdaptiveJetNormal(const double* sorted, const std::vector<Index>& pos, const std::vector<double>& r2,
  const double x[3], const AdaptiveJetOptions& options, AdaptiveJetScratch& scratch)
{
  AdaptiveJetResult out;
  const double top = options.LargestRadius;
  if (!(top > 0.0) || pos.size() < 3)
  {
    return out;
  }
  // Radii: a geometric series ending at the largest, starting at or just below the smallest.
  const double ratio = std::max(1.01, options.Ratio);
  const double smallest = std::min(std::max(options.SmallestRadius, 1e-12 * top), top);
  const int shells = std::min(MaxShells, 1 + static_cast<int>(std::ceil(std::log(top / smallest) / std::log(ratio))));
  double radius2[MaxShells];
  for (int s = 0; s < shells; ++s)
  {
    const double r = top * std::pow(ratio, s - (shells - 1));
    radius2[s] = r * r;
  }
  radius2[shells - 1] = top * top;
  int frame = 0;
  while (frame < shells - 1 && radius2[frame] < options.FrameRadius * options.FrameRadius)
  {
    ++frame;
  }
  // Counting sort of the neighbours by shell; each shell's PCA moments on the way.
  const size_t n = pos.size();
  scratch.Shell.resize(n);
  scratch.Sorted.resize(n);
  Index start[MaxShells + 1] = {};
  Moments pca[MaxShells];
  const double inv = 1.0 / top;
  for (size_t j = 0; j < n; ++j)
  {
    int s = 0;
    while (s < shells - 1 && r2[j] > radius2[s])
    {
      ++s;
    }
    scratch.Shell[j] = static_cast<unsigned char>(s);
    ++start[s + 1];
    const double* p = sorted + 3 * pos[j];
    const double d[3] = { (p[0] - x[0]) * inv, (p[1] - x[1]) * inv, (p[2] - x[2]) * inv };
    pca[s].Add(d);
  }
  for (int s = 0; s < shells; ++s)
  {
    start[s + 1] += start[s];
  }
  {
    Index next[MaxShells];
    std::copy(start, start + shells, next);
    for (size_t j = 0; j < n; ++j)
    {
      scratch.Sorted[static_cast<size_t>(next[scratch.Shell[j]]++)] = pos[j];
    }
  }
  // Cumulative PCA moments; the plane from the frame radius (or the first larger one that has a plane).
  for (int s = 1; s < shells; ++s)
  {
    pca[s].Add(pca[s - 1]);
  }
  Eigen::Vector3d normal, t1, t2, l, mean;
  Eigen::Matrix3d C;
  bool planar = false;
  for (; frame < shells && !planar; ++frame)
  {
    planar = pca[frame].Covariance(C, mean) && Plane(C, normal, t1, t2, l);
  }
  if (!planar)
  {
    return out;
  }
  // Jets over growing radii in the frame's plane; the intervals of the slopes intersected as they come.
  Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 3> B = Eigen::Matrix<double, 6, 3>::Zero(); // heights | e1 | e2
  Index used = 0;
  double lower[2] = { -HUGE_VAL, -HUGE_VAL }, upper[2] = { HUGE_VAL, HUGE_VAL };
  const double sigma = std::max(options.Noise * inv, 1e-9);
  const double gamma = options.Gamma;
  bool chosen = false;
  double slope[2] = { 0.0, 0.0 };
  int chosenShell = 0;
  for (int s = 0; s < shells; ++s)
  {
    for (Index j = start[s]; j < start[s + 1]; ++j)
    {
      const double* p = sorted + 3 * scratch.Sorted[static_cast<size_t>(j)];
      const Eigen::Vector3d d((p[0] - x[0]) * inv, (p[1] - x[1]) * inv, (p[2] - x[2]) * inv);
      if (d.squaredNorm() == 0.0)
      {
        continue; // the point itself and its duplicates: its distance to its neighbours' jet is the residual
      }
      const double u = d.dot(t1), v = d.dot(t2);
      Eigen::Matrix<double, 6, 1> b;
      b << 1.0, u, v, u * u, u * v, v * v;
      M.selfadjointView<Eigen::Upper>().rankUpdate(b);
      B.col(0).noalias() += d.dot(normal) * b;
      ++used;
    }
    if (used < MinimumPerTerm * static_cast<Index>(JetTerms))
    {
      continue;
    }
    Eigen::Matrix<double, 6, 6> A = M;
    A.triangularView<Eigen::StrictlyLower>() = A.transpose();
    Eigen::Matrix<double, 6, 3> rhs = B;
    rhs(1, 1) = 1.0;
    rhs(2, 2) = 1.0;
    Eigen::Matrix<double, 6, 3> Y;
    double condition = 0.0;
    if (!SolveMoment<6>(A, rhs, Y, false, condition) || !Y.allFinite())
    {
      continue; // this radius' neighbours do not determine a jet (e.g. all on a line): try a larger one
    }
    // Slopes and their standard deviations; keep growing while every interval so far shares a point.
    bool disjoint = false;
    for (int c = 0; c < 2; ++c)
    {
      const double a = Y(1 + c, 0);
      const double half = gamma * sigma * std::sqrt(std::max(0.0, Y(1 + c, 1 + c)));
      lower[c] = std::max(lower[c], a - half);
      upper[c] = std::min(upper[c], a + half);
      disjoint = disjoint || lower[c] > upper[c];
    }
    if (disjoint && chosen)
    {
      break;
    }
    chosen = true;
    slope[0] = Y(1, 0);
    slope[1] = Y(2, 0);
    out.Residual = std::fabs(Y(0, 0)) * top;
    chosenShell = s;
  }
  Eigen::Vector3d result = normal;
  if (chosen)
  {
    result = (normal - slope[0] * t1 - slope[1] * t2).normalized();
  }
  else
  {
    // No jet at any radius: the frame's plane, and the distance to it through the centroid.
    chosenShell = frame - 1;
    out.Residual = std::fabs(normal.dot(mean)) * top;
  }
  if (!result.allFinite())
  {
    return out;
  }
  // The PCA at the chosen radius for the surface variation.
  Eigen::Vector3d lc = l;
  if (pca[chosenShell].Covariance(C, mean))
  {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(C);
    lc = eig.eigenvalues();
  }
  for (int a = 0; a < 3; ++a)
  {
    out.Normal[a] = result(a);
    out.Eigenvalues[a] = std::max(0.0, lc(a)) * top * top;
  }
  out.Radius = std::sqrt(radius2[chosenShell]);
  out.Valid = true;
  return out;
}

} // namespace meshfree
