// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMeshFreeHaloDistribution.h"

#include "vtkCommunicator.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkMeshFreeHalo.h"
#include "vtkMeshFreePieces.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>

vtkMeshFreeHaloDistribution::vtkMeshFreeHaloDistribution(
  vtkMultiProcessController* controller, vtkMeshFreeHalo* halo, const double region[6], double radius)
  : Controller(controller)
  , Halo(halo)
  , NumberOfOwned(halo->GetNumberOfOwnedPoints())
  , Radius(radius)
{
  std::copy(region, region + 6, this->Region);
  // The keys are read where the halo holds them (no copy: 8 bytes per held point, issue 24).
  vtkIdTypeArray* ids = halo->GetGlobalIds();
  this->Count = halo->GetOutput()->GetNumberOfPoints();
  this->Ids = ids && ids->GetNumberOfTuples() >= this->Count ? ids->GetPointer(0) : nullptr;
}

vtkMeshFreeHaloDistribution::vtkMeshFreeHaloDistribution(vtkMultiProcessController* controller, vtkIdType n)
  : Controller(controller)
  , Halo(nullptr)
  , NumberOfOwned(n)
  , Radius(0.0)
  , Count(n)
{
  std::fill(this->Region, this->Region + 6, 0.0);
}

double vtkMeshFreeHaloDistribution::Complete(const double x[3]) const
{
  // The radius plus x's depth inside the region, minus its distance to the region when outside.
  double depth = HUGE_VAL, outside = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    const double below = this->Region[2 * a] - x[a], above = x[a] - this->Region[2 * a + 1];
    depth = std::min(depth, -std::max(below, above));
    const double gap = std::max(0.0, std::max(below, above));
    outside += gap * gap;
  }
  return this->Radius + (outside > 0.0 ? -std::sqrt(outside) : std::max(depth, 0.0));
}

void vtkMeshFreeHaloDistribution::Sum(double* values, meshfree::Index count) const
{
  std::vector<double> mine(values, values + count);
  this->Controller->AllReduce(mine.data(), values, count, vtkCommunicator::SUM_OP);
}

void vtkMeshFreeHaloDistribution::Sum(std::int64_t* values, meshfree::Index count) const
{
  std::vector<vtkTypeInt64> mine(values, values + count), all(static_cast<size_t>(count));
  this->Controller->AllReduce(mine.data(), all.data(), count, vtkCommunicator::SUM_OP);
  std::copy(all.begin(), all.end(), values);
}

void vtkMeshFreeHaloDistribution::Max(double* values, meshfree::Index count) const
{
  std::vector<double> mine(values, values + count);
  this->Controller->AllReduce(mine.data(), values, count, vtkCommunicator::MAX_OP);
}

void vtkMeshFreeHaloDistribution::Gather(const std::vector<double>& mine, std::vector<double>& all) const
{
  all = vtkMeshFreePieces::AllGather(this->Controller, mine);
}

void vtkMeshFreeHaloDistribution::UpdateHalo(double* values, int components) const
{
  if (!this->Halo)
  {
    return;
  }
  vtkNew<vtkDoubleArray> array;
  array->SetNumberOfComponents(components);
  array->SetArray(values, this->Count * components, 1); // 1: not freed by the array
  this->Halo->UpdateHalo(array);
}

int vtkMeshFreeHaloDistribution::Rank() const
{
  return this->Controller ? this->Controller->GetLocalProcessId() : 0;
}

int vtkMeshFreeHaloDistribution::Size() const
{
  return this->Controller ? this->Controller->GetNumberOfProcesses() : 1;
}

void vtkMeshFreeHaloDistribution::SetSlab(int axis, double lower, double upper)
{
  this->SlabAxis = axis;
  this->SlabLower = lower;
  this->SlabUpper = upper;
}

bool vtkMeshFreeHaloDistribution::OwnsPosition(const double x[3]) const
{
  return this->SlabAxis < 0 || (this->SlabLower <= x[this->SlabAxis] && x[this->SlabAxis] < this->SlabUpper);
}

bool vtkMeshFreeHaloDistribution::OwnsBall(const double x[3], double radius) const
{
  return this->SlabAxis < 0 ||
    (this->SlabLower <= x[this->SlabAxis] - radius && x[this->SlabAxis] + radius < this->SlabUpper);
}
