#include "vtkMeshFreeDeformableSolid.h"

#include "vtkCellArray.h"
#include "vtkCompositeDataSet.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "vtkMeshFreePieces.h"
#include "Elastic/ElasticShapes.h"
#include "Elastic/ElasticSolid.h"
#include "Common/StateCache.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <utility>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMeshFreeDeformableSolid);

struct vtkMeshFreeDeformableSolid::Internals
{
  meshfree::ElasticSolid Solid;
  meshfree::ElasticSurface Surface;
  std::vector<double> SurfacePoints; // rest positions of the surface vertices
  std::vector<meshfree::Index> Triangles;
  // The input surface gathered from every rank in canonical form (distinct points sorted, triangles sorted):
  // what the model is built from, so that it does not depend on how the input was split.
  std::vector<double> InputPoints;
  std::vector<meshfree::Index> InputTriangles;
  vtkIdType InputNonFinite = 0;     // points with a NaN/Inf coordinate, over all ranks
  std::vector<vtkIdType> LocalToInput; // this rank's input points -> InputPoints
  std::vector<vtkIdType> LocalTriangles; // this rank's input polygons, fan-triangulated (local point ids)
  meshfree::StateCache<meshfree::ElasticState> Cache{ 16 };
  vtkTimeStamp BuildTime;
  bool Valid = false;    // the model was built without error
  bool BuiltWithInput = false;
  bool Unstable = false; // the simulation blew up: later steps repeat the last finite state
};

vtkMeshFreeDeformableSolid::vtkMeshFreeDeformableSolid()
  : Impl(new Internals)
{
  this->SetNumberOfInputPorts(1);
}

vtkMeshFreeDeformableSolid::~vtkMeshFreeDeformableSolid() = default;

int vtkMeshFreeDeformableSolid::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

namespace
{
bool Finite(const std::vector<double>& values)
{
  for (double v : values)
  {
    if (!std::isfinite(v))
    {
      return false;
    }
  }
  return true;
}

vtkSmartPointer<vtkDoubleArray> MakeArray(const char* name, int components, vtkIdType tuples, const double* data)
{
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name);
  array->SetNumberOfComponents(components);
  array->SetNumberOfTuples(tuples);
  std::copy(data, data + components * tuples, array->GetPointer(0));
  return array;
}
/// The local input surface: its points and its polygons fan-triangulated.
void LocalSurface(vtkPolyData* input, std::vector<double>& points, std::vector<vtkIdType>& triangles)
{
  points.clear();
  triangles.clear();
  if (!input)
  {
    return;
  }
  points.resize(3 * static_cast<size_t>(input->GetNumberOfPoints()));
  for (vtkIdType p = 0; p < input->GetNumberOfPoints(); ++p)
  {
    input->GetPoint(p, &points[3 * p]);
  }
  const vtkIdType* ids = nullptr;
  vtkIdType count = 0;
  vtkCellArray* polys = input->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(count, ids);)
  {
    for (vtkIdType t = 1; t + 1 < count; ++t) // fan triangulation of polygons
    {
      triangles.insert(triangles.end(), { ids[0], ids[t], ids[t + 1] });
    }
  }
}

/// Polydata of the deformed surface: output point k is vertex pointIndex[k] of the model's surface.
vtkSmartPointer<vtkPolyData> SurfaceBlock(const std::vector<double>& deformed, const std::vector<double>& displacement,
  const std::vector<double>& normals, const std::vector<vtkIdType>& pointIndex, const std::vector<vtkIdType>& triangles)
{
  const vtkIdType nv = static_cast<vtkIdType>(pointIndex.size());
  std::vector<double> x(3 * nv), d(3 * nv), nn(3 * nv);
  for (vtkIdType k = 0; k < nv; ++k)
  {
    for (int a = 0; a < 3; ++a)
    {
      x[3 * k + a] = deformed[3 * pointIndex[k] + a];
      d[3 * k + a] = displacement[3 * pointIndex[k] + a];
      nn[3 * k + a] = normals[3 * pointIndex[k] + a];
    }
  }
  auto surface = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> sp;
  sp->SetDataTypeToDouble();
  sp->SetNumberOfPoints(nv);
  std::copy(x.begin(), x.end(), static_cast<double*>(sp->GetVoidPointer(0)));
  surface->SetPoints(sp);
  const vtkIdType nt = static_cast<vtkIdType>(triangles.size() / 3);
  vtkNew<vtkIdTypeArray> toff, tconn;
  toff->SetNumberOfTuples(nt + 1);
  tconn->SetNumberOfTuples(3 * nt);
  for (vtkIdType t = 0; t <= nt; ++t)
  {
    toff->SetValue(t, 3 * t);
  }
  std::copy(triangles.begin(), triangles.end(), tconn->GetPointer(0));
  vtkNew<vtkCellArray> tris;
  tris->SetData(toff, tconn);
  surface->SetPolys(tris);
  surface->GetPointData()->AddArray(MakeArray("Displacement", 3, nv, d.data()));
  surface->GetPointData()->SetNormals(MakeArray("Normals", 3, nv, nn.data()));
  return surface;
}
} // namespace

