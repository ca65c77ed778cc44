#include "vtkMeshlessApproximation.h"
#include "vtkMeshFreeFilterSupport.h"

#include "vtkAlgorithmOutput.h"
#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkMeshFreeHalo.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkStructuredGrid.h"

#include "Approximation/Approximation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMeshlessApproximation);
vtkCxxSetObjectMacro(vtkMeshlessApproximation, Controller, vtkMultiProcessController);

vtkMeshlessApproximation::vtkMeshlessApproximation()
{
  this->SetNumberOfInputPorts(2);
  const double nan = vtkMath::Nan();
  this->Center[0] = this->Center[1] = this->Center[2] = nan;
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

vtkMeshlessApproximation::~vtkMeshlessApproximation()
{
  this->SetController(nullptr);
}

bool vtkMeshlessApproximation::IsDistributed(vtkInformation* outInfo) const
{
  return vtkMeshFreeHalo::IsDistributed(this->Controller) && outInfo &&
    outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()) &&
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()) > 1;
}

void vtkMeshlessApproximation::SetProbeConnection(vtkAlgorithmOutput* output)
{
  this->SetInputConnection(1, output);
}

void vtkMeshlessApproximation::AddPointArray(const char* name)
{
  if (name && *name &&
    std::find(this->PointArrays.begin(), this->PointArrays.end(), name) == this->PointArrays.end())
  {
    this->PointArrays.emplace_back(name);
    this->Modified();
  }
}

void vtkMeshlessApproximation::ClearPointArrays()
{
  if (!this->PointArrays.empty())
  {
    this->PointArrays.clear();
    this->Modified();
  }
}

int vtkMeshlessApproximation::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 0)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  }
  else
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet");
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

int vtkMeshlessApproximation::RequestDataObject(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataObject* probe =
    this->GetNumberOfInputConnections(1) > 0 ? vtkDataObject::GetData(inputVector[1], 0) : nullptr;
  const char* wanted = probe ? probe->GetClassName() : (this->HeightField ? "vtkStructuredGrid" : "vtkImageData");
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkDataObject* output = vtkDataObject::GetData(outInfo);
  if (!output || std::strcmp(output->GetClassName(), wanted) != 0)
  {
    vtkDataObject* created = nullptr;
    if (probe)
    {
      created = probe->NewInstance();
    }
    else if (this->HeightField)
    {
      created = vtkStructuredGrid::New();
    }
    else
    {
      created = vtkImageData::New();
    }
    outInfo->Set(vtkDataObject::DATA_OBJECT(), created);
    created->Delete();
  }
  return 1;
}

bool vtkMeshlessApproximation::GridGeometry(
  vtkInformationVector** inputVector, bool distributed, double origin[3], double spacing[3], int dims[3])
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  double bounds[6] = { 0, 0, 0, 0, 0, 0 };
  const bool userBounds = this->ModelBounds[0] < this->ModelBounds[1] ||
    this->ModelBounds[2] < this->ModelBounds[3] || this->ModelBounds[4] < this->ModelBounds[5];
  if (userBounds)
  {
    std::copy(this->ModelBounds, this->ModelBounds + 6, bounds);
  }
  else
  {
    // The bounds of the finite points (vtkPoints::GetBounds skips NaN but not Inf, and one Inf point
    // would collapse an axis of the grid), over every rank's piece when distributed.
    const vtkIdType n = input ? input->GetNumberOfPoints() : 0;
    std::vector<double> xyz(3 * static_cast<size_t>(n));
    for (vtkIdType i = 0; i < n; ++i)
    {
      input->GetPoint(i, &xyz[3 * i]);
    }
    double local[6];
    vtkMeshFreeHalo::FiniteBounds(xyz.data(), n, local);
    if (distributed)
    {
      vtkMeshFreeHalo::GlobalBounds(this->Controller, local, bounds);
    }
    else
    {
      std::copy(local, local + 6, bounds);
    }
    if (!(bounds[0] <= bounds[1] && bounds[2] <= bounds[3] && bounds[4] <= bounds[5]))
    {
      std::fill(bounds, bounds + 6, 0.0); // no finite point anywhere
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    const double range = bounds[2 * a + 1] - bounds[2 * a];
    const bool flat = !(range > 0.0) || !std::isfinite(range) || (this->HeightField && a == 2);
    dims[a] = flat ? 1 : std::max(1, this->SampleDimensions[a]);
    origin[a] = std::isfinite(bounds[2 * a]) ? bounds[2 * a] : 0.0;
    spacing[a] = dims[a] > 1 ? range / (dims[a] - 1) : 1.0;
  }
  if (this->HeightField)
  {
    origin[2] = 0.0;
  }
  return input != nullptr;
}

