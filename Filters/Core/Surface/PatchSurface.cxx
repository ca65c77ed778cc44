// SPDX-License-Identifier: BSD-3-Clause
// Partition of unity of local height fits (PatchSurface.h).
#include "Surface/PatchSurface.h"

#include "Common/LocalFit.h"
#include "Common/Parallel.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace meshfree
{

namespace
{
inline double Wendland(double q)
{
  if (!(q < 1.0))
  {
    return 0.0;
  }
  const double u = 1.0 - q;
  return u * u * u * u * (4.0 * q + 1.0);
}

/// d/dq of Wendland(q).
inline double WendlandDerivative(double q)
{
  if (!(q < 1.0))
  {
    return 0.0;
  }
  const double u = 1.0 - q;
  return -20.0 * q * u * u * u;
}

/// Orthonormal t1, t2 completing the unit n.
void Tangents(const double n[3], double t1[3], double t2[3])
{
  const double a[3] = { std::fabs(n[0]) < 0.9 ? 1.0 : 0.0, std::fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0 };
  t1[0] = a[1] * n[2] - a[2] * n[1];
  t1[1] = a[2] * n[0] - a[0] * n[2];
  t1[2] = a[0] * n[1] - a[1] * n[0];
  const double len = std::sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
  for (int i = 0; i < 3; ++i)
  {
    t1[i] /= len;
  }
  t2[0] = n[1] * t1[2] - n[2] * t1[1];
  t2[1] = n[2] * t1[0] - n[0] * t1[2];
  t2[2] = n[0] * t1[1] - n[1] * t1[0];
}

/// Weighted least-squares heights h = g(u, v) of `terms` monomials (1, u, v, u^2, uv, v^2).
template <int Q>
bool FitHeights(const std::vector<double>& uvh, const std::vector<double>& w, double* coefficients)
{
  Eigen::Matrix<double, Q, Q> M = Eigen::Matrix<double, Q, Q>::Zero();
  Eigen::Matrix<double, Q, 1> B = Eigen::Matrix<double, Q, 1>::Zero();
  const size_t m = w.size();
  for (size_t j = 0; j < m; ++j)
  {
    const double u = uvh[3 * j], v = uvh[3 * j + 1];
    const double all[6] = { 1.0, u, v, u * u, u * v, v * v };
    const Eigen::Map<const Eigen::Matrix<double, Q, 1>> b(all);
    M.noalias() += w[j] * b * b.transpose();
    B.noalias() += (w[j] * uvh[3 * j + 2]) * b;
  }
  Eigen::Matrix<double, Q, 1> y;
  double condition = 0.0;
  if (!SolveMoment<Q>(M, B, y, false, condition))
  {
    return false;
  }
  for (int i = 0; i < Q; ++i)
  {
    coefficients[i] = y(i);
  }
  return y.allFinite();
}
} // namespace

void PatchSurface::SetCloud(const NeighborGrid& grid, const double* normals, const double* radii, const Distribution* d)
{
  this->Frames.clear();
  this->Heights.clear();
  this->Radius.clear();
  this->Positions.clear();
  this->QueryRadius = 0.0;
  const std::vector<Index>& order = grid.SortedOrder();
  const double* sorted = grid.SortedPoints();
  const Index nv = static_cast<Index>(order.size());
  std::vector<double> valid;
  for (Index s = 0; s < nv; ++s)
  {
    const Index id = order[s];
    if (radii[id] > 0.0 && std::isfinite(radii[id]) && IsOwn(d, id))
    {
      valid.push_back(radii[id]);
    }
  }
  // The median of the whole cloud's supports (an exact selection when distributed: the same as serial).
  const Index supported = GlobalSum(d, static_cast<Index>(valid.size()));
  const double rho = supported > 0 ? GlobalMedian(d, std::move(valid)) : 0.0;
  if (supported == 0)
  {
    this->Centres.Build(nullptr, 0);
    return;
  }
  const double patch = 0.5 * rho;

  // Points bucketed by coarse cell (relative to the bounds' minimum).
  double b[6];
  grid.GetBounds(b);
  std::vector<std::pair<std::uint64_t, Index>> keyed;
  keyed.reserve(static_cast<size_t>(nv));
  for (Index s = 0; s < nv; ++s)
  {
    const Index id = order[s];
    const double* n = normals + 3 * id;
    if (!(radii[id] > 0.0) || !(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.0))
    {
      continue;
    }
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a)
    {
      const double t = std::floor((sorted[3 * s + a] - b[2 * a]) / patch);
      key |= static_cast<std::uint64_t>(std::min(t, 2097151.0)) << (21 * a);
    }
    keyed.emplace_back(key, s);
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<double> centres, frames;
  std::vector<unsigned char> own; // distributed: the patch's first point is this process' own
  for (size_t i = 0; i < keyed.size();)
  {
    size_t j = i;
    double c[3] = { 0, 0, 0 }, n[3] = { 0, 0, 0 };
    for (; j < keyed.size() && keyed[j].first == keyed[i].first; ++j)
    {
      const Index s = keyed[j].second;
      const double* nn = normals + 3 * order[s];
      for (int a = 0; a < 3; ++a)
      {
        c[a] += sorted[3 * s + a] - sorted[3 * keyed[i].second + a];
        n[a] += nn[a];
      }
    }
    const double count = static_cast<double>(j - i);
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0)
    {
      for (int a = 0; a < 3; ++a)
      {
        centres.push_back(sorted[3 * keyed[i].second + a] + c[a] / count);
      }
      double frame[9];
      for (int a = 0; a < 3; ++a)
      {
        frame[6 + a] = n[a] / len;
      }
      Tangents(frame + 6, frame, frame + 3);
      frames.insert(frames.end(), frame, frame + 9);
      own.push_back(IsOwn(d, order[keyed[i].second]) ? 1 : 0);
    }
    i = j;
  }
  const Index candidates = static_cast<Index>(centres.size() / 3);

  // One height fit per patch over the points within rho.
  std::vector<double> heights(static_cast<size_t>(6 * candidates), 0.0);
  std::vector<unsigned char> kept(static_cast<size_t>(candidates), 0);
  struct Buffers
  {
    std::vector<Index> Positions;
    std::vector<double> Dist2, UVH, Weights;
  };
  PerThread<Buffers> buffers;
  ParallelFor(candidates, 64, [&](Index begin, Index end) {
    Buffers& mine = buffers.Local();
    std::vector<Index>& pos = mine.Positions;
    std::vector<double>& d2 = mine.Dist2;
    std::vector<double>& uvh = mine.UVH;
    std::vector<double>& w = mine.Weights;
    for (Index p = begin; p < end; ++p)
    {
      const double* c = &centres[3 * p];
      double* f = &frames[9 * p];
      grid.FindWithinRadiusPositions(c, rho, pos, d2);
      // The frame's normal: the weighted mean of the normals over the whole support, not only the cell's
      // (a cell may hold a single point deep in the noise whose normal is tilted far off; alone it would set
      // a patch across the surface and a spurious zero beneath it).
      double mean[3] = { 0.0, 0.0, 0.0 };
      for (size_t j = 0; j < pos.size(); ++j)
      {
        const Index id = order[pos[j]];
        const double* nn = normals + 3 * id;
        const double w = radii[id] > 0.0 ? Wendland(std::sqrt(d2[j]) / rho) : 0.0;
        for (int a = 0; a < 3; ++a)
        {
          mean[a] += w * nn[a];
        }
      }
      const double len = std::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
      if (len > 0.0 && std::isfinite(len))
      {
        for (int a = 0; a < 3; ++a)
        {
          f[6 + a] = mean[a] / len;
        }
        Tangents(f + 6, f, f + 3);
      }
      uvh.clear();
      w.clear();
      for (size_t j = 0; j < pos.size(); ++j)
      {
        const Index s = pos[j];
        const double* nn = normals + 3 * order[s];
        // Only points on this side of a thin sheet (normals agreeing with the patch's).
        if (!(radii[order[s]] > 0.0) || nn[0] * f[6] + nn[1] * f[7] + nn[2] * f[8] <= 0.0)
        {
          continue;
        }
        const double d[3] = { sorted[3 * s] - c[0], sorted[3 * s + 1] - c[1], sorted[3 * s + 2] - c[2] };
        for (int r = 0; r < 3; ++r)
        {
          uvh.push_back((f[3 * r] * d[0] + f[3 * r + 1] * d[1] + f[3 * r + 2] * d[2]) / rho);
        }
        w.push_back(Wendland(std::sqrt(d2[j]) / rho));
      }
      double* h = &heights[6 * p];
      const size_t m = w.size();
      bool ok = m >= 2 * 6 && FitHeights<6>(uvh, w, h);
      if (!ok && m >= 2 * 3)
      {
        std::fill(h, h + 6, 0.0);
        ok = FitHeights<3>(uvh, w, h);
      }
      if (!ok && m >= 2)
      {
        std::fill(h, h + 6, 0.0);
        ok = FitHeights<1>(uvh, w, h);
      }
      kept[p] = ok ? 1 : 0;
    }
  });
  for (Index p = 0; p < candidates; ++p)
  {
    if (!kept[p])
    {
      continue;
    }
    this->Positions.insert(this->Positions.end(), &centres[3 * p], &centres[3 * p] + 3);
    this->Frames.insert(this->Frames.end(), &frames[9 * p], &frames[9 * p] + 9);
    this->Heights.insert(this->Heights.end(), &heights[6 * p], &heights[6 * p] + 6);
    this->Radius.push_back(rho);
  }
  // The centres' grid framed by the whole cloud's patches (the same cells, hence the same sums, as serial).
  std::vector<double> owned;
  for (Index p = 0; p < candidates; ++p)
  {
    if (kept[p] && own[p])
    {
      owned.insert(owned.end(), &centres[3 * p], &centres[3 * p] + 3);
    }
  }
  double frame[6];
  GlobalBounds(d, owned.data(), static_cast<Index>(owned.size() / 3), frame);
  this->Centres.SetFrame(frame, GlobalSum(d, static_cast<Index>(owned.size() / 3)));
  this->Centres.Build(this->Positions.data(), static_cast<Index>(this->Radius.size()));
  this->QueryRadius = rho;
}