void vtkMeshFreeDeformableSolid::GatherInputSurface(vtkPolyData* input, bool distributed)
{
  Internals& impl = *this->Impl;
  std::vector<double> points;
  LocalSurface(input, points, impl.LocalTriangles);
  // Gathered: the points of every rank, and the triangles in the gathered points' numbering.
  vtkIdType offset = 0;
  const std::vector<double> allPoints = vtkMeshFreePieces::AllGather(points, distributed, &offset);
  offset /= 3;
  std::vector<double> local(impl.LocalTriangles.begin(), impl.LocalTriangles.end());
  for (double& id : local)
  {
    id += static_cast<double>(offset);
  }
  const std::vector<double> allTriangles = vtkMeshFreePieces::AllGather(local, distributed);
  impl.InputNonFinite = 0;
  double scale = 0.0;
  for (size_t p = 0; p < allPoints.size(); p += 3)
  {
    const bool finite =
      std::isfinite(allPoints[p]) && std::isfinite(allPoints[p + 1]) && std::isfinite(allPoints[p + 2]);
    impl.InputNonFinite += finite ? 0 : 1;
    for (int a = 0; finite && a < 3; ++a)
    {
      scale = std::max(scale, std::fabs(allPoints[p + a]));
    }
  }
  impl.InputPoints.clear();
  impl.InputTriangles.clear();
  impl.LocalToInput.clear();
  if (impl.InputNonFinite > 0)
  {
    return; // BuildModel reports it
  }
  // Points that pieces share may come from their sources a rounding error apart: merged within 1e-12 of the
  // coordinates' magnitude (float coordinates are 1e-7 apart at least, so distinct points stay distinct).
  std::vector<vtkIdType> merged;
  impl.InputPoints = vtkMeshFreePieces::MergePoints(allPoints, 1e-12 * scale, merged);
  std::vector<std::array<meshfree::Index, 3>> triangles(allTriangles.size() / 3);
  for (size_t t = 0; t < triangles.size(); ++t)
  {
    for (int k = 0; k < 3; ++k)
    {
      triangles[t][k] = merged[static_cast<vtkIdType>(allTriangles[3 * t + k])];
    }
    // Start at the smallest index, keeping the orientation.
    std::rotate(triangles[t].begin(), std::min_element(triangles[t].begin(), triangles[t].end()), triangles[t].end());
  }
  std::sort(triangles.begin(), triangles.end());
  triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
  for (const auto& triangle : triangles)
  {
    impl.InputTriangles.insert(impl.InputTriangles.end(), triangle.begin(), triangle.end());
  }
  const vtkIdType localPoints = static_cast<vtkIdType>(points.size() / 3);
  impl.LocalToInput.assign(merged.begin() + offset, merged.begin() + offset + localPoints);
}

void vtkMeshFreeDeformableSolid::ReportInputWithoutPort(vtkObject* surface)
{
  if (surface)
  {
    vtkErrorMacro("MLS Deformable Solid (pvpython MLSDeformableSolid) is a pure source and takes no input: this Input "
                  "is ignored and the built-in Shape is used. To fill a closed surface use MLS Deformable Solid From "
                  "Surface: MLSDeformableSolidFromSurface(Input=surface, ...) in pvpython, Filters > MeshFree in "
                  "the GUI.");
  }
}

