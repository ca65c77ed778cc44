// SPDX-License-Identifier: BSD-3-Clause
// APSS: the moving algebraic-sphere fit of PointSetSurface.h.
#include "Surface/PointSetSurface.h"

#include "Common/LargeArrays.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace meshfree
{
namespace
{
/// A neighbour whose normal makes more than 135 degrees with the reference neighbour's is on a thin part's other
/// side (Fit).
constexpr double kOtherSide = -0.70710678118654752;
} // namespace

void PointSetSurface::SetCloud(const NeighborGrid& grid, const double* normals, const double* radii, const Distribution* d)
{
  this->Grid = &grid;
  const std::vector<Index>& order = grid.SortedOrder();
  const Index nv = static_cast<Index>(order.size());
  this->Normals.assign(static_cast<size_t>(3 * nv), 0.0);
  // Ignored points get an infinite inverse radius: q = inf (or NaN at distance 0) is never < 1.
  this->InverseRadii.assign(static_cast<size_t>(nv), std::numeric_limits<double>::infinity());
  double largest = 0.0;
  for (Index s = 0; s < nv; ++s)
  {
    const Index id = order[s];
    const double* n = &normals[3 * id];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double r = radii[id];
    if (!(len > 0.0) || !std::isfinite(len) || !(r > 0.0) || !std::isfinite(r))
    {
      continue;
    }
    for (int a = 0; a < 3; ++a)
    {
      this->Normals[3 * s + a] = n[a] / len;
    }
    this->InverseRadii[s] = 1.0 / r;
    largest = std::max(largest, r);
  }
  largest = GlobalMax(d, largest);
  this->QueryRadius = largest;
  // The tiers (class comment): split at the 50th, 90th and 99th percentiles of the supports (of the whole cloud).
  std::vector<double> supports;
  supports.reserve(static_cast<size_t>(nv));
  for (Index s = 0; s < nv; ++s)
  {
    if (std::isfinite(this->InverseRadii[s]) && IsOwn(d, order[s]))
    {
      supports.push_back(1.0 / this->InverseRadii[s]);
    }
  }
  this->Tiers.clear();
  this->NearRadius = largest;
  const Index count = GlobalSum(d, static_cast<Index>(supports.size()));
  if (count < 64)
  {
    return; // one query with the largest support
  }
  std::sort(supports.begin(), supports.end());
  std::vector<double> bounds;
  for (const double share : { 0.5, 0.9, 0.99 })
  {
    const double split = GlobalSelect(d, supports, static_cast<Index>(share * static_cast<double>(count - 1)));
    // A tier must narrow the query noticeably.
    if (split < 0.9 * largest && (bounds.empty() || split > 1.1 * bounds.back()))
    {
      bounds.push_back(split);
    }
  }
  if (bounds.empty())
  {
    return;
  }
  bounds.push_back(largest);
  // Worth it only when the tiers gather clearly fewer points than one query (a surface's points within r grow as
  // r^2): sum over tiers of (share of samples) x radius^2 below 0.7 largest^2. A uniform cloud's supports are
  // nearly equal, and it keeps the single query.
  double cost = 0.0;
  size_t below = 0;
  for (const double bound : bounds)
  {
    const Index upto = GlobalSum(
      d, static_cast<Index>(std::upper_bound(supports.begin(), supports.end(), bound) - supports.begin()));
    cost += static_cast<double>(upto - static_cast<Index>(below)) / static_cast<double>(count) * bound * bound;
    below = static_cast<size_t>(upto);
  }
  if (!(cost < 0.7 * largest * largest))
  {
    return;
  }
  std::vector<double>().swap(supports);
  this->NearRadius = bounds.front();
  this->Tiers.resize(bounds.size());
  std::vector<std::vector<double>> coordinates(bounds.size());
  std::vector<std::vector<Index>> positions(bounds.size());
  const double* xyz = grid.SortedPoints();
  // Each sample's tier (-1: none), then the tiers' arrays at their exact sizes (grown by doubling they faulted
  // their pages in twice: LargeArrays.h).
  detail::Buffer<std::int8_t> tierOf;
  tierOf.resize(static_cast<size_t>(nv));
  std::vector<size_t> tierSize(bounds.size(), 0);
  for (Index s = 0; s < nv; ++s)
  {
    tierOf[s] = -1;
    if (!std::isfinite(this->InverseRadii[s]))
    {
      continue;
    }
    const double r = 1.0 / this->InverseRadii[s];
    const size_t t = static_cast<size_t>(std::lower_bound(bounds.begin(), bounds.end(), r) - bounds.begin());
    const size_t tier = std::min(t, bounds.size() - 1);
    tierOf[s] = static_cast<std::int8_t>(tier);
    ++tierSize[tier];
  }
  for (size_t t = 0; t < bounds.size(); ++t)
  {
    detail::ReserveLarge(coordinates[t], 3 * tierSize[t]);
    detail::ReserveLarge(positions[t], tierSize[t]);
  }
  for (Index s = 0; s < nv; ++s)
  {
    if (tierOf[s] >= 0)
    {
      const size_t tier = static_cast<size_t>(tierOf[s]);
      coordinates[tier].insert(coordinates[tier].end(), xyz + 3 * s, xyz + 3 * s + 3);
      positions[tier].push_back(s);
    }
  }
  detail::Buffer<std::int8_t>().swap(tierOf);
  // Each tier's grid framed by the whole cloud's tier points (the same cells and order as a serial run's).
  std::vector<double> ownCoordinates;
  for (size_t t = 0; d && t < bounds.size(); ++t)
  {
    ownCoordinates.clear();
    for (size_t w = 0; w < positions[t].size(); ++w)
    {
      if (IsOwn(d, order[positions[t][w]]))
      {
        ownCoordinates.insert(ownCoordinates.end(), &coordinates[t][3 * w], &coordinates[t][3 * w] + 3);
      }
    }
    double frame[6];
    GlobalBounds(d, ownCoordinates.data(), static_cast<Index>(ownCoordinates.size() / 3), frame);
    this->Tiers[t].Grid.SetFrame(frame, GlobalSum(d, static_cast<Index>(ownCoordinates.size() / 3)));
  }
  for (size_t t = 0; t < bounds.size(); ++t)
  {
    Tier& tier = this->Tiers[t];
    tier.Radius = bounds[t];
    // Index order within cells is the main grid's sorted order here, itself by position: still order independent.
    tier.Grid.SetCellsByPosition(false);
    // The grid's automatic cell size (about 8 points a cell): cells as wide as the tier's query radius measured no
    // faster (1M-point scan-like cloud, 2026-12-03: 10.7-10.8 s against 10.9 s for the whole surface).
    tier.Grid.Build(coordinates[t].data(), static_cast<Index>(positions[t].size()));
    const std::vector<Index>& order = tier.Grid.SortedOrder();
    tier.Positions.resize(order.size());
    for (size_t w = 0; w < order.size(); ++w)
    {
      tier.Positions[w] = positions[t][static_cast<size_t>(order[w])];
    }
    // Built once: the tier's copies and the grid's sort scratch go now (this is where a distributed surface's
    // memory peaks: issue 24).
    tier.Grid.ReleaseBuildScratch();
    std::vector<double>().swap(coordinates[t]);
    std::vector<Index>().swap(positions[t]);
  }
}

void PointSetSurface::Gather(const double x[3], FieldScratch& s) const
{
  if (this->Tiers.empty())
  {
    this->Grid->FindWithinRadiusPositions(x, this->QueryRadius, s.Positions, s.Dist2);
    return;
  }
  s.Positions.clear();
  s.Dist2.clear();
  for (const Tier& tier : this->Tiers)
  {
    if (tier.Positions.empty())
    {
      continue;
    }
    tier.Grid.FindWithinRadiusPositions(x, tier.Radius, s.MorePositions, s.MoreDist2);
    for (size_t j = 0; j < s.MorePositions.size(); ++j)
    {
      s.Positions.push_back(tier.Positions[static_cast<size_t>(s.MorePositions[j])]);
      s.Dist2.push_back(s.MoreDist2[j]);
    }
  }
}

bool PointSetSurface::Fit(const double x[3], SphereFit& fit, FieldScratch& s) const
{
  if (!this->Grid || !(this->QueryRadius > 0.0))
  {
    return false;
  }
  this->Gather(x, s);
  const size_t found = s.Positions.size();
  if (found < static_cast<size_t>(this->MinimumNeighbors))
  {
    return false;
  }
  // One pass, two sets of moments (centred on x, scaled by H): neighbours whose normal agrees with the first
  // weighted neighbour's, and the others. The heavier set is fitted; the other is the far side of a sheet
  // thinner than the support (or a few flipped normals), which must not be averaged in. "Agrees" means closer to
  // the same direction than to the opposite one by more than perpendicular: within 135 degrees. A sheet's far side
  // faces nearly opposite; a corner's other face (about 90 degrees away) is the same surface turning, and split off
  // at 90 degrees it flipped between the sets from one evaluation point to the next where scan noise tilts those
  // normals around perpendicular: the bunny's base (a ledge over its bottom) grew two small bubbles joined into a
  // handle (chi 0 instead of 2), gone with the 135 degrees; noisy cubes came out as close or closer (rms 1.76e-3
  // against 1.88e-3 at noise 0.005 of the half-side), only an exactly noiseless cube's edges round off a little.
  struct Moments
  {
    double W = 0.0, D[3] = { 0.0, 0.0, 0.0 }, N[3] = { 0.0, 0.0, 0.0 }, DN = 0.0, DD = 0.0;
    int Count = 0;
  } sets[2];
  const double invH = 1.0 / this->QueryRadius;
  const double* xyz = this->Grid->SortedPoints();
  const double* normals = this->Normals.data();
  const double* reference = nullptr;
  for (size_t j = 0; j < found; ++j)
  {
    const Index p = s.Positions[j];
    const double q = std::sqrt(s.Dist2[j]) * this->InverseRadii[p];
    if (!(q < 1.0))
    {
      continue;
    }
    const double u = 1.0 - q;
    const double w = u * u * u * u * (4.0 * q + 1.0);
    const double* n = normals + 3 * p;
    reference = reference ? reference : n;
    Moments& m = sets[n[0] * reference[0] + n[1] * reference[1] + n[2] * reference[2] > kOtherSide ? 0 : 1];
    const double d[3] = { (xyz[3 * p] - x[0]) * invH, (xyz[3 * p + 1] - x[1]) * invH, (xyz[3 * p + 2] - x[2]) * invH };
    m.W += w;
    for (int a = 0; a < 3; ++a)
    {
      m.D[a] += w * d[a];
      m.N[a] += w * n[a];
    }
    m.DN += w * (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
    m.DD += w * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    ++m.Count;
  }
  const Moments& m = sets[sets[1].W > sets[0].W ? 1 : 0];
  const int used = m.Count;
  const double sw = m.W, sdn = m.DN, sdd = m.DD;
  const double* sd = m.D;
  const double* sn = m.N;
  if (used < this->MinimumNeighbors || !(sw > 0.0))
  {
    return false;
  }
  const double inv = 1.0 / sw;
  const double A[3] = { sd[0] * inv, sd[1] * inv, sd[2] * inv };
  const double B[3] = { sn[0] * inv, sn[1] * inv, sn[2] * inv };
  const double C = sdn * inv, D = sdd * inv;
  const double AA = A[0] * A[0] + A[1] * A[1] + A[2] * A[2];
  const double AB = A[0] * B[0] + A[1] * B[1] + A[2] * B[2];
  const double spread = D - AA;
  const double uq = spread > 1e-12 ? 0.5 * (C - AB) / spread : 0.0;
  double ul[3];
  for (int a = 0; a < 3; ++a)
  {
    ul[a] = B[a] - 2.0 * uq * A[a];
  }
  const double u0 = -(ul[0] * A[0] + ul[1] * A[1] + ul[2] * A[2]) - uq * D;
  const double norm = std::sqrt(ul[0] * ul[0] + ul[1] * ul[1] + ul[2] * ul[2]);
  if (!(norm > 1e-2) || !std::isfinite(norm) || !std::isfinite(u0))
  {
    return false; // the normals cancel: no side is outside
  }
  const double disc = norm * norm - 4.0 * u0 * uq;
  // Distance to the sphere; an imaginary sphere (inconsistent data) falls back to the plane's distance.
  const double distance = disc >= 0.0 ? 2.0 * u0 / (norm + std::sqrt(disc)) : u0 / norm;
  fit.Distance = distance * this->QueryRadius;
  for (int a = 0; a < 3; ++a)
  {
    fit.Direction[a] = ul[a] / norm;
  }
  fit.Curvature = 2.0 * uq / norm * invH;
  fit.Neighbors = used;
  return std::isfinite(fit.Distance) && std::isfinite(fit.Curvature);
}

bool PointSetSurface::Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& scratch) const
{
  SphereFit fit;
  if (!this->Fit(x, fit, scratch))
  {
    return false;
  }
  value = fit.Distance;
  if (gradient)
  {
    for (int a = 0; a < 3; ++a)
    {
      gradient[a] = fit.Direction[a];
    }
  }
  return true;
}

} // namespace meshfree
