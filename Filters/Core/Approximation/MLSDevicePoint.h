// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: one MLS evaluation point of the device path (cuda/ApproximationDevice.cu runs it, one thread per
// point), as MESHFREE_HD code on plain views of the cloud, so that the CPU tests run the very same search and fit
// (Testing/Core/TestMLSDevicePoint.cxx) although no GPU is at hand. It reproduces Approximator::MLSShape/MLSPoint
// for the case the fast path finishes: the k nearest in NeighborGrid's neighbour order (d2, then position, then
// original index: GridNeighborBefore) found in its cell-sorted layout (rings of cells around the query's cell,
// pruned by the k-th distance), h = SupportFactor x d_k, the neighbours in that order, the plain weights of
// KernelShapes.h, the moment solve of MLSFastPath.h, values and gradients summed in the CPU's order. Anything else
// returns false: the caller hands the point to the CPU.
#ifndef meshfree_MLSDevicePoint_h
#define meshfree_MLSDevicePoint_h

#include "Common/GridCell.h"
#include "Common/HostDevice.h"
#include "Common/KernelShapes.h"
#include "Common/MLSFastPath.h"

#include <cmath>

namespace meshfree
{
namespace mls
{

/// The longest neighbour list (k) a point keeps, and the components summed per pass.
constexpr int kMaxNeighbors = 64;
constexpr int kComponentGroup = 4;
/// Rings of cells searched around a query's cell before it is left to the CPU (far from the cloud).
constexpr int kMaxRings = 24;

/// The cloud: NeighborGrid's layout (plain pointers, passed by value).
struct CloudView
{
  const double* Points;   // 3 * n, cell-sorted
  const int* Ids;         // original index per sorted position
  const double* Values;   // n * Components, sorted order
  const long long* Cells; // 2 per cell
  long long Dims[3];
  double Origin[3];
  double Size;
  double InvSize;
  int Components;
};

struct FitConstants
{
  int K;
  double SupportFactor;
  int WeightKind;
  double WeightNormalization;
  double Axes[3][3];
  int Gradients;
  int FirstComponent; // this pass: components [FirstComponent, FirstComponent + GroupComponents)
  int GroupComponents;
};

/// Outputs of a batch of points, indexed by the batch position t.
struct OutputView
{
  double* Values;          // Count * Components (chunk)
  double* Gradients;       // Count * Components * 3
  int* Neighbors;          // Count
  double* Conditions;      // Count
  unsigned char* NeedsCPU; // Count (OR-ed over the component passes)
};

/// (d2, sorted position p) before (e2, q) in NeighborGrid's neighbour order.
MESHFREE_HD inline bool Before(const CloudView& cloud, double d2, int p, double e2, int q)
{
  return d2 < e2 ||
    (d2 == e2 &&
      GridPointBefore(cloud.Points + 3 * static_cast<long long>(p), cloud.Ids[p],
        cloud.Points + 3 * static_cast<long long>(q), cloud.Ids[q]));
}

/// The k nearest cloud points of x in NeighborGrid's neighbour order, in bd2/bid/bpos sorted that way; returns how
/// many (fewer than k only when the cloud has fewer points), or -1 when the search gave up (too far from the cloud).
MESHFREE_HD inline int KNearest(const CloudView& cloud, const double x[3], int k, double* bd2, int* bid, int* bpos)
{
  long long c[3];
  double reach = 0.0; // how many rings it takes to cover the grid from c
  double scale = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    double t = floor((x[a] - cloud.Origin[a]) * cloud.InvSize);
    const double top = static_cast<double>(cloud.Dims[a] - 1);
    t = t < 0.0 ? 0.0 : (t > top ? top : t);
    c[a] = static_cast<long long>(t);
    const double span = fmax(t, top - t);
    reach = fmax(reach, span);
    scale = fmax(scale, fabs(x[a]) + fabs(cloud.Origin[a]));
  }
  // Every point in a ring beyond r lies at least r cells away from x's cell (x inside it, or outside the grid
  // beyond it). The margin covers the rounding of the cell assignment and of x - Origin.
  const double margin = 1e-6 * cloud.Size + 1e-12 * scale;
  int found = 0;
  for (int r = 0;; ++r)
  {
    if (r > kMaxRings)
    {
      return -1;
    }
    for (long long dz = -r; dz <= r; ++dz)
    {
      const long long cz = c[2] + dz;
      if (cz < 0 || cz >= cloud.Dims[2])
      {
        continue;
      }
      for (long long dy = -r; dy <= r; ++dy)
      {
        const long long cy = c[1] + dy;
        if (cy < 0 || cy >= cloud.Dims[1])
        {
          continue;
        }
        const bool face = dz == -r || dz == r || dy == -r || dy == r;
        const long long step = (face || r == 0) ? 1 : 2 * r;
        for (long long dx = -r; dx <= r; dx += step)
        {
          const long long cx = c[0] + dx;
          if (cx < 0 || cx >= cloud.Dims[0])
          {
            continue;
          }
          const long long cell = cx + cloud.Dims[0] * (cy + cloud.Dims[1] * cz);
          const long long begin = cloud.Cells[2 * cell], end = cloud.Cells[2 * cell + 1];
          for (long long p = begin; p < end; ++p)
          {
            const double* q = cloud.Points + 3 * p;
            // The grid's distance: (px - x)^2 + (py - y)^2 + (pz - z)^2 in that order.
            const double e0 = q[0] - x[0], e1 = q[1] - x[1], e2 = q[2] - x[2];
            const double d2 = e0 * e0 + e1 * e1 + e2 * e2;
            const int id = cloud.Ids[p];
            const int pos = static_cast<int>(p);
            int j;
            if (found < k)
            {
              j = found++;
            }
            else if (Before(cloud, d2, pos, bd2[k - 1], bpos[k - 1]))
            {
              j = k - 1;
            }
            else
            {
              continue;
            }
            while (j > 0 && Before(cloud, d2, pos, bd2[j - 1], bpos[j - 1]))
            {
              bd2[j] = bd2[j - 1];
              bid[j] = bid[j - 1];
              bpos[j] = bpos[j - 1];
              --j;
            }
            bd2[j] = d2;
            bid[j] = id;
            bpos[j] = pos;
          }
        }
      }
    }
    if (static_cast<double>(r) >= reach)
    {
      return found; // the whole grid has been visited
    }
    const double bound = static_cast<double>(r) * cloud.Size - margin;
    if (found == k && bound > 0.0 && bound * bound > bd2[k - 1])
    {
      return found;
    }
  }
}

/// One MLS point (see the file comment); returns whether it was finished here.
template <int D, int M>
MESHFREE_HD inline bool MLSFast(
  const CloudView& cloud, const FitConstants& fc, const double x[3], long long t, const OutputView& out)
{
  constexpr int Q = mls::BasisSizeOf<D, M>::Value;
  constexpr int R = mls::MLSColumns<D, M>::Value;
  if (!(fabs(x[0]) <= 1.7976931348623157e308) || !(fabs(x[1]) <= 1.7976931348623157e308) ||
    !(fabs(x[2]) <= 1.7976931348623157e308))
  {
    return false;
  }
  double bd2[kMaxNeighbors];
  int bid[kMaxNeighbors];
  int bpos[kMaxNeighbors];
  const int found = KNearest(cloud, x, fc.K, bd2, bid, bpos);
  if (found <= 0)
  {
    return false;
  }
  const double h = fc.SupportFactor * sqrt(bd2[found - 1]);
  if (!(h > 0.0))
  {
    return false; // the CPU's all-coincident rule
  }
  // The CPU sums over the neighbours in this (the neighbour) order too.
  const double invH = 1.0 / h;
  const double invH2 = invH * invH;
  int m = 0; // bd2 now holds the weights of the m neighbours kept, bpos their sorted positions
  for (int j = 0; j < found; ++j)
  {
    // The unit kernel's ValueSquared: q^2 = |d2 / h^2| x 1 (its inverse radius squared is exactly 1).
    const double w = PlainWeightSquared(fc.WeightKind, fc.WeightNormalization, fabs(bd2[j] * invH2));
    if (!(w > 0.0) || !(w <= 1.7976931348623157e308))
    {
      continue;
    }
    bd2[m] = w;
    bpos[m] = bpos[j];
    ++m;
  }
  if (m < Q)
  {
    return false;
  }
  auto local = [&](int j, double xi[3]) {
    const double* q = cloud.Points + 3 * static_cast<long long>(bpos[j]);
    const double dx[3] = { q[0] - x[0], q[1] - x[1], q[2] - x[2] };
    for (int a = 0; a < 3; ++a)
    {
      xi[a] = a < D ? (fc.Axes[a][0] * dx[0] + fc.Axes[a][1] * dx[1] + fc.Axes[a][2] * dx[2]) * invH : 0.0;
    }
  };
  double moment[Q * Q];
  MESHFREE_UNROLL
  for (int a = 0; a < Q * Q; ++a)
  {
    moment[a] = 0.0;
  }
  for (int j = 0; j < m; ++j)
  {
    double xi[3];
    local(j, xi);
    double p[Q];
    mls::EvaluateBasis<D, M>(xi, p);
    mls::AccumulateMoment<Q>(p, bd2[j], moment);
  }
  double s[Q];
  if (!mls::EquilibrateMoment<Q>(moment, s))
  {
    return false;
  }
  double y[Q * R];
  double condition = 0.0;
  const int r = fc.Gradients ? R : 1;
  if (!mls::CholeskyIdentitySolve<Q, R>(moment, s, r, y, condition))
  {
    return false;
  }
  // Apply the shape functions (Approximator::MLSPoint): values v_c = sum_j phi_j f_jc and gradient sums
  // sum_j dphi_aj f_jc, each accumulated from 0 in neighbour order.
  const int C = cloud.Components;
  double v[kComponentGroup], g[3][kComponentGroup];
  MESHFREE_UNROLL
  for (int c = 0; c < kComponentGroup; ++c)
  {
    v[c] = 0.0;
    g[0][c] = g[1][c] = g[2][c] = 0.0;
  }
  for (int j = 0; j < m; ++j)
  {
    double xi[3];
    local(j, xi);
    double p[Q];
    mls::EvaluateBasis<D, M>(xi, p);
    const double w = bd2[j];
    const double phi = w * mls::ShapeDot<Q>(p, y);
    const double* f = cloud.Values + static_cast<long long>(bpos[j]) * C + fc.FirstComponent;
    MESHFREE_UNROLL
    for (int c = 0; c < kComponentGroup; ++c)
    {
      if (c < fc.GroupComponents)
      {
        v[c] += phi * f[c];
      }
    }
    if (R > 1 && fc.Gradients)
    {
      MESHFREE_UNROLL
      for (int a = 0; a < D; ++a)
      {
        const double dphi = w * mls::ShapeDot<Q>(p, y + (1 + a) * Q);
        MESHFREE_UNROLL
        for (int c = 0; c < kComponentGroup; ++c)
        {
          if (c < fc.GroupComponents)
          {
            g[a][c] += dphi * f[c];
          }
        }
      }
    }
  }
  bool finite = true;
  double grad[3][kComponentGroup] = {};
  MESHFREE_UNROLL
  for (int c = 0; c < kComponentGroup; ++c)
  {
    finite = finite && fabs(v[c]) <= 1.7976931348623157e308;
    if (fc.Gradients)
    {
      // Frame.Unproject of the local gradient (sum / h per axis): g_i = 0 + sum_a A_ai l_a.
      double l[3] = { 0.0, 0.0, 0.0 };
      MESHFREE_UNROLL
      for (int a = 0; a < D; ++a)
      {
        l[a] = g[a][c] * invH;
      }
      MESHFREE_UNROLL
      for (int i = 0; i < 3; ++i)
      {
        grad[i][c] = 0.0;
      }
      MESHFREE_UNROLL
      for (int a = 0; a < D; ++a)
      {
        MESHFREE_UNROLL
        for (int i = 0; i < 3; ++i)
        {
          grad[i][c] += fc.Axes[a][i] * l[a];
        }
      }
      if (c < fc.GroupComponents)
      {
        finite = finite && fabs(grad[0][c]) <= 1.7976931348623157e308 && fabs(grad[1][c]) <= 1.7976931348623157e308 &&
          fabs(grad[2][c]) <= 1.7976931348623157e308;
      }
    }
  }
  if (!finite)
  {
    return false; // the CPU masks it, with its own bookkeeping
  }
  MESHFREE_UNROLL
  for (int c = 0; c < kComponentGroup; ++c)
  {
    if (c < fc.GroupComponents)
    {
      const long long o = t * C + fc.FirstComponent + c;
      out.Values[o] = v[c];
      if (fc.Gradients)
      {
        out.Gradients[3 * o] = grad[0][c];
        out.Gradients[3 * o + 1] = grad[1][c];
        out.Gradients[3 * o + 2] = grad[2][c];
      }
    }
  }
  out.Neighbors[t] = m;
  out.Conditions[t] = condition;
  return true;
}

} // namespace mls
} // namespace meshfree

#endif
