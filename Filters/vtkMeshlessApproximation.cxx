#include "vtkMeshlessApproximation.h"
#include "vtkMeshFreeFilterSupport.h"

#include "vtkAlgorithmOutput.h"
#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"

#include "Approximation/Approximation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMeshlessApproximation);

vtkMeshlessApproximation::vtkMeshlessApproximation()
{
  this->SetNumberOfInputPorts(2);
  const double nan = vtkMath::Nan();
  this->Center[0] = this->Center[1] = this->Center[2] = nan;
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
  vtkInformationVector** inputVector, double origin[3], double spacing[3], int dims[3])
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  double bounds[6] = { 0, 0, 0, 0, 0, 0 };
  const bool userBounds = this->ModelBounds[0] < this->ModelBounds[1] ||
    this->ModelBounds[2] < this->ModelBounds[3] || this->ModelBounds[4] < this->ModelBounds[5];
  if (userBounds)
  {
    std::copy(this->ModelBounds, this->ModelBounds + 6, bounds);
  }
  else if (input && input->GetNumberOfPoints() > 0)
  {
    // The bounds of the finite points (vtkPoints::GetBounds skips NaN but not Inf, and one Inf point
    // would collapse an axis of the grid).
    bool any = false;
    for (vtkIdType i = 0; i < input->GetNumberOfPoints(); ++i)
    {
      double x[3];
      input->GetPoint(i, x);
      if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
      {
        continue;
      }
      for (int a = 0; a < 3; ++a)
      {
        bounds[2 * a] = any ? std::min(bounds[2 * a], x[a]) : x[a];
        bounds[2 * a + 1] = any ? std::max(bounds[2 * a + 1], x[a]) : x[a];
      }
      any = true;
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
  // now (the cloud is needed whole anyway), so that the whole extent announced here is the one produced.
  if (this->GetNumberOfInputConnections(0) > 0)
  {
    vtkAlgorithmOutput* connection = this->GetInputConnection(0, 0);
    connection->GetProducer()->Update(connection->GetIndex());
  }
  double origin[3], spacing[3];
  int dims[3];
  this->GridGeometry(inputVector, origin, spacing, dims);
  const int extent[6] = { 0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
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
  // The whole cloud is needed at every output point; the probe follows the downstream request.
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  if (inInfo)
  {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  }
  vtkInformation* probeInfo = inputVector[1]->GetInformationObject(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
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
struct SelectedArray
{
  vtkDataArray* Array;
  int Offset;
};
}

int vtkMeshlessApproximation::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  vtkDataSet* probe = this->GetNumberOfInputConnections(1) > 0 ? vtkDataSet::GetData(inputVector[1], 0) : nullptr;
  vtkDataSet* output = vtkDataSet::GetData(outputVector, 0);
  if (!input || !output)
  {
    vtkErrorMacro("Missing input point set or output.");
    return 0;
  }
  const vtkIdType n = input->GetNumberOfPoints();
  if (n == 0)
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
    selected.push_back({ array, components });
    components += array->GetNumberOfComponents();
  }
  for (const std::string& name : this->PointArrays)
  {
    if (!inPD->GetArray(name.c_str()))
    {
      vtkWarningMacro("PointArrays names '" << name << "', which is not a numeric point array of the input.");
    }
  }
  const int elevation = this->HeightField ? components : -1;
  const int columns = components + (this->HeightField ? 1 : 0);
  std::vector<double> xyz(3 * static_cast<size_t>(n)), values(static_cast<size_t>(n) * columns);
  for (vtkIdType i = 0; i < n; ++i)
  {
    double* x = &xyz[3 * i];
    input->GetPoint(i, x);
    double* row = &values[static_cast<size_t>(i) * columns];
    for (const SelectedArray& s : selected)
    {
      for (int c = 0; c < s.Array->GetNumberOfComponents(); ++c)
      {
        row[s.Offset + c] = s.Array->GetComponent(i, c);
      }
    }
    if (this->HeightField)
    {
      row[elevation] = x[2]; // z = f(x, y): z is the data, the fit is in the x-y plane
      x[2] = 0.0;
    }
  }
  // SPH volumes m/rho when the cloud carries Mass and Density (as the SPH Fluid source writes).
  std::vector<double> volumes;
  vtkDataArray* mass = inPD->GetArray("Mass");
  vtkDataArray* density = inPD->GetArray("Density");
  if (this->Method == SPH && mass && density && mass->GetNumberOfComponents() == 1 &&
    density->GetNumberOfComponents() == 1)
  {
    volumes.resize(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      volumes[i] = mass->GetComponent(i, 0) / density->GetComponent(i, 0);
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
  if (!std::isfinite(this->NullValue))
  {
    vtkWarningMacro("NullValue " << this->NullValue << " is not a finite number: masked points get 0 instead.");
    opts.NullValue = 0.0;
  }
  meshfree::Approximator approx;
  if (!approx.SetOptions(opts))
  {
    vtkErrorMacro("Invalid settings: " << approx.Error());
    return 0;
  }
  approx.SetCloud(xyz.data(), n, values.data(), columns, volumes.empty() ? nullptr : volumes.data());
  const meshfree::ApproximationReport& cloud = approx.Report();
  if (cloud.ExcludedPoints > 0)
  {
    vtkWarningMacro(<< cloud.ExcludedPoints << " of " << n
                    << " input points have NaN/Inf coordinates or values (or a non-positive SPH volume): "
                       "they are ignored.");
  }
  const vtkIdType valid = n - cloud.ExcludedPoints;
  if (valid > 0 && this->SupportRadius <= 0 && this->NeighborCount > valid && this->Method != LS)
  {
    vtkWarningMacro("NeighborCount (" << this->NeighborCount << ") exceeds the " << valid
                                      << " valid input points: all of them are used.");
  }

  // The output's geometry: the probe, or the grid.
  double origin[3], spacing[3];
  int dims[3];
  if (probe)
  {
    output->ShallowCopy(probe);
  }
  else
  {
    this->GridGeometry(inputVector, origin, spacing, dims);
    if (vtkImageData* image = vtkImageData::SafeDownCast(output))
    {
      image->Initialize();
      image->SetDimensions(dims);
      image->SetOrigin(origin);
      image->SetSpacing(spacing);
    }
    else if (vtkStructuredGrid* surface = vtkStructuredGrid::SafeDownCast(output))
    {
      surface->Initialize();
      surface->SetDimensions(dims[0], dims[1], 1);
      vtkNew<vtkPoints> points;
      points->SetDataTypeToDouble();
      points->SetNumberOfPoints(static_cast<vtkIdType>(dims[0]) * dims[1]);
      for (int j = 0; j < dims[1]; ++j)
      {
        for (int i = 0; i < dims[0]; ++i)
        {
          points->SetPoint(static_cast<vtkIdType>(j) * dims[0] + i, origin[0] + i * spacing[0],
            origin[1] + j * spacing[1], 0.0);
        }
      }
      surface->SetPoints(points);
    }
  }
  const vtkIdType m = output->GetNumberOfPoints();
  std::vector<double> eval(3 * static_cast<size_t>(m));
  double cloudBounds[6];
  approx.Grid().GetBounds(cloudBounds);
  double span = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    span = std::max(span, cloudBounds[2 * a + 1] - cloudBounds[2 * a]);
  }
  vtkIdType outside = 0, nonFinite = 0;
  for (vtkIdType i = 0; i < m; ++i)
  {
    double* x = &eval[3 * i];
    output->GetPoint(i, x);
    if (this->HeightField)
    {
      x[2] = 0.0;
    }
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
    {
      ++nonFinite; // masked by the evaluation
      continue;
    }
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
  const bool done = approx.Evaluate(eval.data(), m, out, vtkMeshFreeFilterSupport::Progress(this));
  const meshfree::ApproximationReport& report = approx.Report();
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
    const int nc = s.Array->GetNumberOfComponents();
    vtkNew<vtkDoubleArray> array;
    array->SetName(s.Array->GetName());
    array->SetNumberOfComponents(nc);
    for (int c = 0; c < nc; ++c)
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
      gradient->SetName((std::string(s.Array->GetName()) + "_gradient").c_str());
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
    outPD->SetActiveScalars(selected.front().Array->GetName());
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
  os << indent << "ModelBounds: " << this->ModelBounds[0] << ", " << this->ModelBounds[1] << ", "
     << this->ModelBounds[2] << ", " << this->ModelBounds[3] << ", " << this->ModelBounds[4] << ", "
     << this->ModelBounds[5] << "\n";
  os << indent << "SampleDimensions: " << this->SampleDimensions[0] << ", " << this->SampleDimensions[1] << ", "
     << this->SampleDimensions[2] << "\n";
  os << indent << "PointArrays: " << this->PointArrays.size() << " selected (none = all)\n";
}
