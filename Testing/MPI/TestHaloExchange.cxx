// SPDX-License-Identifier: BSD-3-Clause
// vtkMeshFreeHalo under MPI: run as `mpiexec -n N TestHaloExchange` (any N >= 1). Every rank builds the same
// global cloud and keeps a piece of it; the halo each rank receives is checked against a brute force over the
// global cloud: every remote point within the radius of the rank's region arrives, nothing farther (beyond the
// box test's margin of 1e-12 relative), coordinates, arrays and global ids intact, owned points first.
// k-nearest: every query's k nearest points of the whole cloud are in the halo, also when a rank holds fewer
// than k points (second round). Empty pieces and a one-point cloud must not hang.
#include "MPITestSupport.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkMPIController.h"
#include "vtkMeshFreeHalo.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <vector>

namespace
{
using mpitest::Check;
using mpitest::Failures;
using mpitest::Rank;

/// The points `ids` of the global cloud as a vtkPolyData with arrays "f" (1 component) and "g" (3), and the
/// global ids as the GlobalIds attribute when `withIds`.
vtkSmartPointer<vtkPolyData> Piece(const std::vector<double>& xyz, const std::vector<vtkIdType>& ids, bool withIds)
{
  auto piece = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> f;
  f->SetName("f");
  vtkNew<vtkDoubleArray> g;
  g->SetName("g");
  g->SetNumberOfComponents(3);
  vtkNew<vtkIdTypeArray> gid;
  gid->SetName("MyIds");
  for (vtkIdType id : ids)
  {
    const double* x = &xyz[3 * id];
    points->InsertNextPoint(x);
    f->InsertNextValue(x[0] + 2 * x[1] + 3 * x[2]);
    g->InsertNextTuple3(id, -x[0], x[2]);
    gid->InsertNextValue(id);
  }
  piece->SetPoints(points);
  piece->GetPointData()->AddArray(f);
  piece->GetPointData()->AddArray(g);
  if (withIds)
  {
    piece->GetPointData()->SetGlobalIds(gid);
  }
  return piece;
}

double SquaredBoxDistance(const double* x, const double b[6])
{
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    const double d = std::max({ b[2 * a] - x[a], 0.0, x[a] - b[2 * a + 1] });
    d2 += d * d;
  }
  return d2;
}

/// Checks the halo's output against the global cloud. Returns the number of halo points.
vtkIdType CheckHalo(vtkMeshFreeHalo* halo, const std::vector<double>& xyz, const std::vector<vtkIdType>& mine,
  const double region[6], double radius, bool shipped)
{
  vtkPolyData* out = halo->GetOutput();
  const vtkIdType owned = halo->GetNumberOfOwnedPoints();
  Check(owned == static_cast<vtkIdType>(mine.size()), "owned point count");
  vtkIdTypeArray* ids = halo->GetGlobalIds();
  Check(ids && ids->GetNumberOfTuples() == out->GetNumberOfPoints(), "global ids present");
  if (!ids)
  {
    return 0;
  }
  auto* ghost = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("vtkGhostType"));
  Check(ghost != nullptr, "vtkGhostType present");
  vtkDataArray* f = out->GetPointData()->GetArray("f");
  vtkDataArray* g = out->GetPointData()->GetArray("g");
  Check(shipped == (f && g), "point arrays shipped as asked");
  std::set<vtkIdType> mineSet(mine.begin(), mine.end());
  std::set<vtkIdType> got;
  double worst = 0.0;
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    const vtkIdType id = ids->GetValue(i);
    double x[3];
    out->GetPoint(i, x);
    const double* truth = &xyz[3 * id];
    Check(x[0] == truth[0] && x[1] == truth[1] && x[2] == truth[2], "coordinates exact", id);
    if (f && g)
    {
      Check(f->GetTuple1(i) == truth[0] + 2 * truth[1] + 3 * truth[2], "array f", id);
      Check(g->GetComponent(i, 0) == id && g->GetComponent(i, 1) == -truth[0], "array g", id);
    }
    if (i < owned)
    {
      Check(id == mine[i], "owned points first, in input order", id);
      Check(ghost && ghost->GetValue(i) == 0, "owned point not a ghost", id);
      continue;
    }
    Check(ghost && ghost->GetValue(i) != 0, "halo point flagged as ghost", id);
    Check(!mineSet.count(id), "halo point is remote", id);
    Check(i == owned || ids->GetValue(i - 1) < id, "halo sorted by global id", id);
    got.insert(id);
    worst = std::max(worst, std::sqrt(SquaredBoxDistance(x, region)) / radius);
  }
  Check(worst <= 1.0 + 1e-12, "no halo point beyond the radius", worst);
  // Brute force: every remote point within the radius of the region.
  vtkIdType expected = 0;
  const bool emptyRegion = !(region[0] <= region[1] && region[2] <= region[3] && region[4] <= region[5]);
  for (vtkIdType id = 0; id < static_cast<vtkIdType>(xyz.size() / 3); ++id)
  {
    if (!emptyRegion && !mineSet.count(id) && SquaredBoxDistance(&xyz[3 * id], region) <= radius * radius)
    {
      ++expected;
      Check(got.count(id) == 1, "remote point within the radius arrived", id);
    }
  }
  Check(expected == static_cast<vtkIdType>(got.size()), "halo size", got.size() - expected);
  return static_cast<vtkIdType>(got.size());
}