int vtkMeshFreeDeformableSolid::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const std::vector<double> times = meshfree::OutputTimes(this->EndTime, this->OutputInterval);
  outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
  const double range[2] = { times.front(), times.back() };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  // Every rank simulates the whole solid and outputs its share of the phyxels (see RequestData).
  outInfo->Set(vtkAlgorithm::CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

int vtkMeshFreeDeformableSolid::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkMeshFreePieces::RequestInput(outputVector->GetInformationObject(0), inputVector[0]->GetInformationObject(0));
  return 1;
}

bool vtkMeshFreeDeformableSolid::BuildModel(bool fromInput)
{
  Internals& impl = *this->Impl;
  impl.Valid = false;
  impl.Unstable = false;
  impl.Cache.Clear();
  impl.Cache.SetCapacity(static_cast<size_t>(this->CacheSize));
  impl.SurfacePoints.clear();
  impl.Triangles.clear();
  this->NumberOfPhyxels = 0;
  this->StableTimeStep = 0.0;

  if (!(this->PhyxelSpacing > 0.0) || !std::isfinite(this->PhyxelSpacing))
  {
    vtkErrorMacro("PhyxelSpacing must be a positive number, not " << this->PhyxelSpacing << ".");
    return false;
  }
  if (!(this->OutputInterval > 0.0) || !(this->EndTime >= 0.0) || !std::isfinite(this->OutputInterval) ||
    !std::isfinite(this->EndTime))
  {
    vtkErrorMacro("OutputInterval must be positive and EndTime non-negative, both finite (got "
      << this->OutputInterval << ", " << this->EndTime << ").");
    return false;
  }
  // Finite and not inverted; flat boxes are allowed when `flat` is (a zero-thickness Box shape gives a
  // coplanar plate of phyxels).
  const auto validBox = [](const double* b, bool flat) {
    for (int a = 0; a < 3; ++a)
    {
      if (!std::isfinite(b[2 * a]) || !std::isfinite(b[2 * a + 1]) ||
        !(flat ? b[2 * a] <= b[2 * a + 1] : b[2 * a] < b[2 * a + 1]))
      {
        return false;
      }
    }
    return true;
  };
  if (this->Container != NO_CONTAINER && !validBox(this->ContainerBounds, false))
  {
    vtkErrorMacro("ContainerBounds must be finite with x0 < x1, y0 < y1, z0 < z1 when Container is not None.");
    return false;
  }

  // Phyxels and surface: the input's closed surface, or a built-in shape.
  std::vector<double> rest;
  double volume = 0.0;
  const auto tooMany = static_cast<meshfree::Index>(5e7);
  if (fromInput && impl.InputNonFinite == 0 && impl.InputPoints.empty())
  {
    vtkErrorMacro("The input surface is empty: connect a closed surface, or no input to use Shape.");
    return false;
  }
  if (fromInput)
  {
    if (impl.InputNonFinite > 0)
    {
      vtkErrorMacro("The input surface has " << impl.InputNonFinite << " points with NaN/Inf coordinates.");
      return false;
    }
    impl.SurfacePoints = impl.InputPoints;
    impl.Triangles = impl.InputTriangles;
    // Closed: every edge is shared by exactly two triangles (in opposite directions for a consistent
    // orientation; the count alone catches holes and open sheets).
    std::vector<std::pair<vtkIdType, vtkIdType>> edges;
    edges.reserve(impl.Triangles.size());
    for (size_t t = 0; t + 2 < impl.Triangles.size(); t += 3)
    {
      for (int e = 0; e < 3; ++e)
      {
        const vtkIdType a = impl.Triangles[t + e], b = impl.Triangles[t + (e + 1) % 3];
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
    std::sort(edges.begin(), edges.end());
    size_t boundary = 0;
    for (size_t e = 0; e < edges.size();)
    {
      size_t f = e;
      while (f < edges.size() && edges[f] == edges[e])
      {
        ++f;
      }
      boundary += (f - e == 2) ? 0 : 1;
      e = f;
    }
    if (boundary > 0)
    {
      vtkErrorMacro("The input must be a closed surface made of polygons: " << boundary
                                                                            << " edges are not shared by exactly two polygons.");
      impl.SurfacePoints.clear();
      impl.Triangles.clear();
      return false;
    }
    volume = std::fabs(meshfree::MeshVolume(impl.SurfacePoints, impl.Triangles));
    if (impl.Triangles.empty() || !(volume > 0.0))
    {
      vtkErrorMacro("The input must be a closed surface made of polygons (it encloses no volume).");
      impl.SurfacePoints.clear();
      impl.Triangles.clear();
      return false;
    }
    double b[6] = { VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };
    for (meshfree::Index v : impl.Triangles) // the bounds of the polygons, as vtkPolyData::GetBounds
    {
      for (int a = 0; a < 3; ++a)
      {
        b[2 * a] = std::min(b[2 * a], impl.SurfacePoints[3 * v + a]);
        b[2 * a + 1] = std::max(b[2 * a + 1], impl.SurfacePoints[3 * v + a]);
      }
    }
    std::vector<double> lattice;
    if (!meshfree::SampleLattice(b, this->PhyxelSpacing, [](const double*) { return true; }, lattice, tooMany))
    {
      vtkErrorMacro("PhyxelSpacing " << this->PhyxelSpacing << " is too small for the input's size.");
      return false;
    }
    std::vector<char> inside;
    meshfree::InsideMesh(impl.SurfacePoints, impl.Triangles, lattice, inside);
    for (size_t q = 0; q < inside.size(); ++q)
    {
      if (inside[q])
      {
        rest.insert(rest.end(), &lattice[3 * q], &lattice[3 * q] + 3);
      }
    }
  }
  else
  {
    const auto shape = static_cast<meshfree::ElasticShape>(this->Shape);
    const double* b = this->ShapeBounds;
    if (!validBox(b, true))
    {
      vtkErrorMacro("ShapeBounds must be finite with x0 <= x1, y0 <= y1, z0 <= z1.");
      return false;
    }
    if (!meshfree::SampleLattice(b, this->PhyxelSpacing,
          [shape, b](const double* p) { return meshfree::InsideShape(shape, b, p); }, rest, tooMany))
    {
      vtkErrorMacro("PhyxelSpacing " << this->PhyxelSpacing << " is too small for ShapeBounds.");
      return false;
    }
    volume = meshfree::ShapeVolume(shape, b);
    if (volume > 0.0)
    {
      meshfree::ShapeSurface(shape, b, this->SurfaceResolution, impl.SurfacePoints, impl.Triangles);
    }
  }
  if (rest.empty())
  {
    vtkErrorMacro("No phyxels: no lattice point of spacing " << this->PhyxelSpacing
                                                           << " lies inside the shape. Reduce PhyxelSpacing.");
    impl.SurfacePoints.clear();
    impl.Triangles.clear();
    return false;
  }

  meshfree::ElasticSettings s;
  s.YoungModulus = this->YoungModulus;
  s.PoissonRatio = this->PoissonRatio;
  s.Density = this->Density;
  s.VolumeStiffness = this->VolumeStiffness;
  s.NeighborCount = this->NeighborCount;
  s.SupportScale = this->SupportScale;
  s.Kernel = static_cast<meshfree::KernelType>(this->WeightFunction);
  s.GradientBasis = this->GradientBasis;
  s.HourglassStiffness = this->HourglassStiffness;
  s.PlasticYield = this->PlasticYield;
  s.PlasticCreep = this->PlasticCreep;
  s.PlasticMaxStrain = this->PlasticMaxStrain;
  s.Damping = this->Damping;
  s.Restitution = this->Restitution;
  s.Friction = this->Friction;
  s.Contacts = this->SelfContact != 0;
  s.Container = static_cast<meshfree::ElasticContainer>(this->Container);
  for (int a = 0; a < 6; ++a)
  {
    s.ContainerBounds[a] = this->ContainerBounds[a];
    s.FixedBounds[a] = this->FixedBounds[a];
  }
  for (int a = 0; a < 3; ++a)
  {
    s.Gravity[a] = std::isfinite(this->Gravity[a]) ? this->Gravity[a] : 0.0;
  }
  std::string message;
  if (!impl.Solid.Initialize(rest, volume, s, message))
  {
    vtkErrorMacro("" << message);
    impl.SurfacePoints.clear();
    impl.Triangles.clear();
    return false;
  }
  if (!message.empty())
  {
    vtkWarningMacro("" << message);
  }
  double v0[3];
  for (int a = 0; a < 3; ++a)
  {
    v0[a] = std::isfinite(this->InitialVelocity[a]) ? this->InitialVelocity[a] : 0.0;
  }
  impl.Solid.Reset(v0);
  if (!impl.Triangles.empty())
  {
    impl.Surface.Bind(impl.Solid, impl.SurfacePoints);
  }
  this->NumberOfPhyxels = static_cast<int>(impl.Solid.Size());
  this->StableTimeStep = impl.Solid.StableTimeStep();
  if (!(this->TimeStep >= 0.0) || !std::isfinite(this->TimeStep))
  {
    vtkWarningMacro("TimeStep " << this->TimeStep
                                << " is not a non-negative finite number: the automatic step is used (as for 0).");
  }
  else if (this->Integrator == SYMPLECTIC_EULER && this->TimeStep > this->StableTimeStep)
  {
    vtkWarningMacro("TimeStep " << this->TimeStep << " s exceeds the stable symplectic Euler step "
                                << this->StableTimeStep
                                << " s of this material and sampling: each step is split into "
                                << std::ceil(this->TimeStep / this->StableTimeStep)
                                << " sub-steps. Use the Implicit integrator for larger steps.");
  }
  impl.Cache.Insert(0, impl.Solid.State());
  impl.Valid = true;
  return true;
}

int vtkMeshFreeDeformableSolid::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  Internals& impl = *this->Impl;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkMultiBlockDataSet* output = vtkMultiBlockDataSet::GetData(outputVector);
  // The input surface, whole on every rank: under MPI each rank holds a piece (collective: every rank gathers,
  // also with an empty piece). The model is rebuilt when the gathered surface changes, a decision that is the same
  // on every rank.
  const bool hasInput = this->GetNumberOfInputConnections(0) > 0;
  const std::vector<double> inputPoints = std::move(impl.InputPoints);
  const std::vector<meshfree::Index> inputTriangles = std::move(impl.InputTriangles);
  const vtkIdType inputNonFinite = impl.InputNonFinite;
  this->GatherInputSurface(hasInput ? vtkPolyData::GetData(inputVector[0], 0) : nullptr,
    hasInput && vtkMeshFreePieces::IsDistributed(outInfo));
  if (this->GetMTime() > impl.BuildTime || hasInput != impl.BuiltWithInput || inputPoints != impl.InputPoints ||
    inputTriangles != impl.InputTriangles || inputNonFinite != impl.InputNonFinite)
  {
    this->BuildModel(hasInput);
    impl.BuiltWithInput = hasInput;
    impl.BuildTime.Modified();
  }
  this->SimulatedSteps = 0;

  // The requested time: a reported time (checkpointed), or a time between two of them, simulated from the
  // reported time before it and not checkpointed (meshfree::PlaceRequestedTime).
  const std::vector<double> times = meshfree::OutputTimes(this->EndTime, this->OutputInterval);
  long step = 0;
  const double target = meshfree::PlaceRequestedTime(times,
    outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
      ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
      : 0.0,
    step);
  const bool between = target != times[step];
  output->SetNumberOfBlocks(impl.SurfacePoints.empty() ? 1 : 2);
  vtkNew<vtkPolyData> phyxels;
  output->SetBlock(0, phyxels);
  output->GetMetaData(0u)->Set(vtkCompositeDataSet::NAME(), "Phyxels");
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), target);
  if (!impl.Valid)
  {
    return 1; // the error was reported by BuildModel; an empty "Phyxels" block is the defined result
  }

  // Restore the nearest checkpoint at or before the requested step and simulate forward, checkpointing.
  long found = 0;
  const meshfree::ElasticState* start = impl.Cache.FindAtOrBefore(step, found);
  if (!start)
  {
    vtkErrorMacro("Internal error: the state cache lost its initial state.");
    return 0;
  }
  impl.Solid.State() = *start;
  const bool implicit = this->Integrator == IMPLICIT;
  double maxStep = this->TimeStep > 0.0 && std::isfinite(this->TimeStep) ? this->TimeStep : 0.0;
  if (implicit && !(maxStep > 0.0))
  {
    maxStep = 20.0 * impl.Solid.StableTimeStep();
  }
  const long last = between ? step + 1 : step; // s = step + 1 stands for the partial interval
  const long total = last - found;
  const long unconvergedBefore = impl.Solid.UnconvergedCGSteps();
  const long stepsBefore = impl.Solid.StepsTaken();
  for (long s = found + 1; s <= last; ++s)
  {
    const bool partial = s > step;
    const double from = times[s - 1], to = partial ? target : times[s];
    bool aborted = false;
    auto abort = [this, &aborted]() { return aborted = (this->GetAbortExecute() != 0); };
    const meshfree::ElasticState previous = impl.Solid.State();
    if (!impl.Unstable)
    {
      impl.Solid.Advance(to - from, maxStep, implicit, abort);
    }
    if (aborted)
    {
      impl.Solid.State() = previous;
      output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), from);
      break;
    }
    if (impl.Unstable || !Finite(impl.Solid.State().Position) || !Finite(impl.Solid.State().Velocity))
    {
      if (!impl.Unstable)
      {
        vtkErrorMacro("The simulation became unstable between t = " << from << " and " << to
                                                                    << " s; later times repeat the last finite "
                                                                       "state. Reduce TimeStep or stiffness.");
      }
      if (!partial) // a partial interval is not checkpointed, so it does not mark the later times
      {
        impl.Unstable = true;
      }
      impl.Solid.State() = previous;
    }
    impl.Solid.State().Time = to;
    if (!partial)
    {
      impl.Cache.Insert(s, impl.Solid.State());
    }
    ++this->SimulatedSteps;
    this->UpdateProgress(static_cast<double>(s - found) / static_cast<double>(std::max(1L, total)));
  }
  this->ConjugateGradientIterations = static_cast<int>(impl.Solid.CGIterations());
  if (impl.Solid.UnconvergedCGSteps() > unconvergedBefore)
  {
    vtkWarningMacro("Implicit integrator: the conjugate gradient stopped at its iteration cap before reaching "
                    "its tolerance on "
      << impl.Solid.UnconvergedCGSteps() - unconvergedBefore << " of " << impl.Solid.StepsTaken() - stepsBefore
      << " steps (relative residual up to " << impl.Solid.WorstCGResidual()
      << "): those steps are approximate. A smaller TimeStep converges in fewer iterations.");
  }

  // Phyxels block: positions and the fields of this state (strain and stress computed here only).
  // Under MPI every rank holds the same state and outputs its share of the phyxels, so each is on one rank.
  const meshfree::ElasticSolid& solid = impl.Solid;
  const meshfree::ElasticState& state = solid.State();
  const vtkMeshFreePieces::Range share =
    vtkMeshFreePieces::OutputShare(outInfo, static_cast<vtkIdType>(solid.Size()));
  const vtkIdType n = share.Size();
  const vtkIdType first = share.Begin;
  std::vector<double> F, strain, stress, det;
  solid.ComputeDeformation(F, strain, stress, det);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  std::copy_n(state.Position.begin() + 3 * first, 3 * n, static_cast<double*>(points->GetVoidPointer(0)));
  phyxels->SetPoints(points);
  vtkNew<vtkCellArray> verts;
  vtkNew<vtkIdTypeArray> offsets, connectivity;
  offsets->SetNumberOfTuples(n + 1);
  connectivity->SetNumberOfTuples(n);
  std::vector<double> displacement(3 * n), vonMises(n);
  vtkNew<vtkIdTypeArray> id;
  id->SetName("Id");
  id->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    const vtkIdType s = first + i;
    offsets->SetValue(i, i);
    connectivity->SetValue(i, i);
    id->SetValue(i, s);
    for (int a = 0; a < 3; ++a)
    {
      displacement[3 * i + a] = state.Position[3 * s + a] - solid.RestPositions()[3 * s + a];
    }
    vonMises[i] = meshfree::VonMisesStress(&stress[6 * s]);
  }
  offsets->SetValue(n, n);
  verts->SetData(offsets, connectivity);
  phyxels->SetVerts(verts);
  vtkPointData* pd = phyxels->GetPointData();
  pd->AddArray(MakeArray("Displacement", 3, n, displacement.data()));
  pd->AddArray(MakeArray("Velocity", 3, n, state.Velocity.data() + 3 * first));
  pd->AddArray(MakeArray("Strain", 6, n, strain.data() + 6 * first));
  pd->AddArray(MakeArray("Stress", 6, n, stress.data() + 6 * first));
  pd->AddArray(MakeArray("VonMises", 1, n, vonMises.data()));
  pd->AddArray(MakeArray("DetJ", 1, n, det.data() + first));
  pd->AddArray(MakeArray("Mass", 1, n, solid.Masses().data() + first));
  pd->AddArray(MakeArray("Volume", 1, n, solid.Volumes().data() + first));
  pd->AddArray(id);
  pd->SetActiveScalars("VonMises");

  // Surface block: every vertex follows the MLS displacement field of nearby phyxels [4.43-4.44]. An input
  // surface is output as it came in, each rank its own piece; a built-in shape's surface is whole on piece 0.
  if (!impl.SurfacePoints.empty())
  {
    std::vector<double> deformed, surfaceDisplacement, normals;
    impl.Surface.Deform(solid, F, deformed, surfaceDisplacement);
    meshfree::VertexNormals(deformed, impl.Triangles, normals);
    std::vector<vtkIdType> pointIndex, triangles;
    if (impl.BuiltWithInput)
    {
      pointIndex = impl.LocalToInput;
      triangles = impl.LocalTriangles;
    }
    else if (vtkMeshFreePieces::OutputShare(outInfo, 1).Size() > 0)
    {
      pointIndex.resize(impl.SurfacePoints.size() / 3);
      std::iota(pointIndex.begin(), pointIndex.end(), vtkIdType(0));
      triangles.assign(impl.Triangles.begin(), impl.Triangles.end());
    }
    output->SetBlock(1, SurfaceBlock(deformed, surfaceDisplacement, normals, pointIndex, triangles));
    output->GetMetaData(1u)->Set(vtkCompositeDataSet::NAME(), "Surface");
  }
  return 1;
}

