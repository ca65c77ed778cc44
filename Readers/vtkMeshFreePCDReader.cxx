#include "vtkMeshFreePCDReader.h"

#include "PCDFormat.h"
#include "ReaderHelpers.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <cstring>
#include <set>
#include <string>

vtkStandardNewMacro(vtkMeshFreePCDReader);

namespace
{
int VTKType(const meshfree::pcd::Field& f)
{
  switch (f.Type)
  {
    case 'F':
      return f.Size == 4 ? VTK_FLOAT : VTK_DOUBLE;
    case 'I':
      return f.Size == 1 ? VTK_SIGNED_CHAR : f.Size == 2 ? VTK_SHORT : f.Size == 4 ? VTK_INT : VTK_LONG_LONG;
    default:
      return f.Size == 1 ? VTK_UNSIGNED_CHAR
        : f.Size == 2    ? VTK_UNSIGNED_SHORT
        : f.Size == 4    ? VTK_UNSIGNED_INT
                         : VTK_UNSIGNED_LONG_LONG;
  }
}

double ValueAsDouble(const meshfree::pcd::Field& f, const unsigned char* p)
{
  if (f.Type == 'F')
  {
    if (f.Size == 4)
    {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    double v;
    std::memcpy(&v, p, 8);
    return v;
  }
  // Integer coordinates are rare; go through the widest type of the field's signedness.
  if (f.Type == 'I')
  {
    long long v = 0;
    switch (f.Size)
    {
      case 1: { std::int8_t x; std::memcpy(&x, p, 1); v = x; break; }
      case 2: { std::int16_t x; std::memcpy(&x, p, 2); v = x; break; }
      case 4: { std::int32_t x; std::memcpy(&x, p, 4); v = x; break; }
      default: std::memcpy(&v, p, 8);
    }
    return static_cast<double>(v);
  }
  unsigned long long v = 0;
  std::memcpy(&v, p, f.Size); // little endian: the low bytes
  return static_cast<double>(v);
}

bool IsPackedColor(const meshfree::pcd::Field& f)
{
  return f.Size == 4 && f.Count == 1 && (f.Type == 'F' || f.Type == 'U') &&
    (f.Name == "rgb" || f.Name == "rgba");
}
} // namespace

int vtkMeshFreePCDReader::CanReadFile(const char* filename)
{
  std::string start;
  if (!meshfree::ReadFileStart(filename, 64 * 1024, start))
    return 0;
  meshfree::pcd::Header header;
  std::string error;
  return meshfree::pcd::ParseHeader(start.data(), start.size(), header, error) ? 1 : 0;
}

int vtkMeshFreePCDReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = this->PrepareOutput(outputVector);
  if (!output)
  {
    return 1;
  }
  namespace pcd = meshfree::pcd;
  pcd::Cloud cloud;
  std::string error;
  pcd::PieceRequest request;
  this->GetPiece(outputVector, request.Piece, request.Pieces);
  // An organised cloud's PixelIndex is there when any point of the file was dropped: a piece must know about the
  // others' points too.
  request.FindInvalid = !this->KeepInvalidPoints;
  const bool ok = request.Pieces > 1 ? pcd::ReadPiece(this->FileName, request, cloud, error, /*interleaveXYZ=*/true)
                                     : pcd::ReadFile(this->FileName, cloud, error, /*interleaveXYZ=*/true);
  if (!ok)
  {
    vtkErrorMacro("Cannot read '" << this->FileName << "': " << error);
    return 1;
  }
  this->UpdateProgress(0.5);
  const pcd::Header& head = cloud.Head;
  const std::uint64_t fileWidth = head.Width, fileHeight = head.Height, piecePoints = head.Points;
  std::vector<std::uint64_t> kept;
  if (!this->KeepInvalidPoints)
  {
    const std::uint64_t dropped = pcd::DropInvalidPoints(cloud, &kept);
    if (dropped > 0)
    {
      vtkWarningMacro("'" << this->FileName << "': dropped " << dropped << " of " << piecePoints
                          << (request.Pieces > 1 ? " points of this piece" : " points")
                          << " whose x, y or z is NaN (invalid points); switch KeepInvalidPoints on to keep them.");
    }
  }
  const vtkIdType n = static_cast<vtkIdType>(cloud.Head.Points);

  // Points: the interleaved x y z the core decoded (adopted, no copy) when x, y, z share one floating
  // type; otherwise assembled here in double precision (missing coordinates are 0).
  int coord[3] = { -1, -1, -1 };
  for (std::size_t c = 0; c < cloud.Columns.size(); ++c)
  {
    const pcd::Field& f = head.Fields[cloud.ColumnField[c]];
    for (int k = 0; k < 3; ++k)
      if (coord[k] < 0 && f.Count == 1 && f.Name == std::string(1, "xyz"[k]))
        coord[k] = static_cast<int>(c);
  }
  vtkNew<vtkPoints> points;
  if (cloud.PointsSize)
  {
    vtkSmartPointer<vtkDataArray> xyz;
    xyz.TakeReference(vtkDataArray::CreateDataArray(cloud.PointsSize == 4 ? VTK_FLOAT : VTK_DOUBLE));
    xyz->SetNumberOfComponents(3);
    meshfree::AdoptBulk(xyz, cloud.Points.Release(), 3 * n);
    points->SetData(xyz);
  }
  else
  {
    if (coord[0] < 0 && coord[1] < 0 && coord[2] < 0)
      vtkWarningMacro("'" << this->FileName << "' has no x, y or z field: all points are at the origin.");
    points->SetDataType(VTK_DOUBLE);
    points->SetNumberOfPoints(n);
    double* xyz = static_cast<double*>(points->GetVoidPointer(0));
    for (int k = 0; k < 3; ++k)
    {
      const pcd::Field* f = coord[k] >= 0 ? &head.Fields[cloud.ColumnField[coord[k]]] : nullptr;
      const unsigned char* src = f ? cloud.Columns[coord[k]].Data() : nullptr;
      for (vtkIdType i = 0; i < n; ++i)
        xyz[3 * i + k] = f ? ValueAsDouble(*f, src + i * f->Size) : 0.0;
    }
  }
  output->SetPoints(points);

