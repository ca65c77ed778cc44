// The plain views the device MLS point code (Approximation/MLSDevicePoint.h) reads, built on the host from an
// Approximator's grid, frame and options, so that tests can run that MESHFREE_HD code on the CPU: its k-nearest
// search and per-point fits (TestMLSDevicePoint), and which points the device must hand back (Cuda/CudaMLSParity).
#ifndef meshfree_MLSHostViews_h
#define meshfree_MLSHostViews_h

#include "Approximation/Approximation.h"
#include "Approximation/MLSDevicePoint.h"

#include <algorithm>
#include <vector>

namespace meshfree
{
namespace testing
{

/// The grid's cloud in sorted order (ids, values), as the device gets it.
struct HostViews
{
  std::vector<int> Ids;
  std::vector<double> Values;
  mls::CloudView Cloud{};
};

inline void MakeHostViews(const NeighborGrid& grid, const std::vector<double>& values, int components, HostViews& v)
{
  const Index nv = grid.NumberOfValidPoints();
  v.Ids.resize(nv);
  v.Values.resize(nv * components);
  for (Index p = 0; p < nv; ++p)
  {
    const Index id = grid.SortedOrder()[p];
    v.Ids[p] = static_cast<int>(id);
    for (int c = 0; c < components; ++c)
    {
      v.Values[p * components + c] = values[id * components + c];
    }
  }
  v.Cloud.Points = grid.SortedPoints();
  v.Cloud.Ids = v.Ids.data();
  v.Cloud.Values = v.Values.data();
  v.Cloud.Cells = reinterpret_cast<const long long*>(grid.Cells());
  Index dims[3];
  grid.GetGridDimensions(dims);
  double bounds[6];
  grid.GetBounds(bounds);
  for (int a = 0; a < 3; ++a)
  {
    v.Cloud.Dims[a] = dims[a];
    v.Cloud.Origin[a] = bounds[2 * a];
  }
  v.Cloud.Size = grid.CellSize();
  v.Cloud.InvSize = 1.0 / grid.CellSize();
  v.Cloud.Components = components;
}

/// The fit constants of the Approximator `a` set up with options `o` (degree `o.Degree` in dimension `dim`).
inline mls::FitConstants MakeFitConstants(const Approximator& a, const ApproximationOptions& o, int dim)
{
  mls::FitConstants fc{};
  fc.K = std::max(o.NeighborCount, kMinimumNeighborsPerTerm * BasisSize(dim, o.Degree));
  fc.SupportFactor = o.SupportFactor;
  fc.WeightKind = static_cast<int>(o.Weight);
  fc.WeightNormalization = Kernel(o.Weight, dim, 1.0).NormalizationFactor();
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      fc.Axes[r][c] = a.Frame3().Axes[r][c];
    }
  }
  fc.Gradients = o.ComputeGradients ? 1 : 0;
  return fc;
}

/// Runs the device's per-point code on the host for the m probes q (3 each), component group by group as the kernel
/// does, into `out`; out.NeedsCPU[t] is set to 1 where it refused point t (the points the device hands back) and
/// left as it was elsewhere.
template <int D, int M>
void RunHostPoints(const mls::CloudView& cloud, mls::FitConstants fc, const double* q, int m, const mls::OutputView& out)
{
  for (int c0 = 0; c0 < cloud.Components; c0 += mls::kComponentGroup)
  {
    fc.FirstComponent = c0;
    fc.GroupComponents = std::min(mls::kComponentGroup, cloud.Components - c0);
    for (int t = 0; t < m; ++t)
    {
      if (!mls::MLSFast<D, M>(cloud, fc, &q[3 * t], t, out))
      {
        out.NeedsCPU[t] = 1;
      }
    }
  }
}

} // namespace testing
} // namespace meshfree

#endif
