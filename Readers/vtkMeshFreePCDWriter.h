/**
 * @class   vtkMeshFreePCDWriter
 * @brief   writes a point set as a Point Cloud Library .pcd file (v0.7: ascii, binary, binary_compressed)
 *
 * The points become the fields x y z as 4-byte floats, the format's convention that PCL's point types and
 * tools read (a warning says when that moves points by more than 1e-5 of the cloud's size);
 * WriteDoubleCoordinates keeps double points as 8-byte fields, which most PCL tools cannot read. The normals
 * (the active point normals, or a 3-component array named `Normals`) become PCL's normal_x normal_y normal_z
 * (floats; doubles too with WriteDoubleCoordinates). Every other numeric point array becomes a field named
 * like the array (white space replaced by '_'), of the array's type, with COUNT = its number of components.
 * An unsigned-char array named `rgb` (3 components) or `rgba` (4) is written as PCL's packed colour field,
 * so clouds read by vtkMeshFreePCDReader round-trip to PCL.
 * Field data `Viewpoint` (7 values) and `OrganizedDimensions` (WIDTH, HEIGHT, when their product is the
 * number of points) go into the header. binary_compressed is LZF, as PCL writes it.
 *
 * @sa vtkMeshFreePCDReader
 */
#ifndef vtkMeshFreePCDWriter_h
#define vtkMeshFreePCDWriter_h

#include "MeshFreeReadersModule.h"
#include "vtkWriter.h"

class vtkPointSet;

class MESHFREEREADERS_EXPORT vtkMeshFreePCDWriter : public vtkWriter
{
public:
  static vtkMeshFreePCDWriter* New();
  vtkTypeMacro(vtkMeshFreePCDWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum
  {
    ASCII = 0,
    BINARY = 1,
    BINARY_COMPRESSED = 2
  };

  ///@{
  /** The .pcd file to write. */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /** DATA encoding: 0 ascii, 1 binary (default), 2 binary_compressed (LZF). */
  vtkSetClampMacro(Encoding, int, ASCII, BINARY_COMPRESSED);
  vtkGetMacro(Encoding, int);
  void SetEncodingToAscii() { this->SetEncoding(ASCII); }
  void SetEncodingToBinary() { this->SetEncoding(BINARY); }
  void SetEncodingToBinaryCompressed() { this->SetEncoding(BINARY_COMPRESSED); }
  ///@}

  ///@{
  /**
   * Off (default): x y z (and the normals) are written as 4-byte floats, what PCL's tools read. On: double
   * points (and double normals) are written as 8-byte doubles, for clouds far from the origin whose
   * coordinates floats cannot hold; vtkMeshFreePCDReader reads them back exactly, but most PCL tools misread
   * or refuse them (PCL's point types hold floats).
   */
  vtkSetMacro(WriteDoubleCoordinates, vtkTypeBool);
  vtkGetMacro(WriteDoubleCoordinates, vtkTypeBool);
  vtkBooleanMacro(WriteDoubleCoordinates, vtkTypeBool);
  ///@}

protected:
  vtkMeshFreePCDWriter();
  ~vtkMeshFreePCDWriter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  void WriteData() override;

  char* FileName = nullptr;
  int Encoding = BINARY;
  vtkTypeBool WriteDoubleCoordinates = false;

private:
  vtkMeshFreePCDWriter(const vtkMeshFreePCDWriter&) = delete;
  void operator=(const vtkMeshFreePCDWriter&) = delete;
};

#endif
