#include "vtkMeshlessNormals.h"
#include "vtkMeshFreeFilterSupport.h"

#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"

#include "Common/Statistics.h"
#include "Surface/CloudNormals.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkMeshlessNormals);

namespace
{
const char* const kNormals = "Normals";

const char* OrientationName(int orientation)
{
  static const char* const names[] = { "Auto", "Propagation", "Viewpoint", "InputNormals" };
  return orientation >= 0 && orientation < 4 ? names[orientation] : "?";
}

/// A named double array of n tuples copied from values.
vtkSmartPointer<vtkDoubleArray> NewArray(const char* name, int components, const double* values, vtkIdType n)
{
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name);
  array->SetNumberOfComponents(components);
  array->SetNumberOfTuples(n);
  if (n > 0)
  {
    std::copy_n(values, static_cast<size_t>(n) * components, array->GetPointer(0));
  }
  return array;
}

/// Median of the values whose mask is set (0 when none is).
double MaskedMedian(const std::vector<double>& values, const std::vector<unsigned char>& mask)
{
  std::vector<double> kept;
  for (size_t i = 0; i < values.size() && i < mask.size(); ++i)
  {
    if (mask[i])
    {
      kept.push_back(values[i]);
    }
  }
  return meshfree::Median(std::move(kept));
}
} // namespace

vtkMeshlessNormals::vtkMeshlessNormals() = default;

int vtkMeshlessNormals::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  vtkPointSet* output = vtkPointSet::GetData(outputVector, 0);
  if (!input || !output)
  {
    vtkErrorMacro("Missing input or output point set.");
    return 0;
  }
  output->Initialize();

  // Validate and gather: coordinates as doubles, the input's Normals as orientation reference.
  const vtkIdType n = input->GetNumberOfPoints();
  std::vector<double> xyz(3 * static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    input->GetPoint(i, &xyz[3 * i]);
  }
  std::vector<double> reference;
  vtkDataArray* inputNormals = input->GetPointData()->GetArray(kNormals);
  if (inputNormals && inputNormals->GetNumberOfComponents() != 3)
  {
    vtkWarningMacro("The input's point array Normals has " << inputNormals->GetNumberOfComponents()
                                                           << " components, not 3: it is not used.");
    inputNormals = nullptr;
  }
  if (this->Orientation == INPUT_NORMALS && !inputNormals)
  {
    // Returning 1 keeps the executive from adding its own error: one clear message, an empty output.
    vtkErrorMacro("Orientation InputNormals needs a 3-component point array Normals on the input; the output is "
                  "empty.");
    return 1;
  }
  const bool useReference = inputNormals && (this->Orientation == AUTO || this->Orientation == INPUT_NORMALS);
  if (useReference)
  {
    reference.resize(3 * static_cast<size_t>(n));
    for (vtkIdType i = 0; i < n; ++i)
    {
      inputNormals->GetTuple(i, &reference[3 * i]);
    }
  }
  output->ShallowCopy(input);
  if (n == 0)
  {
    vtkWarningMacro("The input has no points: nothing to compute.");
  }

  // Compute.
  meshfree::CloudNormalsOptions options;
  options.Neighborhood.NeighborCount = this->NeighborCount;
  options.Neighborhood.SupportRadius = this->SupportRadius;
  options.Orientation = useReference ? meshfree::OrientationMode::Reference
    : this->Orientation == VIEWPOINT ? meshfree::OrientationMode::Viewpoint
                                     : meshfree::OrientationMode::Propagation;
  std::copy(this->Viewpoint, this->Viewpoint + 3, options.Viewpoint);
  options.ComputeCurvature = this->ComputeCurvature;
  options.ProjectPoints = this->ProjectPoints;
  options.ProjectionIterations = this->ProjectionIterations;
  meshfree::CloudNormalsResult result;
  const bool done = meshfree::ComputeCloudNormals(xyz.data(), n, useReference ? reference.data() : nullptr,
    options, result, vtkMeshFreeFilterSupport::Progress(this));
  if (!done || result.Aborted)
  {
    output->Initialize();
    vtkWarningMacro("Aborted: the output is empty.");
    return 1;
  }
  if (result.Invalid > 0)
  {
    vtkWarningMacro(<< result.Invalid << " of " << n
                    << " points have no normal (NaN/Inf coordinates, or fewer than 3 non-collinear neighbours): "
                       "their arrays are 0 and vtkValidPointMask is 0.");
  }
  vtkDebugMacro("Orientation " << OrientationName(this->Orientation) << ": " << result.Orientation.Components
                               << " connected pieces, " << result.Orientation.FlippedComponents << " turned, "
                               << result.Orientation.Ambiguous << " ambiguous points; " << result.Projected
                               << " points projected; " << result.Outliers << " outliers left out of the fits, "
                               << result.Duplicates << " exact duplicates merged.");

  // Wrap the results.
  if (this->ProjectPoints && n > 0)
  {
    vtkNew<vtkPoints> moved;
    moved->SetDataType(input->GetPoints()->GetDataType());
    moved->SetNumberOfPoints(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      moved->SetPoint(i, &result.Points[3 * i]);
    }
    output->SetPoints(moved);
  }
  vtkPointData* pd = output->GetPointData();
  pd->SetNormals(NewArray(kNormals, 3, result.Normals.data(), n));
  if (this->ComputeCurvature)
  {
    pd->AddArray(NewArray("Curvature", 1, result.Curvature.data(), n));
  }
  pd->AddArray(NewArray("SurfaceVariation", 1, result.SurfaceVariation.data(), n));
  pd->AddArray(NewArray("OrientationConfidence", 1, result.Confidence.data(), n));
  vtkNew<vtkCharArray> mask;
  mask->SetName("vtkValidPointMask");
  mask->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    mask->SetValue(i, static_cast<char>(result.Valid[i] ? 1 : 0));
  }
  pd->AddArray(mask);
  pd->SetActiveScalars(this->ComputeCurvature ? "Curvature" : "OrientationConfidence");

  vtkFieldData* fd = output->GetFieldData();
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "NoiseEstimate", result.Scale.Noise);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "SupportRadius", MaskedMedian(result.Radius, result.Valid));
  vtkNew<vtkIdTypeArray> ambiguous;
  ambiguous->SetName("AmbiguousOrientations");
  ambiguous->InsertNextValue(static_cast<vtkIdType>(result.Orientation.Ambiguous));
  fd->AddArray(ambiguous);
  return 1;
}

void vtkMeshlessNormals::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NeighborCount: " << this->NeighborCount << "\n";
  os << indent << "SupportRadius: " << this->SupportRadius << "\n";
  os << indent << "Orientation: " << OrientationName(this->Orientation) << "\n";
  os << indent << "Viewpoint: " << this->Viewpoint[0] << ", " << this->Viewpoint[1] << ", " << this->Viewpoint[2]
     << "\n";
  os << indent << "ComputeCurvature: " << this->ComputeCurvature << "\n";
  os << indent << "ProjectPoints: " << this->ProjectPoints << "\n";
  os << indent << "ProjectionIterations: " << this->ProjectionIterations << "\n";
}
