// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMeshFreeSlabs.h"

#include "vtkDoubleArray.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkMeshFreeHalo.h"
#include "vtkMeshFreeHaloDistribution.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>

namespace vtkMeshFreeSlabs
{

int Partition::Slab(double c) const
{
  return static_cast<int>(std::upper_bound(this->Cuts.begin(), this->Cuts.end(), c) - this->Cuts.begin());
}

double Partition::Lower(int r) const
{
  return r == 0 ? -HUGE_VAL : this->Cuts[r - 1];
}

double Partition::Upper(int r) const
{
  return r == static_cast<int>(this->Cuts.size()) ? HUGE_VAL : this->Cuts[r];
}

void Partition::Region(int r, double region[6]) const
{
  std::copy(this->Bounds, this->Bounds + 6, region);
  region[2 * this->Axis] = std::max(this->Bounds[2 * this->Axis], this->Lower(r));
  region[2 * this->Axis + 1] = std::min(this->Bounds[2 * this->Axis + 1], this->Upper(r));
}

Partition Choose(vtkMultiProcessController* controller, const double* xyz, vtkIdType n)
{
  Partition slabs;
  double local[6];
  vtkMeshFreeHalo::FiniteBounds(xyz, n, local);
  vtkMeshFreeHalo::GlobalBounds(controller, local, slabs.Bounds);
  for (int a = 1; a < 3; ++a)
  {
    const double extent = slabs.Bounds[2 * a + 1] - slabs.Bounds[2 * a];
    slabs.Axis = extent > slabs.Bounds[2 * slabs.Axis + 1] - slabs.Bounds[2 * slabs.Axis] ? a : slabs.Axis;
  }
  std::vector<double> coordinates;
  for (vtkIdType i = 0; i < n; ++i)
  {
    const double* x = xyz + 3 * i;
    if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]))
    {
      coordinates.push_back(x[slabs.Axis]);
    }
  }
  vtkMeshFreeHaloDistribution processes(controller, n);
  slabs.Points = meshfree::GlobalSum(&processes, static_cast<meshfree::Index>(coordinates.size()));
  const int size = controller ? controller->GetNumberOfProcesses() : 1;
  for (int r = 1; r < size; ++r)
  {
    slabs.Cuts.push_back(slabs.Points > 0
        ? meshfree::GlobalSelect(&processes, coordinates, slabs.Points * r / size)
        : slabs.Bounds[2 * slabs.Axis]);
  }
  return slabs;
}

vtkSmartPointer<vtkPolyData> Move(vtkMultiProcessController* controller, vtkPolyData* piece, const Partition& slabs)
{
  const int me = controller ? controller->GetLocalProcessId() : 0;
  double region[6];
  slabs.Region(me, region);
  if (slabs.Points == 0 || region[2 * slabs.Axis] > region[2 * slabs.Axis + 1])
  {
    for (int a = 0; a < 3; ++a)
    {
      region[2 * a] = 1.0; // an empty box asks for nothing
      region[2 * a + 1] = 0.0;
    }
  }
  vtkNew<vtkMeshFreeHalo> halo;
  halo->SetController(controller);
  halo->Exchange(piece, region, 0.0);
  vtkPolyData* both = halo->GetOutput();
  // Keep the points of this slab (the exchange brought the slab's box, cuts included, and kept the whole piece).
  vtkNew<vtkIdList> kept;
  const vtkIdType m = both->GetNumberOfPoints();
  for (vtkIdType i = 0; i < m; ++i)
  {
    double x[3];
    both->GetPoint(i, x);
    if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]) && slabs.Slab(x[slabs.Axis]) == me)
    {
      kept->InsertNextId(i);
    }
  }
  auto mine = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(kept->GetNumberOfIds());
  for (vtkIdType j = 0; j < kept->GetNumberOfIds(); ++j)
  {
    points->SetPoint(j, both->GetPoint(kept->GetId(j)));
  }
  mine->SetPoints(points);
  vtkPointData* from = both->GetPointData();
  vtkPointData* to = mine->GetPointData();
  for (int a = 0; a < from->GetNumberOfArrays(); ++a)
  {
    vtkAbstractArray* array = from->GetAbstractArray(a);
    if (!array->GetName() || std::string(array->GetName()) == "vtkGhostType")
    {
      continue;
    }
    vtkSmartPointer<vtkAbstractArray> part = vtkSmartPointer<vtkAbstractArray>::Take(array->NewInstance());
    part->SetName(array->GetName());
    part->SetNumberOfComponents(array->GetNumberOfComponents());
    part->SetNumberOfTuples(kept->GetNumberOfIds());
    array->GetTuples(kept, part);
    to->AddArray(part);
    if (array == from->GetGlobalIds())
    {
      to->SetGlobalIds(vtkDataArray::SafeDownCast(part));
    }
  }
  return mine;
}

} // namespace vtkMeshFreeSlabs
