#include "vtkMeshlessNormals.h"
#include "vtkMeshFreeFilterSupport.h"

#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMeshFreeHalo.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"

#include "vtkMeshFreePieces.h"

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

  // Under MPI (a piece of several, on several ranks) every rank takes part in every collective call below, with
  // an empty piece too, and every decision that guards one is the same on every rank.
  const bool distributed = vtkMeshFreePieces::IsDistributed(outputVector->GetInformationObject(0));
  vtkMultiProcessController* controller = distributed ? vtkMultiProcessController::GetGlobalController() : nullptr;
  const bool reporter = !distributed || controller->GetLocalProcessId() == 0; // one rank warns about the cloud

  // Validate and gather: coordinates as doubles, the input's Normals as orientation reference.
  const vtkIdType n = input->GetNumberOfPoints();
  const vtkIdType total = vtkMeshFreeHalo::GlobalSum(controller, n);
  vtkDataArray* inputNormals = input->GetPointData()->GetArray(kNormals);
  if (inputNormals && inputNormals->GetNumberOfComponents() != 3)
  {
    vtkWarningMacro("The input's point array Normals has " << inputNormals->GetNumberOfComponents()
                                                           << " components, not 3: it is not used.");
    inputNormals = nullptr;
  }
  bool haveNormals = inputNormals != nullptr;
  if (distributed)
  {
    // Used when every rank with points has them (all ranks' pieces empty: when any rank has them).
    const bool some = vtkMeshFreeHalo::GlobalMax(controller, (n > 0 || total == 0) && inputNormals ? 1.0 : 0.0) > 0;
    const bool lacking = vtkMeshFreeHalo::GlobalMax(controller, n > 0 && !inputNormals ? 1.0 : 0.0) > 0;
    if (some && lacking && reporter)
    {
      vtkWarningMacro("Some ranks' pieces have a 3-component point array Normals and others do not: it is not used.");
    }
    haveNormals = some && !lacking;
  }
  if (this->Orientation == INPUT_NORMALS && !haveNormals)
  {
    // Returning 1 keeps the executive from adding its own error: one clear message, an empty output.
    vtkErrorMacro("Orientation InputNormals needs a 3-component point array Normals on the input; the output is "
                  "empty.");
    return 1;
  }
  const bool useReference = haveNormals && (this->Orientation == AUTO || this->Orientation == INPUT_NORMALS);
  const int width = useReference ? 6 : 3;
  std::vector<double> rows(static_cast<size_t>(width) * n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    input->GetPoint(i, &rows[static_cast<size_t>(width) * i]);
    if (useReference)
    {
      inputNormals->GetTuple(i, &rows[static_cast<size_t>(width) * i + 3]);
    }
  }
  // Distributed: the whole cloud on every rank, in global id order (the orientation is global; see the class doc).
  const vtkMeshFreePieces::GatheredCloud cloud = vtkMeshFreePieces::GatherCloud(controller, input, rows, width);
  rows.clear();
  const vtkIdType count = cloud.Count;
  std::vector<double> xyz(3 * static_cast<size_t>(count));
  std::vector<double> reference(useReference ? 3 * static_cast<size_t>(count) : 0);
  for (vtkIdType i = 0; i < count; ++i)
  {
    std::copy_n(&cloud.Rows[static_cast<size_t>(width) * i], 3, &xyz[3 * i]);
    if (useReference)
    {
      std::copy_n(&cloud.Rows[static_cast<size_t>(width) * i + 3], 3, &reference[3 * i]);
    }
  }
  output->ShallowCopy(input);
  if (count == 0 && reporter)
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
  const bool done = meshfree::ComputeCloudNormals(xyz.data(), count, useReference ? reference.data() : nullptr,
    options, result, vtkMeshFreeFilterSupport::Progress(this));
  if (!done || result.Aborted)
  {
    output->Initialize();
    vtkWarningMacro("Aborted: the output is empty.");
    return 1;
  }
  if (result.Invalid > 0 && reporter)
  {
    vtkWarningMacro(<< result.Invalid << " of " << count
                    << " points have no normal (NaN/Inf coordinates, or fewer than 3 non-collinear neighbours): "
                       "their arrays are 0 and vtkValidPointMask is 0.");
  }
  vtkDebugMacro("Orientation " << OrientationName(this->Orientation) << ": " << result.Orientation.Components
                               << " connected pieces, " << result.Orientation.FlippedComponents << " turned, "
                               << result.Orientation.Ambiguous << " ambiguous points; " << result.Projected
                               << " points projected; " << result.Outliers << " outliers left out of the fits, "
                               << result.Duplicates << " exact duplicates merged.");

  // Wrap the results of this rank's own points (all of them when not distributed).
  const std::vector<vtkIdType>& own = cloud.Own;
  auto ownArray = [&own, n](const char* name, int components, const std::vector<double>& values) {
    auto array = vtkSmartPointer<vtkDoubleArray>::New();
    array->SetName(name);
    array->SetNumberOfComponents(components);
    array->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      std::copy_n(&values[static_cast<size_t>(own[i]) * components], components, array->GetPointer(components * i));
    }
    return array;
  };
  if (this->ProjectPoints && n > 0)
  {
    vtkNew<vtkPoints> moved;
    moved->SetDataType(input->GetPoints()->GetDataType());
    moved->SetNumberOfPoints(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      moved->SetPoint(i, &result.Points[3 * own[i]]);
    }
    output->SetPoints(moved);
  }
  vtkPointData* pd = output->GetPointData();
  pd->SetNormals(ownArray(kNormals, 3, result.Normals));
  if (this->ComputeCurvature)
  {
    pd->AddArray(ownArray("Curvature", 1, result.Curvature));
  }
  pd->AddArray(ownArray("SurfaceVariation", 1, result.SurfaceVariation));
  pd->AddArray(ownArray("OrientationConfidence", 1, result.Confidence));
  vtkNew<vtkCharArray> mask;
  mask->SetName("vtkValidPointMask");
  mask->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    mask->SetValue(i, static_cast<char>(result.Valid[own[i]] ? 1 : 0));
  }
  pd->AddArray(mask);
  pd->SetActiveScalars(this->ComputeCurvature ? "Curvature" : "OrientationConfidence");

  // Field data: of the whole cloud, the same on every rank.
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
