#include "vtkMeshFreePointCloudReader.h"

#include "vtkAlgorithm.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

vtkMeshFreePointCloudReader::vtkMeshFreePointCloudReader()
{
  this->SetNumberOfInputPorts(0);
}

vtkMeshFreePointCloudReader::~vtkMeshFreePointCloudReader()
{
  this->SetFileName(nullptr);
}

int vtkMeshFreePointCloudReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  outputVector->GetInformationObject(0)->Set(vtkAlgorithm::CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

void vtkMeshFreePointCloudReader::GetPiece(vtkInformationVector* outputVector, int& piece, int& pieces)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  piece = info->Has(SDDP::UPDATE_PIECE_NUMBER()) ? info->Get(SDDP::UPDATE_PIECE_NUMBER()) : 0;
  pieces = info->Has(SDDP::UPDATE_NUMBER_OF_PIECES()) ? info->Get(SDDP::UPDATE_NUMBER_OF_PIECES()) : 1;
  if (pieces < 1)
  {
    pieces = 1;
  }
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
