/**
 * @class   vtkMeshFreePointCloudReader
 * @brief   what the MeshFree point-cloud readers share: a file name, the invalid-point policy, no inputs
 *
 * Subclasses (vtkMeshFreePCDReader, vtkMeshFreeXYZReader) parse their format in RequestData, after
 * PrepareOutput has emptied the output and checked that a file name is set.
 */
#ifndef vtkMeshFreePointCloudReader_h
#define vtkMeshFreePointCloudReader_h

#include "MeshFreeReadersModule.h"
#include "vtkPolyDataAlgorithm.h"

class MESHFREEREADERS_EXPORT vtkMeshFreePointCloudReader : public vtkPolyDataAlgorithm
{
public:
  vtkTypeMacro(vtkMeshFreePointCloudReader, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /** The file to read. */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /** Keep the points (rows) whose coordinates are NaN - PCL's invalid-point marker - instead of dropping them
   * (with a warning that counts them). Default off. */
  vtkSetMacro(KeepInvalidPoints, bool);
  vtkGetMacro(KeepInvalidPoints, bool);
  vtkBooleanMacro(KeepInvalidPoints, bool);
  ///@}

protected:
  vtkMeshFreePointCloudReader();
  ~vtkMeshFreePointCloudReader() override;

  /** The emptied output of the request; nullptr, with an error, when no FileName is set. */
  vtkPolyData* PrepareOutput(vtkInformationVector* outputVector);

  char* FileName = nullptr;
  bool KeepInvalidPoints = false;

private:
  vtkMeshFreePointCloudReader(const vtkMeshFreePointCloudReader&) = delete;
  void operator=(const vtkMeshFreePointCloudReader&) = delete;
};

#endif
