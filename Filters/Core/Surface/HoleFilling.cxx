// SPDX-License-Identifier: BSD-3-Clause
// The fitted surface continued by the winding number (HoleFilling.h).
#include "Surface/HoleFilling.h"

#include "Surface/PointSetSurface.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace meshfree
{

void FilledField::Set(const ImplicitField& fit, const NeighborGrid& grid, const double* supports, const double* points,
  const double* normals, const double* areas, Index count, const Distribution* d)
{
  this->Fit = &fit;
  // The MLS fit leaves every sample within its query radius (>= each support) in the scratch.
  this->FitQueriesSamples = dynamic_cast<const PointSetSurface*>(&fit) != nullptr;
  this->Points = points;
  this->Normals = normals;
  this->Areas = areas;
  this->Count = count;
  this->Grid = &grid;
  const std::vector<Index>& order = grid.SortedOrder();
  std::vector<double> valid;
  for (size_t s = 0; s < order.size(); ++s)
  {
    const double h = supports[order[s]];
    if (h > 0.0 && std::isfinite(h) && IsOwn(d, order[s]))
    {
      valid.push_back(h);
    }
  }
  // One scale for every sample, the median support: a sample's own support is inflated where the sampling
  // is sparse or one-sided (a scan's grazing border), and blending over it let the fits' extrapolation and the
  // winding number's film meet at an angle, folding the surface (measured: dihedral angles up to 178 degrees in
  // the filled part of a virtual scan, against 102-110 with the median).
  this->InverseScale = 0.0;
  if (GlobalSum(d, static_cast<Index>(valid.size())) > 0)
  {
    this->InverseScale = 1.0 / GlobalMedian(d, std::move(valid)); // the whole cloud's (exact when distributed)
  }
  double b[6];
  grid.GetBounds(b);
  const double diagonal = std::sqrt((b[1] - b[0]) * (b[1] - b[0]) + (b[3] - b[2]) * (b[3] - b[2]) + (b[5] - b[4]) * (b[5] - b[4]));
  // |grad w| of a closed surface's 1/2 level is about 1 / (its size); far from the data it decays as
  // 1 / distance^3: the floor keeps f_w finite there (its sign is what matters).
  this->GradientFloor = diagonal > 0.0 ? 1e-3 / diagonal : 1.0;
  // The winding number's cube lattice: edges of one median support from the cloud's corner (the same for every
  // process: a cube is opened within 2 radii of its centre, so the points an evaluation reads lie within 3 x 0.87
  // supports, no farther than the fits' 3); distributed, its tree is built now (collectively), serially on first use.
  this->Cubes = WindingCubes();
  if (this->InverseScale > 0.0)
  {
    this->Cubes.Size = 1.0 / this->InverseScale;
    // Room for the cloud in the lattice's 2^21 cubes per axis.
    const double extent = std::max(b[1] - b[0], std::max(b[3] - b[2], b[5] - b[4]));
    this->Cubes.Size = std::max(this->Cubes.Size, extent / 1048576.0);
    for (int a = 0; a < 3; ++a)
    {
      this->Cubes.Origin[a] = b[2 * a];
    }
  }
  this->Cubes.Processes = d;
  if (d)
  {
    this->Winding();
  }
}

double FilledField::Shortfall() const
{
  if (!this->Built.load() || !this->Cubes.Processes)
  {
    return -HUGE_VAL;
  }
  // A cube opened that this process does not hold: the halo needs the cubes' reach more (opened within Beta = 2
  // radii of their centre, their points a radius farther).
  const double incomplete = this->Tree.Incomplete() ? 1.5 * std::sqrt(3.0) * this->Cubes.Size : -HUGE_VAL;
  return std::max(this->Tree.Shortfall(), incomplete);
}

const WindingNumber& FilledField::Winding() const
{
  std::call_once(this->Once, [this]() {
    this->Tree.Build(this->Points, this->Normals, this->Areas, this->Count, this->Cubes);
    this->Built = true;
  });
  return this->Tree;
}

double FilledField::Blend(const double x[3], double gradient[3], FieldScratch& scratch, bool fitQueried) const
{
  if (gradient)
  {
    std::fill(gradient, gradient + 3, 0.0);
  }
  if (!(this->InverseScale > 0.0))
  {
    return 1.0;
  }
  // The nearest sample: among the neighbours the MLS fit has just gathered (all samples within its narrowest
  // tier's radius, the median support, PointSetSurface::NarrowRadius()), else by a k = 1 query.
  const double* p = nullptr;
  double d2 = std::numeric_limits<double>::infinity();
  if (fitQueried)
  {
    for (size_t j = 0; j < scratch.Dist2.size(); ++j)
    {
      if (scratch.Dist2[j] < d2)
      {
        d2 = scratch.Dist2[j];
        p = this->Grid->SortedPoints() + 3 * scratch.Positions[j];
      }
    }
  }
  else
  {
    Index id = -1;
    if (this->Grid->FindKNearest(x, 1, &id, &d2) == 1)
    {
      p = this->Points + 3 * id;
    }
  }
  const double best = d2 * this->InverseScale * this->InverseScale;
  if (!p || !(best < 1.0))
  {
    return 1.0;
  }
  const double q = std::sqrt(best);
  const double u = (q - Inner) / (1.0 - Inner);
  if (u <= 0.0)
  {
    return 0.0;
  }
  if (gradient && q > 0.0)
  {
    const double inv = this->InverseScale;
    const double dtdq = 6.0 * u * (1.0 - u) / (1.0 - Inner);
    for (int a = 0; a < 3; ++a)
    {
      // grad q = (x - p) / |x - p| / h = (x - p) inv^2 / q
      gradient[a] = dtdq * (x[a] - p[a]) * inv * inv / q;
    }
  }
  return u * u * (3.0 - 2.0 * u);
}

double FilledField::BlendWeight(const double x[3], FieldScratch& scratch) const
{
  return this->Blend(x, nullptr, scratch, false);
}

bool FilledField::Evaluate(const double x[3], double& value, double gradient[3], FieldScratch& scratch) const
{
  double fFit = 0.0, gFit[3] = { 0.0, 0.0, 0.0 }, gt[3] = { 0.0, 0.0, 0.0 };
  const bool fitted = this->Fit->Evaluate(x, fFit, gradient ? gFit : nullptr, scratch);
  double t = this->Blend(x, gradient ? gt : nullptr, scratch, this->FitQueriesSamples);
  if (!fitted)
  {
    t = 1.0; // no fit here: the winding number alone
    std::fill(gt, gt + 3, 0.0);
  }
  if (t <= 0.0)
  {
    value = fFit;
    if (gradient)
    {
      std::copy(gFit, gFit + 3, gradient);
    }
    return true;
  }
  double gw[3];
  const double w = this->Winding().Evaluate(x, gw);
  const double len = std::max(std::sqrt(gw[0] * gw[0] + gw[1] * gw[1] + gw[2] * gw[2]), this->GradientFloor);
  const double fW = (0.5 - w) / len;
  value = (1.0 - t) * fFit + t * fW;
  if (gradient)
  {
    for (int a = 0; a < 3; ++a)
    {
      // grad f_w ~ -grad w / |grad w| (its second-order term vanishes on the 1/2 level).
      gradient[a] = (1.0 - t) * gFit[a] - t * gw[a] / len + (t < 1.0 ? (fW - fFit) * gt[a] : 0.0);
    }
  }
  return std::isfinite(value);
}

std::vector<double> SampleAreas(const std::vector<double>& neighborDistance, int k)
{
  std::vector<double> areas(neighborDistance.size(), 0.0);
  const double perNeighbour = M_PI / static_cast<double>(std::max(1, k));
  for (size_t i = 0; i < areas.size(); ++i)
  {
    const double r = neighborDistance[i];
    areas[i] = r > 0.0 && std::isfinite(r) ? perNeighbour * r * r : 0.0;
  }
  return areas;
}

} // namespace meshfree
