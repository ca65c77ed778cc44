/**
 * @class   vtkMeshFreePointCloudReader
 * @brief   what the MeshFree point-cloud readers share: a file name, the invalid-point policy, no inputs
 *
 * Subclasses (vtkMeshFreePCDReader, vtkMeshFreeXYZReader) parse their format in RequestData, after
 * PrepareOutput has emptied the output and checked that a file name is set.
 *
 * Pieces: RequestInformation sets CAN_HANDLE_PIECE_REQUEST, so that under MPI every rank runs RequestData for its
 * piece (UPDATE_PIECE_NUMBER of UPDATE_NUMBER_OF_PIECES, see GetPiece) and reads only its contiguous share of the
 * points, in file order: the pieces concatenated in rank order are the serial output (same points, arrays and
 * order), an empty piece has the same arrays with no tuples. The readers do no communication: every rank reads the
 * header itself, and a file that is wrong in its header, sizes or counts gives the same error on every rank.
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

  /** Announces that the readers answer piece requests (CAN_HANDLE_PIECE_REQUEST). */
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  /** The emptied output of the request; nullptr, with an error, when no FileName is set. */
  vtkPolyData* PrepareOutput(vtkInformationVector* outputVector);

  /** The piece asked for (UPDATE_PIECE_NUMBER, 0 when unset) and the number of pieces (1 when unset). */
  static void GetPiece(vtkInformationVector* outputVector, int& piece, int& pieces);

  char* FileName = nullptr;
  bool KeepInvalidPoints = false;

private:
  vtkMeshFreePointCloudReader(const vtkMeshFreePointCloudReader&) = delete;
  void operator=(const vtkMeshFreePointCloudReader&) = delete;
};

#endif
