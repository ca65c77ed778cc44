#include "vtkMeshFreeMLSKernel.h"

#include "vtkDataSet.h"
#include "vtkDoubleArray.h"
#include "vtkIdList.h"
#include "vtkDataArray.h"
#include "vtkPointData.h"
#include "vtkObjectFactory.h"

#include "Approximation/Approximation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

vtkStandardNewMacro(vtkMeshFreeMLSKernel);

struct vtkMeshFreeMLSKernel::Internals
{
  meshfree::Approximator Approx;
  bool Ready = false;
};

namespace
{
// Per-thread scratch, and the weights of the last ComputeBasis() call of this thread, reused by the
// ComputeWeights() call that follows it for the same point (VTK calls them in pairs).
struct ThreadState
{
  meshfree::FitScratch Scratch;
  std::vector<meshfree::Index> Ids;
  std::vector<double> Dist2;
  std::vector<double> Phi;
  const void* Owner = nullptr;
  double X[3] = { 0, 0, 0 };
  bool Valid = false;
};
thread_local ThreadState State;
}

vtkMeshFreeMLSKernel::vtkMeshFreeMLSKernel()
  : Core(new Internals)
{
}

vtkMeshFreeMLSKernel::~vtkMeshFreeMLSKernel() = default;

void vtkMeshFreeMLSKernel::FreeStructures()
{
  this->Superclass::FreeStructures();
  this->Core->Ready = false;
}

void vtkMeshFreeMLSKernel::Initialize(vtkAbstractPointLocator* loc, vtkDataSet* ds, vtkPointData* pd)
{
  this->Superclass::Initialize(loc, ds, pd);
  this->Core->Ready = false;
  if (!ds)
  {
    vtkErrorMacro("No source data set.");
    return;
  }
  meshfree::ApproximationOptions opts;
  opts.Method = meshfree::ApproximationMethod::MLS;
  opts.Degree = this->BasisDegree;
  opts.Weight = static_cast<meshfree::KernelType>(this->WeightFunction);
  opts.NeighborCount = this->NeighborCount;
  opts.SupportRadius = this->SupportRadius;
  opts.Epsilon = this->Epsilon;
  if (!this->Core->Approx.SetOptions(opts))
  {
    vtkErrorMacro("Invalid settings: " << this->Core->Approx.Error());
    return;
  }
  const vtkIdType n = ds->GetNumberOfPoints();
  std::vector<double> xyz(3 * static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    ds->GetPoint(i, &xyz[3 * i]);
  }
  // vtkPointInterpolator sums weight x value for every source array: a source point with a NaN/Inf value
  // in any of them would make the result NaN, so such points get no weight (as NaN/Inf coordinates).
  vtkIdType badValues = 0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int a = 0; pd && a < pd->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = pd->GetArray(a);
    if (!array || array->GetNumberOfTuples() != n)
    {
      continue;
    }
    const int nc = array->GetNumberOfComponents();
    for (vtkIdType i = 0; i < n; ++i)
    {
      for (int c = 0; c < nc; ++c)
      {
        if (!std::isfinite(array->GetComponent(i, c)))
        {
          badValues += std::isfinite(xyz[3 * i]) ? 1 : 0;
          xyz[3 * i] = xyz[3 * i + 1] = xyz[3 * i + 2] = nan;
          break;
        }
      }
    }
  }
  this->Core->Approx.SetCloud(xyz.data(), n, nullptr, 0);
  if (this->Core->Approx.Report().ExcludedPoints > 0)
  {
    vtkWarningMacro(<< this->Core->Approx.Report().ExcludedPoints
                    << " source points have NaN/Inf coordinates or values (" << badValues
                    << " of them values): they are ignored.");
  }
  this->Core->Ready = this->Core->Approx.PrepareShapeFunctions();
  if (!this->Core->Ready)
  {
    vtkWarningMacro("The source has no valid point: every probe point is a null point.");
  }
  State.Owner = nullptr;
}

vtkIdType vtkMeshFreeMLSKernel::ComputeBasis(double x[3], vtkIdList* pIds, vtkIdType)
{
  pIds->Reset();
  ThreadState& st = State;
  st.Owner = nullptr;
  if (!this->Core->Ready)
  {
    return 0;
  }
  const meshfree::NeighborGrid& grid = this->Core->Approx.Grid();
  if (this->SupportRadius > 0.0)
  {
    grid.FindWithinRadius(x, this->SupportRadius, st.Ids, &st.Dist2);
  }
  else
  {
    // As the MeshlessApproximation filter: at least kMinimumNeighborsPerTerm neighbours per basis term, or
    // each fit nearly interpolates and overshoots between points (cubics in 3D with 20 neighbours).
    const int terms = meshfree::BasisSize(std::max(this->Core->Approx.CloudDimension(), 0), this->BasisDegree);
    grid.FindKNearest(x, std::max(this->NeighborCount, meshfree::kMinimumNeighborsPerTerm * terms), st.Ids, st.Dist2);
  }
  const int n = static_cast<int>(st.Ids.size());
  if (!this->Core->Approx.ShapeFunctionsFor(x, st.Ids.data(), n, st.Phi, st.Scratch))
  {
    return 0; // no support or no fit: the interpolator's null-point strategy applies
  }
  pIds->SetNumberOfIds(n);
  for (int j = 0; j < n; ++j)
  {
    pIds->SetId(j, static_cast<vtkIdType>(st.Ids[j]));
  }
  st.Owner = this;
  st.X[0] = x[0];
  st.X[1] = x[1];
  st.X[2] = x[2];
  return n;
}

vtkIdType vtkMeshFreeMLSKernel::ComputeWeights(double x[3], vtkIdList* pIds, vtkDoubleArray* weights)
{
  const vtkIdType n = pIds->GetNumberOfIds();
  weights->SetNumberOfTuples(n);
  double* w = weights->GetPointer(0);
  ThreadState& st = State;
  const bool cached = st.Owner == this && st.X[0] == x[0] && st.X[1] == x[1] && st.X[2] == x[2] &&
    static_cast<vtkIdType>(st.Phi.size()) == n;
  bool same = cached;
  for (vtkIdType j = 0; same && j < n; ++j)
  {
    same = st.Ids[j] == pIds->GetId(j);
  }
  if (!same)
  {
    st.Ids.resize(n);
    for (vtkIdType j = 0; j < n; ++j)
    {
      st.Ids[j] = pIds->GetId(j);
    }
    if (!this->Core->Ready ||
      !this->Core->Approx.ShapeFunctionsFor(x, st.Ids.data(), static_cast<int>(n), st.Phi, st.Scratch))
    {
      st.Phi.assign(n, 0.0);
    }
  }
  for (vtkIdType j = 0; j < n; ++j)
  {
    w[j] = st.Phi[j];
  }
  return n;
}

void vtkMeshFreeMLSKernel::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "BasisDegree: " << this->BasisDegree << "\n";
  os << indent << "WeightFunction: " << this->WeightFunction << "\n";
  os << indent << "NeighborCount: " << this->NeighborCount << "\n";
  os << indent << "SupportRadius: " << this->SupportRadius << "\n";
  os << indent << "Epsilon: " << this->Epsilon << "\n";
}
