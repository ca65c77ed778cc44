#include "vtkMeshFreeSPHFluid.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkFieldData.h"

#include "vtkMeshFreePieces.h"
#include "SPH/SPHFluid.h"
#include "Common/Parallel.h"
#include "Common/StateCache.h"
#include "cuda/Device.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMeshFreeSPHFluid);

namespace
{
/// What the field data array Backend says of the CPU, e.g. "CPU (oneTBB, 2 threads)".
std::string CPUBackend()
{
  return std::string("CPU (") + meshfree::ParallelBackend() + ")";
}
}

struct vtkMeshFreeSPHFluid::Internals
{
  meshfree::SPHFluid Solver;
  meshfree::StateCache<meshfree::SPHState> Cache{ 16 };
  std::string Key;         // every property the cached states depend on; a different key empties the cache
  std::vector<double> Obstacles; // the gathered obstacle triangles, canonical; different ones empty the cache
  bool SetupFailed = false;
  std::vector<double> Times;
  std::string BackendWarning; // the last one given: the same one is not repeated on every update
};

vtkMeshFreeSPHFluid::vtkMeshFreeSPHFluid()
  : Impl(new Internals)
{
  this->SetNumberOfInputPorts(1);
}

vtkMeshFreeSPHFluid::~vtkMeshFreeSPHFluid() = default;

int vtkMeshFreeSPHFluid::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

namespace
{
// Triangles of the polygons and strips of `surface`, 9 doubles each (fan triangulation of polygons).
// Triangles with a NaN or infinite vertex are left out and counted in `skipped`.
std::vector<double> Triangles(vtkPolyData* surface, long& skipped)
{
  std::vector<double> out;
  skipped = 0;
  if (!surface || surface->GetNumberOfPoints() == 0)
  {
    return out;
  }
  auto add = [&](vtkIdType a, vtkIdType b, vtkIdType c) {
    double p[9];
    bool finite = true;
    int v = 0;
    for (vtkIdType id : { a, b, c })
    {
      surface->GetPoint(id, p + 3 * v);
      finite = finite && std::isfinite(p[3 * v]) && std::isfinite(p[3 * v + 1]) && std::isfinite(p[3 * v + 2]);
      ++v;
    }
    if (finite)
    {
      out.insert(out.end(), p, p + 9);
    }
    else
    {
      ++skipped;
    }
  };
  vtkIdType n;
  const vtkIdType* ids;
  vtkCellArray* polys = surface->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(n, ids);)
  {
    for (vtkIdType k = 1; k + 1 < n; ++k)
    {
      add(ids[0], ids[k], ids[k + 1]);
    }
  }
  vtkCellArray* strips = surface->GetStrips();
  for (strips->InitTraversal(); strips->GetNextCell(n, ids);)
  {
    for (vtkIdType k = 0; k + 2 < n; ++k)
    {
      k % 2 == 0 ? add(ids[k], ids[k + 1], ids[k + 2]) : add(ids[k + 1], ids[k], ids[k + 2]);
    }
  }
  return out;
}
}

bool vtkMeshFreeSPHFluid::ValidTimes() const
{
  return this->OutputInterval > 0.0 && std::isfinite(this->OutputInterval) && this->EndTime >= 0.0 &&
    std::isfinite(this->EndTime);
}

int vtkMeshFreeSPHFluid::GetNumberOfOutputTimes()
{
  return static_cast<int>(meshfree::OutputTimes(this->EndTime, this->OutputInterval).size());
}

void vtkMeshFreeSPHFluid::ReportObstaclesWithoutPort(vtkObject* obstacles)
{
  if (obstacles)
  {
    vtkErrorMacro("SPH Fluid (pvpython SPHFluid) is a pure source and takes no input: these Obstacles are ignored and "
                  "the fluid runs without them. For obstacles use SPH Fluid With Obstacles: "
                  "SPHFluidWithObstacles(Obstacles=surface, ...) in pvpython, Filters > MeshFree in the GUI.");
  }
}

