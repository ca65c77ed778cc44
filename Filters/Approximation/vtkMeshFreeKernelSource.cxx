#include "vtkMeshFreeKernelSource.h"

#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "Common/Kernels.h"

#include <cmath>
#include <stdexcept>

vtkStandardNewMacro(vtkMeshFreeKernelSource);

vtkMeshFreeKernelSource::vtkMeshFreeKernelSource()
{
  this->SetNumberOfInputPorts(0);
}

namespace
{
void PlaneGeometry(double h, int resolution, double origin[3], double spacing[3])
{
  const double halfWidth = 1.2 * h;
  origin[0] = origin[1] = -halfWidth;
  origin[2] = 0.0;
  spacing[0] = spacing[1] = 2.0 * halfWidth / (resolution - 1);
  spacing[2] = 1.0;
}
}

int vtkMeshFreeKernelSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  double origin[3], spacing[3];
  PlaneGeometry(this->SupportRadius, this->Resolution, origin, spacing);
  int extent[6] = { 0, this->Resolution - 1, 0, this->Resolution - 1, 0, 0 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  return 1;
}

int vtkMeshFreeKernelSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector);
  double origin[3], spacing[3];
  PlaneGeometry(this->SupportRadius, this->Resolution, origin, spacing);
  output->SetDimensions(this->Resolution, this->Resolution, 1);
  output->SetOrigin(origin);
  output->SetSpacing(spacing);

  meshfree::Kernel kernel;
  try
  {
    kernel = meshfree::Kernel(static_cast<meshfree::KernelType>(this->Kernel), this->Dimension,
      this->SupportRadius, this->Epsilon);
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("Invalid kernel settings: " << e.what());
    return 0;
  }

  const vtkIdType n = output->GetNumberOfPoints();
  vtkNew<vtkDoubleArray> value;
  value->SetName("Value");
  value->SetNumberOfTuples(n);
  vtkNew<vtkDoubleArray> gradient;
  gradient->SetName("Gradient");
  gradient->SetNumberOfComponents(3);
  gradient->SetNumberOfTuples(n);
  vtkNew<vtkDoubleArray> laplacian;
  laplacian->SetName("Laplacian");
  laplacian->SetNumberOfTuples(n);

  for (vtkIdType i = 0; i < n; ++i)
  {
    double x[3];
    output->GetPoint(i, x);
    if (this->Dimension == 1)
    {
      x[1] = 0.0; // 1D kernel: only the x axis counts; the plane shows it extruded along y
    }
    x[2] = 0.0;
    const double r = std::sqrt(x[0] * x[0] + x[1] * x[1]);
    double g[3];
    kernel.Gradient(x, g);
    value->SetValue(i, kernel.Value(r));
    gradient->SetTuple(i, g);
    laplacian->SetValue(i, kernel.Laplacian(r));
  }
  // A tiny support or epsilon can push the Laplacian (1/h^(d+2), 1/eps^4) past double's range at the centre:
  // such values are clamped to +-VTK_DOUBLE_MAX, never Inf or NaN.
  vtkIdType clamped = 0;
  for (vtkDataArray* array : { static_cast<vtkDataArray*>(value), static_cast<vtkDataArray*>(gradient),
         static_cast<vtkDataArray*>(laplacian) })
  {
    double* v = static_cast<vtkDoubleArray*>(array)->GetPointer(0);
    const vtkIdType count = array->GetNumberOfValues();
    for (vtkIdType i = 0; i < count; ++i)
    {
      if (!std::isfinite(v[i]))
      {
        v[i] = std::isnan(v[i]) ? 0.0 : std::copysign(VTK_DOUBLE_MAX, v[i]);
        ++clamped;
      }
    }
  }
  if (clamped > 0)
  {
    vtkWarningMacro(<< clamped << " kernel values overflow double (support radius " << this->SupportRadius
                    << ", epsilon " << this->Epsilon << "): they are clamped to +-VTK_DOUBLE_MAX.");
  }
  output->GetPointData()->AddArray(value);
  output->GetPointData()->AddArray(gradient);
  output->GetPointData()->AddArray(laplacian);
  output->GetPointData()->SetActiveScalars("Value");
  return 1;
}

void vtkMeshFreeKernelSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Kernel: " << this->Kernel << "\n";
  os << indent << "Dimension: " << this->Dimension << "\n";
  os << indent << "SupportRadius: " << this->SupportRadius << "\n";
  os << indent << "Epsilon: " << this->Epsilon << "\n";
  os << indent << "Resolution: " << this->Resolution << "\n";
}