bool PatchSurface::Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& s) const
{
  if (this->Radius.empty())
  {
    return false;
  }
  this->Centres.FindWithinRadius(x, this->QueryRadius, s.Positions, &s.Dist2);
  // Two sides (the class comment's thin parts): the patches facing like the heaviest one, and those facing
  // away from it (normals more than 120 degrees apart); the heavier side is blended.
  const double* facing = nullptr;
  double heaviest = 0.0;
  for (size_t j = 0; j < s.Positions.size(); ++j)
  {
    const double w = Wendland(std::sqrt(s.Dist2[j]) / this->Radius[s.Positions[j]]);
    if (w > heaviest)
    {
      heaviest = w;
      facing = &this->Frames[9 * s.Positions[j] + 6];
    }
  }
  if (!facing)
  {
    return false;
  }
  struct Sums
  {
    double W = 0.0, WQ = 0.0, GW[3] = { 0, 0, 0 }, GWQ[3] = { 0, 0, 0 }, GQ[3] = { 0, 0, 0 };
  } sides[2];
  for (size_t j = 0; j < s.Positions.size(); ++j)
  {
    const Index p = s.Positions[j];
    const double rho = this->Radius[p];
    const double dist = std::sqrt(s.Dist2[j]);
    const double q = dist / rho;
    const double w = Wendland(q);
    if (!(w > 0.0))
    {
      continue;
    }
    const double* c = &this->Positions[3 * p];
    const double* f = &this->Frames[9 * p];
    Sums& side = sides[f[6] * facing[0] + f[7] * facing[1] + f[8] * facing[2] < -0.5 ? 1 : 0];
    double& sw = side.W;
    double& swq = side.WQ;
    double* gw = side.GW;
    double* gwq = side.GWQ;
    double* gq = side.GQ;
    const double* a = &this->Heights[6 * p];
    const double d[3] = { x[0] - c[0], x[1] - c[1], x[2] - c[2] };
    const double u = (f[0] * d[0] + f[1] * d[1] + f[2] * d[2]) / rho;
    const double v = (f[3] * d[0] + f[4] * d[1] + f[5] * d[2]) / rho;
    const double h = (f[6] * d[0] + f[7] * d[1] + f[8] * d[2]) / rho;
    const double g = a[0] + a[1] * u + a[2] * v + a[3] * u * u + a[4] * u * v + a[5] * v * v;
    const double gu = a[1] + 2.0 * a[3] * u + a[4] * v;
    const double gv = a[2] + a[4] * u + 2.0 * a[5] * v;
    const double slope = std::sqrt(1.0 + gu * gu + gv * gv);
    const double local = rho * (h - g) / slope;
    sw += w;
    swq += w * local;
    if (gradient)
    {
      const double dw = dist > 0.0 ? WendlandDerivative(q) / (rho * dist) : 0.0;
      for (int k = 0; k < 3; ++k)
      {
        const double gradLocal = (f[6 + k] - gu * f[k] - gv * f[3 + k]) / slope;
        gw[k] += dw * d[k];
        gwq[k] += dw * d[k] * local;
        gq[k] += w * gradLocal;
      }
    }
  }
  const Sums& used = sides[sides[1].W > sides[0].W ? 1 : 0];
  const double sw = used.W;
  if (!(sw > 0.0))
  {
    return false;
  }
  const double* gw = used.GW;
  const double* gwq = used.GWQ;
  const double* gq = used.GQ;
  value = used.WQ / sw;
  if (gradient)
  {
    // grad (sum w Q / sum w) = (sum w grad Q + sum grad w (Q - f)) / sum w
    for (int k = 0; k < 3; ++k)
    {
      gradient[k] = (gq[k] + gwq[k] - value * gw[k]) / sw;
    }
  }
  return std::isfinite(value);
}

} // namespace meshfree