int vtkMeshFreeSPHFluid::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  if (!this->ValidTimes())
  {
    vtkErrorMacro("OutputInterval must be finite and > 0, and EndTime finite and >= 0 (got "
      << this->OutputInterval << ", " << this->EndTime << "); the output is empty");
  }
  this->Impl->Times = meshfree::OutputTimes(this->EndTime, this->OutputInterval);
  const std::vector<double>& times = this->Impl->Times;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
  const double range[2] = { times.front(), times.back() };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  // Every rank simulates the whole fluid and outputs its share of the particles (see RequestData).
  outInfo->Set(vtkAlgorithm::CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

int vtkMeshFreeSPHFluid::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkMeshFreePieces::RequestInput(
    outputVector->GetInformationObject(0), inputVector[0]->GetInformationObject(0));
  return 1;
}

int vtkMeshFreeSPHFluid::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  Internals& impl = *this->Impl;
  if (!this->ValidTimes())
  {
    return 1; // empty output, the error has been reported by RequestInformation
  }
  if (impl.Times.empty())
  {
    impl.Times = meshfree::OutputTimes(this->EndTime, this->OutputInterval);
  }

  // The requested time: an output time (cached), or a time between two of them, simulated from the output
  // time before it and not cached (meshfree::PlaceRequestedTime).
  const std::vector<double>& times = impl.Times;
  const double requested = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    : 0.0;
  long step = 0;
  const double target = meshfree::PlaceRequestedTime(times, requested, step);
  const bool between = target != times[step];
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), target);

  meshfree::SPHParameters p;
  p.Dimension = this->Dimension;
  std::copy(this->FluidBounds, this->FluidBounds + 6, p.FluidBounds);
  std::copy(this->DomainBounds, this->DomainBounds + 6, p.DomainBounds);
  p.ParticleSpacing = this->ParticleSpacing;
  p.SmoothingLength = this->SmoothingLength;
  p.RestDensity = this->RestDensity;
  p.GasStiffness = this->GasStiffness;
  p.EquationOfState = static_cast<meshfree::SPHEquationOfState>(this->EquationOfState);
  p.Kernels = static_cast<meshfree::SPHKernelPair>(this->KernelPair);
  p.Viscosity = this->Viscosity;
  p.SurfaceTension = this->SurfaceTension;
  p.ArtificialViscosity = this->ArtificialViscosity;
  std::copy(this->Gravity, this->Gravity + 3, p.Gravity);
  p.TimeStep = this->TimeStep;
  p.CFLNumber = this->CFLNumber;
  p.Solver = static_cast<meshfree::SPHSolver>(this->Solver);
  p.DensityTolerance = this->DensityTolerance;
  p.DivergenceTolerance = this->DivergenceTolerance;
  p.MaximumIterations = this->MaximumIterations;

  // The obstacles, whole on every rank: under MPI each rank holds a piece (collective: every rank gathers, also
  // with an empty piece). The canonical order makes the triangles, and so the simulation, the same bits whatever
  // the number of ranks.
  const bool distributed = vtkMeshFreePieces::IsDistributed(outInfo);
  std::vector<double> obstacles;
  long skipped = 0; // triangles of this rank's piece
  if (this->GetNumberOfInputConnections(0) > 0)
  {
    obstacles = Triangles(vtkPolyData::GetData(inputVector[0], 0), skipped);
    obstacles = vtkMeshFreePieces::AllGather(obstacles, distributed);
    vtkMeshFreePieces::CanonicalTriangles(obstacles);
  }
  std::ostringstream key;
  key << std::hexfloat << p.Dimension << ' ' << p.ParticleSpacing << ' ' << p.SmoothingLength << ' '
      << p.RestDensity << ' ' << p.GasStiffness << ' ' << this->EquationOfState << ' ' << this->KernelPair << ' '
      << p.Viscosity << ' ' << p.ArtificialViscosity << ' ' << p.SurfaceTension << ' ' << p.TimeStep << ' ' << p.CFLNumber << ' '
      << this->OutputInterval << ' ' << this->Solver << ' ' << p.DensityTolerance << ' ' << p.DivergenceTolerance << ' '
      << p.MaximumIterations;
  for (int i = 0; i < 6; ++i)
  {
    key << ' ' << p.FluidBounds[i] << ' ' << p.DomainBounds[i] << ' ' << (i < 3 ? p.Gravity[i] : 0.0);
  }
  impl.Cache.SetCapacity(static_cast<std::size_t>(this->CacheSize));
  if (key.str() != impl.Key || obstacles != impl.Obstacles)
  {
    impl.Key = key.str();
    impl.Obstacles = std::move(obstacles);
    impl.Cache.Clear();
    impl.SetupFailed = false;
    if (skipped > 0)
    {
      vtkWarningMacro("SPH Fluid: " << skipped << " Obstacles triangles with a NaN or infinite vertex were left out");
    }
    try
    {
      impl.Solver.Setup(p, impl.Obstacles);
      meshfree::SPHState initial = impl.Solver.InitialState();
      impl.Cache.Insert(0, std::move(initial));
    }
    catch (const std::exception& e)
    {
      vtkErrorMacro("SPH Fluid: " << e.what());
      impl.SetupFailed = true;
    }
    for (const std::string& warning : impl.Solver.Warnings())
    {
      vtkWarningMacro("SPH Fluid: " << warning);
    }
  }
  if (impl.SetupFailed)
  {
    return 1; // empty output, the error has been reported
  }

  // Restore the nearest earlier cached state and simulate forward, caching every output time reached; then,
  // for a time between output times, on to it (not cached).
  long found = 0;
  const meshfree::SPHState* cached = impl.Cache.FindAtOrBefore(step, found);
  meshfree::SPHState state = *cached;
  std::string backend = this->SelectBackend(static_cast<vtkIdType>(state.Size()));
  bool advanced = false, onDevice = false;
  const long reducedBefore = impl.Solver.ReducedSteps();
  const long unconvergedBefore = impl.Solver.UnconvergedSteps();
  const long last = between ? step + 1 : step; // k = step + 1 stands for the partial interval
  for (long k = found + 1; k <= last; ++k)
  {
    const long stepsBefore = state.Steps;
    const double span = static_cast<double>(last - found);
    const auto progress = [this, k, found, span](double fraction) {
      this->UpdateProgress((static_cast<double>(k - found - 1) + fraction) / span);
      return !this->GetAbortExecute();
    };
    const bool partial = k > step;
    const meshfree::SPHFluid::Status status = impl.Solver.Advance(state, partial ? target : times[k], progress);
    this->StepsTaken += state.Steps - stepsBefore;
    advanced = true;
    onDevice = impl.Solver.UsedBackend() == meshfree::SPHBackend::CUDA;
    if (this->Backend == BACKEND_CUDA && !onDevice && !impl.Solver.BackendNote().empty())
    {
      this->WarnBackend(impl.Solver.BackendNote());
    }
    if (status == meshfree::SPHFluid::Status::Aborted)
    {
      vtkWarningMacro("SPH Fluid: aborted at t = " << state.Time << "; the output is empty");
      return 1;
    }
    if (status == meshfree::SPHFluid::Status::Failed)
    {
      vtkErrorMacro("SPH Fluid: " << impl.Solver.ErrorMessage() << "; the output is empty");
      return 1;
    }
    if (!partial)
    {
      impl.Cache.Insert(k, state);
    }
  }
  if (advanced)
  {
    backend = onDevice ? "CUDA (" + meshfree::cuda::DeviceName() + ")" : CPUBackend();
  }
  if (impl.Solver.UnconvergedSteps() > unconvergedBefore)
  {
    vtkWarningMacro("SPH Fluid: the DFSPH solves did not reach DensityTolerance / DivergenceTolerance within "
      << this->MaximumIterations << " iterations on " << impl.Solver.UnconvergedSteps() - unconvergedBefore
      << " steps (raise MaximumIterations or the tolerances; a tolerance of 0 is never reached)");
  }
  if (impl.Solver.ReducedSteps() > reducedBefore)
  {
    vtkWarningMacro("SPH Fluid: TimeStep " << this->TimeStep << " s exceeds the stability limit; it was reduced on "
                                           << impl.Solver.ReducedSteps() - reducedBefore
                                           << " steps (set CFLNumber > 0 for adaptive steps)");
  }

  // Output: one vertex per particle of this piece's share (all of them without pieces). Every rank holds the same
  // state, so the shares of the ranks hold each particle exactly once.
  const vtkMeshFreePieces::Range share =
    vtkMeshFreePieces::OutputShare(outInfo, static_cast<vtkIdType>(state.Size()));
  const vtkIdType n = share.Size();
  const vtkIdType first = share.Begin;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  vtkNew<vtkDoubleArray> velocity, density, pressure, acceleration;
  velocity->SetName("Velocity");
  velocity->SetNumberOfComponents(3);
  velocity->SetNumberOfTuples(n);
  density->SetName("Density");
  density->SetNumberOfTuples(n);
  pressure->SetName("Pressure");
  pressure->SetNumberOfTuples(n);
  vtkNew<vtkIdTypeArray> ids;
  ids->SetName("Id");
  ids->SetNumberOfTuples(n);
  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfTuples(n);
  vtkNew<vtkIdTypeArray> offsets;
  offsets->SetNumberOfTuples(n + 1);
  for (vtkIdType i = 0; i < n; ++i)
  {
    const vtkIdType s = first + i;
    points->SetPoint(i, &state.Position[3 * s]);
    velocity->SetTypedTuple(i, &state.Velocity[3 * s]);
    density->SetValue(i, state.Density[s]);
    pressure->SetValue(i, state.Pressure[s]);
    ids->SetValue(i, static_cast<vtkIdType>(state.Id[s]));
    connectivity->SetValue(i, i);
    offsets->SetValue(i, i);
  }
  offsets->SetValue(n, n);
  vtkNew<vtkCellArray> verts;
  verts->SetData(offsets, connectivity);
  output->SetPoints(points);
  output->SetVerts(verts);
  vtkPointData* pd = output->GetPointData();
  pd->AddArray(velocity);
  pd->AddArray(density);
  pd->AddArray(pressure);
  pd->AddArray(ids);
  if (this->ComputeAcceleration)
  {
    acceleration->SetName("Acceleration");
    acceleration->SetNumberOfComponents(3);
    acceleration->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      acceleration->SetTypedTuple(i, &state.Acceleration[3 * (first + i)]);
    }
    pd->AddArray(acceleration);
  }
  if (this->ComputeNeighborCount)
  {
    const std::vector<int> counts = impl.Solver.NeighborCounts(state);
    vtkNew<vtkIntArray> neighbors;
    neighbors->SetName("NeighborCount");
    neighbors->SetNumberOfTuples(n);
    std::copy(counts.begin() + first, counts.begin() + first + n, neighbors->GetPointer(0));
    pd->AddArray(neighbors);
  }
  pd->SetActiveScalars("Pressure");
  vtkNew<vtkStringArray> ran;
  ran->SetName("Backend");
  ran->InsertNextValue(backend);
  output->GetFieldData()->AddArray(ran);
  // The solver and what it did over the output interval that ended at this state (SPHSolverReport).
  vtkNew<vtkStringArray> solverName;
  solverName->SetName("Solver");
  solverName->InsertNextValue(this->Solver == SOLVER_DFSPH ? "DFSPH" : "WCSPH");
  output->GetFieldData()->AddArray(solverName);
  const meshfree::SPHSolverReport& report = state.Report;
  const double steps = report.Steps > 0 ? static_cast<double>(report.Steps) : 1.0;
  vtkNew<vtkDoubleArray> densityIterations, divergenceIterations, densityError;
  densityIterations->SetName("DensityIterations");
  densityIterations->InsertNextValue(report.LastDensityIterations);
  densityIterations->InsertNextValue(static_cast<double>(report.DensityIterations) / steps);
  divergenceIterations->SetName("DivergenceIterations");
  divergenceIterations->InsertNextValue(report.LastDivergenceIterations);
  divergenceIterations->InsertNextValue(static_cast<double>(report.DivergenceIterations) / steps);
  densityError->SetName("AverageDensityError");
  if (this->Solver == SOLVER_DFSPH)
  {
    densityError->InsertNextValue(report.AverageDensityError);
    densityError->InsertNextValue(report.MaxAverageDensityError);
  }
  else
  {
    double compression = 0.0;
    for (meshfree::Index i = 0; i < state.Size(); ++i)
    {
      compression += std::max(state.Density[i] / this->RestDensity - 1.0, 0.0);
    }
    compression /= static_cast<double>(std::max<meshfree::Index>(1, state.Size()));
    densityError->InsertNextValue(compression);
    densityError->InsertNextValue(compression);
  }
  output->GetFieldData()->AddArray(densityIterations);
  output->GetFieldData()->AddArray(divergenceIterations);
  output->GetFieldData()->AddArray(densityError);
  return 1;
}