int vtkMeshlessApproximation::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkInformation* probeInfo = inputVector[1]->GetInformationObject(0);
  if (probeInfo)
  {
    if (probeInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    {
      outInfo->CopyEntry(probeInfo, vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT());
    }
    else
    {
      outInfo->Remove(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT());
    }
    outInfo->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
    return 1;
  }
  // The output grid depends on the input's bounds, which only its data know: bring the input up to date
  // now, so that the whole extent announced here is the one produced. Distributed, each rank brings its own
  // piece (the one ParaView will ask for: piece = rank) and the bounds are agreed over all ranks.
  const bool distributed = vtkMeshFreeHalo::IsDistributed(this->Controller);
  if (this->GetNumberOfInputConnections(0) > 0)
  {
    vtkAlgorithmOutput* connection = this->GetInputConnection(0, 0);
    if (distributed)
    {
      vtkNew<vtkInformation> request;
      request->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), this->Controller->GetLocalProcessId());
      request->Set(
        vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), this->Controller->GetNumberOfProcesses());
      request->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
      vtkNew<vtkInformationVector> requests;
      requests->SetNumberOfInformationObjects(connection->GetProducer()->GetNumberOfOutputPorts());
      requests->SetInformationObject(connection->GetIndex(), request);
      connection->GetProducer()->Update(connection->GetIndex(), requests);
    }
    else
    {
      connection->GetProducer()->Update(connection->GetIndex());
    }
  }
  double origin[3], spacing[3];
  int dims[3];
  this->GridGeometry(inputVector, distributed, origin, spacing, dims);
  std::copy(origin, origin + 3, this->GridOrigin);
  std::copy(spacing, spacing + 3, this->GridSpacing);
  std::copy(dims, dims + 3, this->GridDimensions);
  const int extent[6] = { 0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  if (!this->HeightField)
  {
    outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
    outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  }
  return 1;
}

int vtkMeshlessApproximation::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // Serial: the whole cloud, at every output point. Distributed: the cloud's piece of this rank (the rest
  // comes from the halo exchange). The probe follows the downstream request.
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const bool distributed = this->IsDistributed(outInfo);
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  if (inInfo)
  {
    int piece = 0, pieces = 1;
    if (distributed)
    {
      pieces = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
      piece = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
        ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
        : this->Controller->GetLocalProcessId();
    }
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), piece);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), pieces);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  }
  vtkInformation* probeInfo = inputVector[1]->GetInformationObject(0);
  if (probeInfo)
  {
    probeInfo->CopyEntry(outInfo, vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
    probeInfo->CopyEntry(outInfo, vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
    probeInfo->CopyEntry(outInfo, vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS());
    if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT()))
    {
      probeInfo->CopyEntry(outInfo, vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT());
    }
  }
  return 1;
}