/// Every query's k nearest points of the whole cloud (ties included) are in the halo's output.
void CheckKNearest(vtkMeshFreeHalo* halo, const std::vector<double>& xyz, const std::vector<vtkIdType>& queries, int k)
{
  std::set<vtkIdType> have;
  vtkIdTypeArray* ids = halo->GetGlobalIds();
  for (vtkIdType i = 0; i < ids->GetNumberOfTuples(); ++i)
  {
    have.insert(ids->GetValue(i));
  }
  const vtkIdType n = static_cast<vtkIdType>(xyz.size() / 3);
  for (vtkIdType q : queries)
  {
    std::vector<std::pair<double, vtkIdType>> d;
    for (vtkIdType j = 0; j < n; ++j)
    {
      const double dx = xyz[3 * j] - xyz[3 * q], dy = xyz[3 * j + 1] - xyz[3 * q + 1],
                   dz = xyz[3 * j + 2] - xyz[3 * q + 2];
      d.emplace_back(dx * dx + dy * dy + dz * dz, j);
    }
    std::sort(d.begin(), d.end());
    for (int j = 0; j < std::min<vtkIdType>(k, n); ++j)
    {
      Check(have.count(d[j].second) == 1, "k-nearest neighbour in the halo", d[j].second);
    }
  }
}
} // namespace

