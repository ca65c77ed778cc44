// SPDX-License-Identifier: BSD-3-Clause
// vtkMeshFreeMLSKernel on a distributed cloud: run as `mpiexec -n N TestMLSKernelDistributed` (any N >= 1). Each
// rank holds a piece of the source cloud (by index) and a piece of the probe points; vtkMeshFreeHalo's
// ExchangeForKNearest brings every source point the kernel's neighbourhoods need, and vtkPointInterpolator with
// the MLS kernel on that halo'd source must give, at every probe point, what the serial run (the whole cloud on
// one rank) gives: the kernel lists its neighbours by distance, so the sums run in the same order and the values
// agree bit for bit (checked to 1e-12 of the range, reported exactly). Also with a rank that holds no source
// point and one that holds no probe point.
#include "MPITestSupport.h"
#include "vtkDoubleArray.h"
#include "vtkMPIController.h"
#include "vtkMeshFreeHalo.h"
#include "vtkMeshFreeMLSKernel.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPointInterpolator.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace
{
using mpitest::Check;
using mpitest::Failures;
using mpitest::RandomPoints;
using mpitest::Rank;

/// Points [begin, end) of xyz as a vtkPolyData, with the field f when `withField`.
vtkSmartPointer<vtkPolyData> Cloud(const std::vector<double>& xyz, vtkIdType begin, vtkIdType end, bool withField)
{
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> f;
  f->SetName("f");
  for (vtkIdType i = begin; i < end; ++i)
  {
    const double* x = &xyz[3 * i];
    points->InsertNextPoint(x);
    f->InsertNextValue(std::sin(3 * x[0]) + x[1] * x[1] + 0.5 * x[2]);
  }
  cloud->SetPoints(points);
  if (withField)
  {
    cloud->GetPointData()->AddArray(f);
  }
  return cloud;
}

/// f at the probe points interpolated from `source` with the MLS kernel.
std::vector<double> Interpolate(vtkPolyData* source, vtkPolyData* probe)
{
  vtkNew<vtkMeshFreeMLSKernel> kernel;
  kernel->SetNeighborCount(20);
  vtkNew<vtkPointInterpolator> interpolator;
  interpolator->SetInputData(probe);
  interpolator->SetSourceData(source);
  interpolator->SetKernel(kernel);
  interpolator->SetNullPointsStrategyToNullValue();
  interpolator->Update();
  vtkDataArray* f = interpolator->GetOutput()->GetPointData()->GetArray("f");
  std::vector<double> values(static_cast<size_t>(probe->GetNumberOfPoints()));
  for (vtkIdType i = 0; f && i < probe->GetNumberOfPoints(); ++i)
  {
    values[i] = f->GetTuple1(i);
  }
  Check(f != nullptr || probe->GetNumberOfPoints() == 0, "interpolated array f");
  return values;
}

/// One case: a cloud of n points and m probes, rank r holding the index share [lo(r), lo(r + 1)) of each, where
/// `skew` moves the source shares so that rank 0 holds none.
void RunCase(vtkMPIController* controller, int n, int m, bool skew)
{
  const int ranks = controller->GetNumberOfProcesses();
  const std::vector<double> cloudXYZ = RandomPoints(n, 7, 0.0, 1.0);
  const std::vector<double> probeXYZ = RandomPoints(m, 11, 0.05, 0.95);
  auto share = [&](int total, int r, bool shifted) {
    if (shifted && ranks > 1)
    {
      return r == 0 ? 0 : static_cast<vtkIdType>(static_cast<long long>(r - 1) * total / (ranks - 1));
    }
    return static_cast<vtkIdType>(static_cast<long long>(r) * total / ranks);
  };
  auto piece = Cloud(cloudXYZ, share(n, Rank, skew), share(n, Rank + 1, skew), true);
  // The last rank gets no probe point.
  const int probeRanks = std::max(1, ranks - 1);
  const vtkIdType p0 = Rank < probeRanks ? static_cast<vtkIdType>(static_cast<long long>(Rank) * m / probeRanks) : m;
  const vtkIdType p1 =
    Rank < probeRanks ? static_cast<vtkIdType>(static_cast<long long>(Rank + 1) * m / probeRanks) : m;
  auto probe = Cloud(probeXYZ, p0, p1, false);

  vtkNew<vtkMeshFreeHalo> halo;
  halo->SetController(controller);
  std::vector<double> queries(probeXYZ.begin() + 3 * p0, probeXYZ.begin() + 3 * p1);
  // The kernel's neighbourhood: max(NeighborCount, 2 per basis term) = 20 for quadratics in 3D.
  Check(halo->ExchangeForKNearest(piece, queries.data(), p1 - p0, 20) == 1, "exchange");
  const std::vector<double> distributed = Interpolate(halo->GetOutput(), probe);

  auto whole = Cloud(cloudXYZ, 0, n, true);
  const std::vector<double> serial = Interpolate(whole, probe);
  double range = 0.0, worst = 0.0;
  for (size_t i = 0; i < serial.size(); ++i)
  {
    range = std::max(range, std::fabs(serial[i]));
    worst = std::max(worst, std::fabs(distributed[i] - serial[i]));
  }
  const double all = vtkMeshFreeHalo::GlobalMax(controller, worst);
  const vtkIdType received = vtkMeshFreeHalo::GlobalSum(controller, halo->GetOutput()->GetNumberOfPoints());
  if (Rank == 0)
  {
    std::printf("cloud %d, probes %d%s, %d rank(s): max |N ranks - serial| = %.3g; %lld halo + owned points\n", n, m,
      skew ? " (rank 0 without source points)" : "", ranks, all, static_cast<long long>(received));
  }
  Check(all <= 1e-12 * std::max(range, 1.0), "MLS kernel on the halo'd source equals serial", all);
}
} // namespace

int main(int argc, char* argv[])
{
  vtkNew<vtkMPIController> controller;
  controller->Initialize(&argc, &argv);
  Rank = controller->GetLocalProcessId();
  RunCase(controller, 4000, 600, false);
  RunCase(controller, 4000, 600, true);
  RunCase(controller, 30, 50, false); // fewer source points than the neighbourhood on each rank
  const int failures = static_cast<int>(vtkMeshFreeHalo::GlobalSum(controller, Failures));
  if (Rank == 0)
  {
    std::printf(failures == 0 ? "OK\n" : "FAILED: %d checks\n", failures);
  }
  controller->Finalize();
  return failures == 0 ? 0 : 1;
}