namespace
{
/// One array to approximate: its columns [Offset, Offset + Components) in the values table. Array is null on a
/// rank whose (empty) piece lacks it.
struct SelectedArray
{
  vtkDataArray* Array;
  int Offset;
  int Components;
  std::string Name;
};

/// "name\ncomponents\n..." - the selection, comparable over ranks.
std::string Describe(const std::vector<SelectedArray>& selected, bool volumes)
{
  std::ostringstream text;
  text << (volumes ? 1 : 0) << "\n";
  for (const SelectedArray& s : selected)
  {
    text << s.Name << "\n" << s.Components << "\n";
  }
  return text.str();
}

/// Collective. The selection of the first rank that has points (every rank must approximate the same
/// columns); false when this rank has points and another selection.
bool AgreeOnSelection(vtkMultiProcessController* controller, vtkIdType n, vtkPointData* pd,
  std::vector<SelectedArray>& selected, bool& volumes)
{
  const int ranks = controller->GetNumberOfProcesses();
  const int rank = controller->GetLocalProcessId();
  const double first = ranks - vtkMeshFreeHalo::GlobalMax(controller, n > 0 ? ranks - rank : 0);
  const int root = first < ranks ? static_cast<int>(first) : 0;
  std::string mine = Describe(selected, volumes);
  vtkIdType length = static_cast<vtkIdType>(mine.size());
  controller->Broadcast(&length, 1, root);
  std::vector<char> text(static_cast<size_t>(length) + 1, '\0');
  if (rank == root)
  {
    std::copy(mine.begin(), mine.end(), text.begin());
  }
  controller->Broadcast(text.data(), length, root);
  const std::string agreed(text.data(), static_cast<size_t>(length));
  if (agreed == mine)
  {
    return true;
  }
  std::istringstream in(agreed);
  int v = 0;
  in >> v;
  volumes = v != 0;
  selected.clear();
  std::string name;
  int components = 0, offset = 0;
  in.ignore();
  while (std::getline(in, name) && in >> components)
  {
    in.ignore();
    vtkDataArray* array = pd->GetArray(name.c_str());
    selected.push_back(
      { array && array->GetNumberOfComponents() == components ? array : nullptr, offset, components, name });
    offset += components;
  }
  return n == 0;
}

/// Collective: Sum, Max and Gather over the controller's ranks for the core's distributed cloud.
meshfree::CloudPartition Partition(vtkMultiProcessController* controller, const unsigned char* owned)
{
  meshfree::CloudPartition partition;
  auto reduce = [controller](double* values, int n, int op) {
    std::vector<double> result(static_cast<size_t>(std::max(n, 0)));
    controller->AllReduce(values, result.data(), n, op);
    std::copy(result.begin(), result.end(), values);
  };
  partition.Sum = [reduce](double* values, int n) { reduce(values, n, vtkCommunicator::SUM_OP); };
  partition.Max = [reduce](double* values, int n) { reduce(values, n, vtkCommunicator::MAX_OP); };
  partition.Owned = owned;
  partition.Gather = [controller](const std::vector<double>& mine, std::vector<double>& all) {
    const int parts = controller->GetNumberOfProcesses();
    const vtkIdType length = static_cast<vtkIdType>(mine.size());
    std::vector<vtkIdType> lengths(static_cast<size_t>(parts), 0), offsets(static_cast<size_t>(parts), 0);
    controller->AllGather(&length, lengths.data(), 1);
    vtkIdType total = 0;
    for (int p = 0; p < parts; ++p)
    {
      offsets[p] = total;
      total += lengths[p];
    }
    all.assign(static_cast<size_t>(total), 0.0);
    if (total > 0)
    {
      double none = 0.0;
      controller->AllGatherV(mine.empty() ? &none : mine.data(), all.data(), length, lengths.data(), offsets.data());
    }
  };
  return partition;
}

/// The prepared cloud (fit coordinates, values, volumes) as a vertex-less vtkPolyData for the halo exchange.
vtkSmartPointer<vtkPolyData> CloudData(const std::vector<double>& xyz, const std::vector<double>& values, int columns,
  const std::vector<double>& volumes, vtkDataArray* globalIds)
{
  const vtkIdType n = static_cast<vtkIdType>(xyz.size() / 3);
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(n);
  std::copy(xyz.begin(), xyz.end(), coordinates->GetPointer(0));
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  cloud->SetPoints(points);
  vtkNew<vtkDoubleArray> table;
  table->SetName("values");
  table->SetNumberOfComponents(std::max(columns, 1));
  table->SetNumberOfTuples(n);
  if (columns > 0)
  {
    std::copy(values.begin(), values.end(), table->GetPointer(0));
  }
  else
  {
    table->Fill(0.0);
  }
  cloud->GetPointData()->AddArray(table);
  if (!volumes.empty() || n == 0)
  {
    vtkNew<vtkDoubleArray> v;
    v->SetName("volumes");
    v->SetNumberOfTuples(n);
    std::copy(volumes.begin(), volumes.end(), v->GetPointer(0));
    cloud->GetPointData()->AddArray(v);
  }
  if (globalIds)
  {
    cloud->GetPointData()->SetGlobalIds(globalIds);
  }
  return cloud;
}

/// Collective. The halo the evaluation's reach asks for (ExchangeForKNearest or Exchange by radius).
int ExchangeReach(
  vtkMeshFreeHalo* halo, vtkPolyData* cloud, const std::vector<double>& queries, int k, double radius, double factor)
{
  const vtkIdType nq = static_cast<vtkIdType>(queries.size() / 3);
  if (k > 0)
  {
    return halo->ExchangeForKNearest(cloud, queries.data(), nq, k, radius, factor);
  }
  double region[6];
  vtkMeshFreeHalo::FiniteBounds(queries.data(), nq, region);
  return halo->Exchange(cloud, region, radius);
}
} // namespace