int main(int argc, char* argv[])
{
  vtkNew<vtkMPIController> controller;
  controller->Initialize(&argc, &argv);
  vtkMultiProcessController::SetGlobalController(controller);
  Rank = controller->GetLocalProcessId();
  const int size = controller->GetNumberOfProcesses();

  // 1. A random cloud split into slabs along x (spatially coherent pieces), global ids given by the input.
  {
    const int n = 4000;
    const std::vector<double> xyz = mpitest::RandomPoints(n, 7);
    std::vector<vtkIdType> mine;
    for (vtkIdType id = 0; id < n; ++id)
    {
      if (std::min(size - 1, static_cast<int>(xyz[3 * id] * size)) == Rank)
      {
        mine.push_back(id);
      }
    }
    vtkSmartPointer<vtkPolyData> piece = Piece(xyz, mine, true);
    double region[6];
    piece->GetBounds(region);
    if (mine.empty())
    {
      region[0] = 1.0, region[1] = 0.0;
    }
    const double radius = 0.05;
    vtkNew<vtkMeshFreeHalo> halo;
    halo->Exchange(piece, region, radius);
    const vtkIdType received = CheckHalo(halo, xyz, mine, region, radius, true);
    Check(halo->GetNumberOfGlobalPoints() == n, "global point count");
    std::printf("slabs, radius %g: rank %d owns %zu of %d points, receives %lld halo points (%.1f %% of the "
                "cloud)\n",
      radius, Rank, mine.size(), n, static_cast<long long>(received), 100.0 * received / n);

    double bounds[6];
    vtkMeshFreeHalo::GlobalBounds(controller, region, bounds);
    double truth[6] = { 1, 0, 1, 0, 1, 0 };
    vtkMeshFreeHalo::FiniteBounds(xyz.data(), n, truth);
    for (int a = 0; a < 6; ++a)
    {
      Check(bounds[a] == truth[a], "global bounds", bounds[a] - truth[a]);
    }
    Check(vtkMeshFreeHalo::GlobalSum(controller, static_cast<vtkIdType>(mine.size())) == n, "global sum");

    // k nearest of the own points, arrays not shipped.
    vtkNew<vtkMeshFreeHalo> knn;
    knn->ShipPointDataOff();
    std::vector<double> queries;
    for (vtkIdType id : mine)
    {
      queries.insert(queries.end(), &xyz[3 * id], &xyz[3 * id] + 3);
    }
    knn->ExchangeForKNearest(piece, queries.data(), static_cast<vtkIdType>(mine.size()), 12);
    double knnRegion[6];
    vtkMeshFreeHalo::FiniteBounds(queries.data(), static_cast<vtkIdType>(mine.size()), knnRegion);
    const vtkIdType knnReceived = CheckHalo(knn, xyz, mine, knnRegion, knn->GetRadius(), false);
    std::printf("slabs, 12 nearest: rank %d radius %g, receives %lld halo points (%.1f %% of the cloud)\n", Rank,
      knn->GetRadius(), static_cast<long long>(knnReceived), 100.0 * knnReceived / n);
    std::vector<vtkIdType> sample;
    for (size_t i = 0; i < mine.size(); i += 37)
    {
      sample.push_back(mine[i]);
    }
    CheckKNearest(knn, xyz, sample, 12);
  }

  // 2. Split by index without global ids (they are generated: the serial index), one rank far from its
  //    neighbours' points: a probe region elsewhere, and an infinite radius (the whole cloud).
  {
    const int n = 1000;
    const std::vector<double> xyz = mpitest::RandomPoints(n, 11);
    std::vector<vtkIdType> mine;
    for (vtkIdType id = Rank * n / size; id < (Rank + 1) * n / size; ++id)
    {
      mine.push_back(id);
    }
    vtkSmartPointer<vtkPolyData> piece = Piece(xyz, mine, false);
    const double region[6] = { 0.1 * Rank, 0.1 * Rank + 0.2, 0.4, 0.5, 0.0, 0.05 };
    vtkNew<vtkMeshFreeHalo> halo;
    halo->Exchange(piece, region, 0.07);
    CheckHalo(halo, xyz, mine, region, 0.07, true);
    vtkNew<vtkMeshFreeHalo> everything;
    everything->Exchange(piece, region, std::numeric_limits<double>::infinity());
    Check(everything->GetOutput()->GetNumberOfPoints() == n, "infinite radius brings the whole cloud");
  }

  // 3. Tiny clouds: fewer points than ranks, one point, none; k larger than the cloud; k-NN second round.
  for (int n : { 5, 1, 0 })
  {
    const std::vector<double> xyz = mpitest::RandomPoints(n, 3);
    std::vector<vtkIdType> mine;
    for (vtkIdType id = Rank * n / size; id < (Rank + 1) * n / size; ++id)
    {
      mine.push_back(id);
    }
    vtkSmartPointer<vtkPolyData> piece = Piece(xyz, mine, false);
    std::vector<double> queries;
    for (vtkIdType id : mine)
    {
      queries.insert(queries.end(), &xyz[3 * id], &xyz[3 * id] + 3);
    }
    for (int k : { 2, 10 })
    {
      vtkNew<vtkMeshFreeHalo> knn;
      knn->ExchangeForKNearest(piece, queries.data(), static_cast<vtkIdType>(mine.size()), k);
      CheckKNearest(knn, xyz, mine, k);
      Check(knn->GetNumberOfOwnedPoints() == static_cast<vtkIdType>(mine.size()), "tiny cloud: owned points");
      if (Rank == 0)
      {
        std::printf("%d point(s), k = %d: %d round(s), rank 0 radius %g, %lld points on rank 0\n", n, k,
          knn->GetNumberOfRounds(), knn->GetRadius(),
          static_cast<long long>(knn->GetOutput()->GetNumberOfPoints()));
      }
    }
  }

  int failed = Failures > 0 ? 1 : 0;
  int anyFailed = failed;
  controller->AllReduce(&failed, &anyFailed, 1, vtkCommunicator::MAX_OP);
  if (Rank == 0)
  {
    std::printf(anyFailed ? "vtkMeshFreeHalo: FAILED\n" : "vtkMeshFreeHalo: every check passed on %d rank(s)\n",
      size);
  }
  controller->Finalize();
  return anyFailed ? 1 : 0;
}