void vtkMeshFreeDeformableSolid::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Shape: " << this->Shape << "\n";
  os << indent << "ShapeBounds: " << this->ShapeBounds[0] << " " << this->ShapeBounds[1] << " "
     << this->ShapeBounds[2] << " " << this->ShapeBounds[3] << " " << this->ShapeBounds[4] << " "
     << this->ShapeBounds[5] << "\n";
  os << indent << "PhyxelSpacing: " << this->PhyxelSpacing << "\n";
  os << indent << "SurfaceResolution: " << this->SurfaceResolution << "\n";
  os << indent << "YoungModulus: " << this->YoungModulus << "\n";
  os << indent << "PoissonRatio: " << this->PoissonRatio << "\n";
  os << indent << "Density: " << this->Density << "\n";
  os << indent << "VolumeStiffness: " << this->VolumeStiffness << "\n";
  os << indent << "NeighborCount: " << this->NeighborCount << "\n";
  os << indent << "SupportScale: " << this->SupportScale << "\n";
  os << indent << "WeightFunction: " << this->WeightFunction << "\n";
  os << indent << "GradientBasis: " << this->GradientBasis << "\n";
  os << indent << "HourglassStiffness: " << this->HourglassStiffness << "\n";
  os << indent << "PlasticYield: " << this->PlasticYield << "\n";
  os << indent << "PlasticCreep: " << this->PlasticCreep << "\n";
  os << indent << "PlasticMaxStrain: " << this->PlasticMaxStrain << "\n";
  os << indent << "Integrator: " << this->Integrator << "\n";
  os << indent << "TimeStep: " << this->TimeStep << "\n";
  os << indent << "Damping: " << this->Damping << "\n";
  os << indent << "Gravity: " << this->Gravity[0] << " " << this->Gravity[1] << " " << this->Gravity[2] << "\n";
  os << indent << "InitialVelocity: " << this->InitialVelocity[0] << " " << this->InitialVelocity[1] << " "
     << this->InitialVelocity[2] << "\n";
  os << indent << "Container: " << this->Container << "\n";
  os << indent << "Restitution: " << this->Restitution << "\n";
  os << indent << "Friction: " << this->Friction << "\n";
  os << indent << "SelfContact: " << this->SelfContact << "\n";
  os << indent << "EndTime: " << this->EndTime << "\n";
  os << indent << "OutputInterval: " << this->OutputInterval << "\n";
  os << indent << "CacheSize: " << this->CacheSize << "\n";
  os << indent << "NumberOfPhyxels: " << this->NumberOfPhyxels << "\n";
  os << indent << "StableTimeStep: " << this->StableTimeStep << "\n";
}