int vtkMeshlessApproximation::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  vtkDataSet* probe = this->GetNumberOfInputConnections(1) > 0 ? vtkDataSet::GetData(inputVector[1], 0) : nullptr;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkDataSet* output = vtkDataSet::GetData(outputVector, 0);
  if (!input || !output)
  {
    vtkErrorMacro("Missing input point set or output.");
    return 0;
  }
  // Distributed: every rank below takes part in every collective call, in the same order, whatever its piece.
  const bool distributed = this->IsDistributed(outInfo);
  vtkMultiProcessController* controller = distributed ? this->Controller : nullptr;
  const vtkIdType n = input->GetNumberOfPoints();
  const vtkIdType globalN = vtkMeshFreeHalo::GlobalSum(controller, n);
  if (globalN == 0)
  {
    vtkWarningMacro("The input has no points: every output point gets NullValue and vtkValidPointMask = 0.");
  }

  // The arrays to approximate, side by side in one row-major table (every component, as double).
  std::vector<SelectedArray> selected;
  int components = 0;
  vtkPointData* inPD = input->GetPointData();
  for (int a = 0; a < inPD->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = inPD->GetArray(a);
    const char* name = array ? array->GetName() : nullptr;
    if (!array || !name || std::strcmp(name, "vtkValidPointMask") == 0)
    {
      continue;
    }
    if (!this->PointArrays.empty() &&
      std::find(this->PointArrays.begin(), this->PointArrays.end(), name) == this->PointArrays.end())
    {
      continue;
    }
    selected.push_back({ array, components, array->GetNumberOfComponents(), name });
    components += array->GetNumberOfComponents();
  }
  for (const std::string& name : this->PointArrays)
  {
    if (n > 0 && !inPD->GetArray(name.c_str()))
    {
      vtkWarningMacro("PointArrays names '" << name << "', which is not a numeric point array of the input.");
    }
  }
  // SPH volumes m/rho when the cloud carries Mass and Density (as the SPH Fluid source writes).
  vtkDataArray* mass = inPD->GetArray("Mass");
  vtkDataArray* density = inPD->GetArray("Density");
  bool useVolumes = this->Method == SPH && mass && density && mass->GetNumberOfComponents() == 1 &&
    density->GetNumberOfComponents() == 1;
  if (controller && !AgreeOnSelection(controller, n, inPD, selected, useVolumes))
  {
    vtkErrorMacro("This rank's piece of the cloud has other point arrays than the first rank with points: the "
                  "arrays it lacks are taken as NaN (its points are ignored).");
  }
  components = selected.empty() ? 0 : selected.back().Offset + selected.back().Components;
  const int elevation = this->HeightField ? components : -1;
  const int columns = components + (this->HeightField ? 1 : 0);
  const double nan = vtkMath::Nan();
  std::vector<double> xyz(3 * static_cast<size_t>(n)), values(static_cast<size_t>(n) * columns);
  for (vtkIdType i = 0; i < n; ++i)
  {
    double* x = &xyz[3 * i];
    input->GetPoint(i, x);
    double* row = &values[static_cast<size_t>(i) * columns];
    for (const SelectedArray& s : selected)
    {
      for (int c = 0; c < s.Components; ++c)
      {
        row[s.Offset + c] = s.Array ? s.Array->GetComponent(i, c) : nan;
      }
    }
    if (this->HeightField)
    {
      row[elevation] = x[2]; // z = f(x, y): z is the data, the fit is in the x-y plane
      x[2] = 0.0;
    }
  }
  std::vector<double> volumes;
  if (useVolumes)
  {
    volumes.resize(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      volumes[i] = mass && density ? mass->GetComponent(i, 0) / density->GetComponent(i, 0) : nan;
    }
  }

  meshfree::ApproximationOptions opts;
  opts.Method = static_cast<meshfree::ApproximationMethod>(this->Method);
  opts.Degree = this->BasisDegree;
  opts.Weight = static_cast<meshfree::KernelType>(this->WeightFunction);
  opts.NeighborCount = this->NeighborCount;
  opts.SupportRadius = this->SupportRadius;
  opts.Epsilon = this->Epsilon;
  opts.CenterSet = std::isfinite(this->Center[0]) && std::isfinite(this->Center[1]) && std::isfinite(this->Center[2]);
  std::copy(this->Center, this->Center + 3, opts.Center);
  if (this->HeightField)
  {
    opts.Center[2] = 0.0;
  }
  opts.ShepardNormalization = this->ShepardNormalization;
  opts.ComputeGradients = this->ComputeGradients;
  opts.Diagnostics = this->Diagnostics;
  opts.NullValue = this->NullValue;
  opts.Backend = static_cast<meshfree::ApproximationBackend>(this->Backend);
  opts.Smoothing = this->Smoothing;
  opts.RBFGlobalLimit = this->RBFGlobalLimit;
  opts.PatchPoints = this->RBFPatchPoints;
  opts.RBFKernel = static_cast<meshfree::RBFKernelType>(this->RBFKernel);
  if (!std::isfinite(this->NullValue))
  {
    vtkWarningMacro("NullValue " << this->NullValue << " is not a finite number: masked points get 0 instead.");
    opts.NullValue = 0.0;
  }
  meshfree::Approximator approx;
  if (!approx.SetOptions(opts))
  {
    // The same options on every rank: every rank stops here, before any collective call of the core.
    vtkErrorMacro("Invalid settings: " << approx.Error());
    return 0;
  }
  // Distributed, the first SetCloud (this rank's points) agrees on everything global; the second, after the
  // halo exchange below, gives the evaluation its neighbours.
  meshfree::CloudPartition partition;
  if (controller)
  {
    partition = Partition(controller, nullptr);
  }
  approx.SetCloud(xyz.data(), n, values.data(), columns, volumes.empty() ? nullptr : volumes.data(),
    controller ? &partition : nullptr);
  const vtkIdType excluded = vtkMeshFreeHalo::GlobalSum(controller, approx.Report().ExcludedPoints);
  if (excluded > 0)
  {
    vtkWarningMacro(<< excluded << " of " << globalN
                    << " input points have NaN/Inf coordinates or values (or a non-positive SPH volume): "
                       "they are ignored.");
  }
  const vtkIdType valid = globalN - excluded;
  if (valid > 0 && this->SupportRadius <= 0 && this->NeighborCount > valid && this->Method != LS &&
    this->Method != RBF && this->Method != AUTO)
  {
    vtkWarningMacro("NeighborCount (" << this->NeighborCount << ") exceeds the " << valid
                                      << " valid input points: all of them are used.");
  }

  // The output's geometry: the probe (its piece), or the grid (its requested extent).
  if (probe)
  {
    output->ShallowCopy(probe);
  }
  else
  {
    int extent[6] = { 0, this->GridDimensions[0] - 1, 0, this->GridDimensions[1] - 1, 0, this->GridDimensions[2] - 1 };
    if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT()))
    {
      int requested[6];
      outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), requested);
      for (int a = 0; a < 3; ++a)
      {
        extent[2 * a] = std::max(extent[2 * a], requested[2 * a]);
        extent[2 * a + 1] = std::min(extent[2 * a + 1], requested[2 * a + 1]);
      }
    }
    const double* origin = this->GridOrigin;
    const double* spacing = this->GridSpacing;
    if (vtkImageData* image = vtkImageData::SafeDownCast(output))
    {
      image->Initialize();
      image->SetExtent(extent);
      image->SetOrigin(this->GridOrigin);
      image->SetSpacing(this->GridSpacing);
    }
    else if (vtkStructuredGrid* surface = vtkStructuredGrid::SafeDownCast(output))
    {
      surface->Initialize();
      extent[4] = extent[5] = 0;
      surface->SetExtent(extent);
      vtkNew<vtkPoints> points;
      points->SetDataTypeToDouble();
      const int ni = std::max(0, extent[1] - extent[0] + 1), nj = std::max(0, extent[3] - extent[2] + 1);
      points->SetNumberOfPoints(static_cast<vtkIdType>(ni) * nj);
      for (int j = 0; j < nj; ++j)
      {
        for (int i = 0; i < ni; ++i)
        {
          points->SetPoint(static_cast<vtkIdType>(j) * ni + i, origin[0] + (extent[0] + i) * spacing[0],
            origin[1] + (extent[2] + j) * spacing[1], 0.0);
        }
      }
      surface->SetPoints(points);
    }
  }
  const vtkIdType m = output->GetNumberOfPoints();
  std::vector<double> eval(3 * static_cast<size_t>(m));
  vtkIdType nonFinite = 0;
  for (vtkIdType i = 0; i < m; ++i)
  {
    double* x = &eval[3 * i];
    output->GetPoint(i, x);
    if (this->HeightField)
    {
      x[2] = 0.0;
    }
    nonFinite += (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])) ? 0 : 1;
  }

  // Distributed: the halo, every point of the other ranks' pieces the evaluation here reads (in one or two
  // rounds), then the cloud again with it. LS reads nothing but the global sums the first SetCloud made.
  this->HaloPoints = 0;
  meshfree::ApproximationReach reach;
  if (controller)
  {
    approx.Reach(eval.data(), m, reach);
  }
  if (controller && !reach.Global)
  {
    vtkDataArray* inputIds = inPD->GetGlobalIds();
    vtkSmartPointer<vtkPolyData> cloud =
      CloudData(xyz, values, columns, volumes, inputIds && n > 0 ? inputIds : nullptr);
    vtkNew<vtkMeshFreeHalo> halo;
    halo->SetController(controller);
    ExchangeReach(halo, cloud, reach.Queries, reach.K, reach.Radius, reach.KFactor);
    if (reach.SecondLevel)
    {
      // The neighbours' own neighbourhoods (SPH volumes): every point found is a query.
      vtkPoints* found = halo->GetOutput()->GetPoints();
      std::vector<double> queries(3 * static_cast<size_t>(found->GetNumberOfPoints()));
      for (vtkIdType i = 0; i < found->GetNumberOfPoints(); ++i)
      {
        found->GetPoint(i, &queries[3 * i]);
      }
      ExchangeReach(halo, cloud, queries, reach.K2, reach.Radius2, 1.0);
    }
    // Local and halo points ordered by global id (ties break as in the serial run), own points flagged.
    vtkPolyData* extended = halo->GetOutput();
    const vtkIdType total = extended->GetNumberOfPoints();
    const vtkIdType owned = halo->GetNumberOfOwnedPoints();
    std::vector<vtkIdType> order(total);
    std::iota(order.begin(), order.end(), vtkIdType(0));
    const vtkIdType* ids = halo->GetGlobalIds()->GetPointer(0);
    std::stable_sort(order.begin(), order.end(), [ids](vtkIdType a, vtkIdType b) { return ids[a] < ids[b]; });
    vtkDataArray* table = extended->GetPointData()->GetArray("values");
    vtkDataArray* v = extended->GetPointData()->GetArray("volumes");
    std::vector<unsigned char> own(total);
    std::vector<double> xyz2(3 * static_cast<size_t>(total)), values2(static_cast<size_t>(total) * columns);
    std::vector<double> volumes2(useVolumes ? total : 0);
    for (vtkIdType s = 0; s < total; ++s)
    {
      const vtkIdType id = order[s];
      extended->GetPoint(id, &xyz2[3 * s]);
      for (int c = 0; c < columns; ++c)
      {
        values2[static_cast<size_t>(s) * columns + c] = table ? table->GetComponent(id, c) : nan;
      }
      if (useVolumes)
      {
        volumes2[s] = v ? v->GetComponent(id, 0) : nan;
      }
      own[s] = id < owned ? 1 : 0;
    }
    partition.Owned = own.data();
    approx.SetCloud(xyz2.data(), total, values2.data(), columns, useVolumes ? volumes2.data() : nullptr, &partition);
    this->HaloPoints = total - owned;
  }

  const double* cloudBounds = approx.CloudBounds();
  double span = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    span = std::max(span, cloudBounds[2 * a + 1] - cloudBounds[2 * a]);
  }
  vtkIdType outside = 0;
  for (vtkIdType i = 0; i < m; ++i)
  {
    const double* x = &eval[3 * i];
    for (int a = 0; a < 3; ++a)
    {
      if (x[a] < cloudBounds[2 * a] - 0.1 * span || x[a] > cloudBounds[2 * a + 1] + 0.1 * span)
      {
        ++outside;
        break;
      }
    }
  }
  if (nonFinite > 0)
  {
    vtkWarningMacro(<< nonFinite << " of " << m
                    << " output (probe) points have NaN/Inf coordinates: they get NullValue and "
                       "vtkValidPointMask = 0 (their coordinates are the probe's, passed through).");
  }
  if (outside > 0 && valid > 0)
  {
    vtkWarningMacro(<< outside << " of " << m
                    << " output points lie well outside the input's bounds: the values there are extrapolated "
                       "(or masked when no fit reaches them).");
  }

  std::vector<double> results(static_cast<size_t>(m) * columns);
  std::vector<double> gradients(this->ComputeGradients ? 3 * static_cast<size_t>(m) * columns : 0);
  vtkNew<vtkCharArray> mask;
  mask->SetName("vtkValidPointMask");
  mask->SetNumberOfTuples(m);
  std::vector<unsigned char> validOut(m, 0);
  vtkNew<vtkIntArray> counts;
  vtkNew<vtkDoubleArray> conditions;
  std::vector<double> countValues(this->Diagnostics ? m : 0), conditionValues(this->Diagnostics ? m : 0);
  meshfree::ApproximationOutput out;
  out.Values = results.data();
  out.Gradients = this->ComputeGradients ? gradients.data() : nullptr;
  out.Valid = validOut.data();
  out.NeighborCounts = this->Diagnostics ? countValues.data() : nullptr;
  out.Conditions = this->Diagnostics ? conditionValues.data() : nullptr;
  // An image output whose points are origin + index x spacing bit for bit (extent from 0): the evaluation generates
  // them itself (the device MLS on the device, no upload of the points); the results are those at eval.
  meshfree::ImageGeometry lattice;
  bool generated = false;
  vtkImageData* image = vtkImageData::SafeDownCast(output);
  if (image && !this->HeightField && m > 0)
  {
    int ext[6];
    image->GetExtent(ext);
    image->GetOrigin(lattice.Origin);
    image->GetSpacing(lattice.Spacing);
    generated = ext[0] == 0 && ext[2] == 0 && ext[4] == 0;
    for (int a = 0; a < 3; ++a)
    {
      lattice.Dimensions[a] = ext[2 * a + 1] - ext[2 * a] + 1;
    }
    generated = generated && lattice.NumberOfPoints() == static_cast<meshfree::Index>(m);
    for (vtkIdType i = 0; generated && i < m; ++i)
    {
      double x[3];
      meshfree::ImagePoint(lattice, i, x);
      generated = std::memcmp(x, &eval[3 * i], sizeof(x)) == 0;
    }
  }
  const bool done = generated ? approx.EvaluateImage(lattice, out, vtkMeshFreeFilterSupport::Progress(this))
                              : approx.Evaluate(eval.data(), m, out, vtkMeshFreeFilterSupport::Progress(this));
  const meshfree::ApproximationReport& report = approx.Report();
  if (this->Backend == BACKEND_CUDA && !report.BackendNote.empty())
  {
    vtkWarningMacro(<< report.BackendNote);
  }
  if (!done && !report.Aborted && valid > 0)
  {
    vtkWarningMacro("Approximation failed (" << approx.Error()
                                             << "): every output point gets NullValue and vtkValidPointMask = 0.");
  }
  else if (report.Masked > nonFinite && valid > 0 && !report.Aborted)
  {
    vtkWarningMacro(<< report.Masked - nonFinite << " of " << m
                    << " output points could not be evaluated (no input point within the support, or a "
                       "degenerate fit after every fallback): they get NullValue and vtkValidPointMask = 0.");
  }
  if (report.MergedPoints > 0 && (!controller || controller->GetLocalProcessId() == 0))
  {
    vtkWarningMacro(<< report.MergedPoints
                    << " input points coincide with others (closer than 1e-10 of the cloud's diameter): RBF "
                       "merged each group into one point with the mean of their values.");
  }
  if (report.Regularized > 0)
  {
    vtkWarningMacro(<< report.Regularized
                    << " RBF fit(s) were singular or ill-conditioned (condition estimate above 1e14): solved in the "
                       "least-squares sense (near-duplicate points?); the result may not interpolate there.");
  }
  if (report.Widened + report.DegreeLowered > 0)
  {
    vtkDebugMacro(<< report.Widened << " points needed a wider support, " << report.DegreeLowered
                  << " a lower degree.");
  }

  // Wrap the results as VTK arrays.
  vtkPointData* outPD = output->GetPointData();
  for (vtkIdType i = 0; i < m; ++i)
  {
    mask->SetValue(i, static_cast<char>(validOut[i]));
  }
  for (const SelectedArray& s : selected)
  {
    const int nc = s.Components;
    vtkNew<vtkDoubleArray> array;
    array->SetName(s.Name.c_str());
    array->SetNumberOfComponents(nc);
    for (int c = 0; c < nc && s.Array; ++c)
    {
      if (const char* cname = s.Array->GetComponentName(c))
      {
        array->SetComponentName(c, cname);
      }
    }
    array->SetNumberOfTuples(m);
    double* dst = array->GetPointer(0);
    for (vtkIdType i = 0; i < m; ++i)
    {
      std::copy_n(&results[static_cast<size_t>(i) * columns + s.Offset], nc, dst + i * nc);
    }
    outPD->AddArray(array);
    if (this->ComputeGradients)
    {
      vtkNew<vtkDoubleArray> gradient;
      gradient->SetName((s.Name + "_gradient").c_str());
      gradient->SetNumberOfComponents(3 * nc);
      gradient->SetNumberOfTuples(m);
      double* g = gradient->GetPointer(0);
      for (vtkIdType i = 0; i < m; ++i)
      {
        std::copy_n(&gradients[3 * (static_cast<size_t>(i) * columns + s.Offset)], 3 * nc, g + 3 * i * nc);
      }
      outPD->AddArray(gradient);
    }
  }
  if (this->HeightField)
  {
    vtkNew<vtkDoubleArray> z;
    z->SetName("Elevation");
    z->SetNumberOfTuples(m);
    for (vtkIdType i = 0; i < m; ++i)
    {
      z->SetValue(i, results[static_cast<size_t>(i) * columns + elevation]);
    }
    if (this->ComputeGradients)
    {
      vtkNew<vtkDoubleArray> gradient;
      gradient->SetName("Elevation_gradient");
      gradient->SetNumberOfComponents(3);
      gradient->SetNumberOfTuples(m);
      for (vtkIdType i = 0; i < m; ++i)
      {
        gradient->SetTuple(i, &gradients[3 * (static_cast<size_t>(i) * columns + elevation)]);
      }
      outPD->AddArray(gradient);
    }
    outPD->AddArray(z);
    outPD->SetActiveScalars("Elevation");
    vtkPointSet* surface = vtkPointSet::SafeDownCast(output);
    if (surface && surface->GetPoints())
    {
      vtkNew<vtkPoints> moved;
      moved->SetDataTypeToDouble();
      moved->SetNumberOfPoints(m);
      for (vtkIdType i = 0; i < m; ++i)
      {
        moved->SetPoint(i, eval[3 * i], eval[3 * i + 1], z->GetValue(i));
      }
      surface->SetPoints(moved);
    }
    else if (probe)
    {
      vtkWarningMacro("HeightField with a probe that is not a point set: Elevation is added, the points stay.");
    }
  }
  outPD->AddArray(mask);
  if (this->Diagnostics)
  {
    counts->SetName("NeighborCount");
    counts->SetNumberOfTuples(m);
    conditions->SetName("ConditionNumber");
    conditions->SetNumberOfTuples(m);
    for (vtkIdType i = 0; i < m; ++i)
    {
      counts->SetValue(i, static_cast<int>(countValues[i]));
      conditions->SetValue(i, conditionValues[i]);
    }
    outPD->AddArray(counts);
    outPD->AddArray(conditions);
  }
  if (!this->HeightField && !selected.empty() && !probe)
  {
    outPD->SetActiveScalars(selected.front().Name.c_str());
  }
  if (!report.MethodUsed.empty() && (this->Method == RBF || this->Method == AUTO))
  {
    vtkNew<vtkStringArray> chosen;
    chosen->SetName("ApproximationMethod");
    chosen->InsertNextValue(report.MethodUsed);
    output->GetFieldData()->AddArray(chosen);
    vtkNew<vtkStringArray> reason;
    reason->SetName("ApproximationMethodReason");
    reason->InsertNextValue(report.MethodReason);
    output->GetFieldData()->AddArray(reason);
  }
  vtkNew<vtkStringArray> ran;
  ran->SetName("Backend");
  ran->InsertNextValue(report.Backend);
  output->GetFieldData()->AddArray(ran);
  if (controller)
  {
    // How many points of other ranks this rank received (field data `HaloPoints`, distributed runs only).
    vtkMeshFreeFilterSupport::AddFieldValue(
      output->GetFieldData(), "HaloPoints", static_cast<double>(this->HaloPoints));
  }
  return 1;
}