std::string vtkMeshFreeSPHFluid::SelectBackend(vtkIdType particles)
{
  // CUDA: the device whenever it can run the setup (otherwise a warning with the reason, and the CPU). Auto: the
  // device for jobs of at least GetAutoDeviceParticles() particles when it can run them, silently the CPU
  // otherwise. The device is probed (once per process) only when it could be chosen.
  meshfree::SPHFluid& solver = this->Impl->Solver;
  const bool wanted = this->Backend == BACKEND_CUDA ||
    (this->Backend == BACKEND_AUTO && particles >= vtkMeshFreeSPHFluid::GetAutoDeviceParticles());
  const std::string reason = wanted ? solver.DeviceDeclineReason() : std::string();
  const bool device = wanted && reason.empty();
  solver.SetBackend(device ? meshfree::SPHBackend::CUDA : meshfree::SPHBackend::CPU);
  if (this->Backend == BACKEND_CUDA)
  {
    this->WarnBackend(reason);
  }
  return device ? "CUDA (" + meshfree::cuda::DeviceName() + ")" : CPUBackend();
}

void vtkMeshFreeSPHFluid::WarnBackend(const std::string& reason)
{
  const std::string warning = reason.empty()
    ? std::string()
    : "SPH Fluid: Backend CUDA is not usable here (" + reason + "); the CPU ran the simulation";
  if (warning != this->Impl->BackendWarning)
  {
    this->Impl->BackendWarning = warning;
    if (!warning.empty())
    {
      vtkWarningMacro(<< warning);
    }
  }
}

