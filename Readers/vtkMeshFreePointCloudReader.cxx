#include "vtkMeshFreePointCloudReader.h"

#include "vtkPolyData.h"

vtkMeshFreePointCloudReader::vtkMeshFreePointCloudReader()
{
  this->SetNumberOfInputPorts(0);
}

vtkMeshFreePointCloudReader::~vtkMeshFreePointCloudReader()
{
  this->SetFileName(nullptr);
}

vtkPolyData* vtkMeshFreePointCloudReader::PrepareOutput(vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  output->Initialize();
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("No FileName given.");
    return nullptr;
  }
  return output;
}

void vtkMeshFreePointCloudReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "KeepInvalidPoints: " << (this->KeepInvalidPoints ? "On" : "Off") << "\n";
}