void vtkMeshlessApproximation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Method: " << this->Method << "\n";
  os << indent << "BasisDegree: " << this->BasisDegree << "\n";
  os << indent << "WeightFunction: " << this->WeightFunction << "\n";
  os << indent << "NeighborCount: " << this->NeighborCount << "\n";
  os << indent << "SupportRadius: " << this->SupportRadius << "\n";
  os << indent << "Epsilon: " << this->Epsilon << "\n";
  os << indent << "Center: " << this->Center[0] << ", " << this->Center[1] << ", " << this->Center[2] << "\n";
  os << indent << "ComputeGradients: " << this->ComputeGradients << "\n";
  os << indent << "Diagnostics: " << this->Diagnostics << "\n";
  os << indent << "HeightField: " << this->HeightField << "\n";
  os << indent << "ShepardNormalization: " << this->ShepardNormalization << "\n";
  os << indent << "NullValue: " << this->NullValue << "\n";
  os << indent << "Smoothing: " << this->Smoothing << "\n";
  os << indent << "RBFGlobalLimit: " << this->RBFGlobalLimit << "\n";
  os << indent << "RBFPatchPoints: " << this->RBFPatchPoints << "\n";
  os << indent << "RBFKernel: " << this->RBFKernel << "\n";
  os << indent << "Backend: " << this->Backend << "\n";
  os << indent << "ModelBounds: " << this->ModelBounds[0] << ", " << this->ModelBounds[1] << ", "
     << this->ModelBounds[2] << ", " << this->ModelBounds[3] << ", " << this->ModelBounds[4] << ", "
     << this->ModelBounds[5] << "\n";
  os << indent << "SampleDimensions: " << this->SampleDimensions[0] << ", " << this->SampleDimensions[1] << ", "
     << this->SampleDimensions[2] << "\n";
  os << indent << "PointArrays: " << this->PointArrays.size() << " selected (none = all)\n";
}