void vtkMeshFreeSPHFluid::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FluidBounds: ";
  for (double b : this->FluidBounds)
  {
    os << b << " ";
  }
  os << "\n" << indent << "DomainBounds: ";
  for (double b : this->DomainBounds)
  {
    os << b << " ";
  }
  os << "\n";
  os << indent << "Dimension: " << this->Dimension << "\n";
  os << indent << "ParticleSpacing: " << this->ParticleSpacing << "\n";
  os << indent << "SmoothingLength: " << this->SmoothingLength << "\n";
  os << indent << "RestDensity: " << this->RestDensity << "\n";
  os << indent << "GasStiffness: " << this->GasStiffness << "\n";
  os << indent << "EquationOfState: " << this->EquationOfState << "\n";
  os << indent << "KernelPair: " << this->KernelPair << "\n";
  os << indent << "Viscosity: " << this->Viscosity << "\n";
  os << indent << "ArtificialViscosity: " << this->ArtificialViscosity << "\n";
  os << indent << "SurfaceTension: " << this->SurfaceTension << "\n";
  os << indent << "Gravity: " << this->Gravity[0] << " " << this->Gravity[1] << " " << this->Gravity[2] << "\n";
  os << indent << "TimeStep: " << this->TimeStep << "\n";
  os << indent << "CFLNumber: " << this->CFLNumber << "\n";
  os << indent << "EndTime: " << this->EndTime << "\n";
  os << indent << "OutputInterval: " << this->OutputInterval << "\n";
  os << indent << "ComputeAcceleration: " << this->ComputeAcceleration << "\n";
  os << indent << "ComputeNeighborCount: " << this->ComputeNeighborCount << "\n";
  os << indent << "CacheSize: " << this->CacheSize << "\n";
  os << indent << "Backend: " << this->Backend << "\n";
  os << indent << "Solver: " << this->Solver << "\n";
  os << indent << "DensityTolerance: " << this->DensityTolerance << "\n";
  os << indent << "DivergenceTolerance: " << this->DivergenceTolerance << "\n";
  os << indent << "MaximumIterations: " << this->MaximumIterations << "\n";
}
