/**
 * @class   vtkMeshFreePCDWriter
 * @brief   writes a point set as a Point Cloud Library .pcd file (v0.7: ascii, binary, binary_compressed)
 *
 * The points become the fields x y z (4-byte floats when the points are float, else 8-byte). Every numeric
 * point array becomes a field named like the array (white space replaced by '_'), of the array's type, with
 * COUNT = its number of components. An unsigned-char array named `rgb` (3 components) or `rgba` (4) is
 * written as PCL's packed colour field, so clouds read by vtkMeshFreePCDReader round-trip to PCL.
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

protected:
  vtkMeshFreePCDWriter();
  ~vtkMeshFreePCDWriter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  void WriteData() override;

  char* FileName = nullptr;
  int Encoding = BINARY;

private:
  vtkMeshFreePCDWriter(const vtkMeshFreePCDWriter&) = delete;
  void operator=(const vtkMeshFreePCDWriter&) = delete;
};

#endif