  // PCL's normal_x, normal_y, normal_z: one 3-component array, the active normals (glyphs, surfaces).
  std::set<std::string> names;
  if (cloud.NormalsSize)
  {
    vtkSmartPointer<vtkDataArray> normals;
    normals.TakeReference(vtkDataArray::CreateDataArray(cloud.NormalsSize == 4 ? VTK_FLOAT : VTK_DOUBLE));
    normals->SetNumberOfComponents(3);
    meshfree::AdoptBulk(normals, cloud.Normals.Release(), 3 * n);
    normals->SetName("Normals");
    output->GetPointData()->SetNormals(normals);
    names.insert("Normals");
  }

  // Every other field: a point array that adopts the decoded column (no copy).
  for (std::size_t c = 0; c < cloud.Columns.size(); ++c)
  {
    if (static_cast<int>(c) == coord[0] || static_cast<int>(c) == coord[1] || static_cast<int>(c) == coord[2])
      continue;
    const pcd::Field& f = head.Fields[cloud.ColumnField[c]];
    std::string name = f.Name;
    for (int k = 1; names.count(name); ++k)
      name = f.Name + "_" + std::to_string(k);
    names.insert(name);
    vtkSmartPointer<vtkDataArray> array;
    if (IsPackedColor(f))
    {
      const int comps = f.Name == "rgba" ? 4 : 3;
      auto* dst = static_cast<unsigned char*>(pcd::AllocateBulk(static_cast<std::size_t>(n) * comps));
      if (!dst)
      {
        vtkErrorMacro("Cannot read '" << this->FileName << "': out of memory for " << n << " colours.");
        output->Initialize();
        return 1;
      }
      auto colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
      colors->SetNumberOfComponents(comps);
      meshfree::AdoptBulk(colors, dst, static_cast<vtkIdType>(n) * comps);
      const unsigned char* src = cloud.Columns[c].Data();
      for (vtkIdType i = 0; i < n; ++i)
      {
        std::uint32_t bits;
        std::memcpy(&bits, src + 4 * i, 4);
        dst[comps * i] = static_cast<unsigned char>(bits >> 16);
        dst[comps * i + 1] = static_cast<unsigned char>(bits >> 8);
        dst[comps * i + 2] = static_cast<unsigned char>(bits);
        if (comps == 4)
          dst[comps * i + 3] = static_cast<unsigned char>(bits >> 24);
      }
      array = colors;
    }
    else
    {
      array.TakeReference(vtkDataArray::CreateDataArray(VTKType(f)));
      array->SetNumberOfComponents(f.Count);
      meshfree::AdoptBulk(array, cloud.Columns[c].Release(), static_cast<vtkIdType>(n) * f.Count);
    }
    array->SetName(name.c_str());
    output->GetPointData()->AddArray(array);
  }
  if ((!kept.empty() || cloud.InvalidElsewhere) && fileHeight > 1)
  {
    // Indices in the file's WIDTH x HEIGHT grid (a piece's kept[i] counts from its first point).
    vtkNew<vtkIdTypeArray> pixel;
    pixel->SetName("PixelIndex");
    pixel->SetNumberOfValues(n);
    for (vtkIdType i = 0; i < n; ++i)
      pixel->SetValue(i, static_cast<vtkIdType>(cloud.First + (kept.empty() ? i : kept[i])));
    output->GetPointData()->AddArray(pixel);
  }

  vtkNew<vtkDoubleArray> viewpoint;
  viewpoint->SetName("Viewpoint");
  viewpoint->SetNumberOfValues(7);
  for (int k = 0; k < 7; ++k)
    viewpoint->SetValue(k, head.Viewpoint[k]);
  output->GetFieldData()->AddArray(viewpoint);
  vtkNew<vtkIdTypeArray> dims;
  dims->SetName("OrganizedDimensions");
  dims->SetNumberOfValues(2);
  dims->SetValue(0, static_cast<vtkIdType>(fileWidth));
  dims->SetValue(1, static_cast<vtkIdType>(fileHeight));
  output->GetFieldData()->AddArray(dims);

  if (!meshfree::AddVertexCells(output, n))
  {
    vtkErrorMacro("Cannot read '" << this->FileName << "': out of memory for " << n << " vertex cells.");
    output->Initialize();
  }
  return 1;
}
