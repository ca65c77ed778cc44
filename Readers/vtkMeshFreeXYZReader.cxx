#include "vtkMeshFreeXYZReader.h"

#include "PCDFormat.h"
#include "ReaderHelpers.h"
#include "XYZFormat.h"

#include "vtkDoubleArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <type_traits>

vtkStandardNewMacro(vtkMeshFreeXYZReader);

namespace
{
std::string Lower(std::string s)
{
  for (char& c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool EndsWith(const std::string& s, const std::string& tail)
{
  return s.size() >= tail.size() && Lower(s.substr(s.size() - tail.size())) == tail;
}
} // namespace

int vtkMeshFreeXYZReader::CanReadFile(const char* filename)
{
  std::string start;
  if (!meshfree::ReadFileStart(filename, 64 * 1024, start))
    return 0;
  if (meshfree::xyz::LooksLikeCloud(start.data(), start.size()))
    return 1;
  // A binary file that cannot be a PLOT3D grid either (a damaged file): claimed, to be refused with an
  // error by RequestData, because ParaView's PLOT3D reader, the other reader of ".xyz", aborts on such data.
  return meshfree::xyz::LooksBinary(start.data(), start.size()) &&
      !meshfree::xyz::LooksLikePlot3D(start.data(), start.size())
    ? 1
    : 0;
}

int vtkMeshFreeXYZReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = this->PrepareOutput(outputVector);
  if (!output)
  {
    return 1;
  }
  meshfree::pcd::PieceRequest request;
  this->GetPiece(outputVector, request.Piece, request.Pieces);
  meshfree::pcd::MappedFile file;
  request.Mapping = &file;
  meshfree::xyz::Table table;
  std::string error;
  // One piece of several: the file is only mapped, the rank reads the pages of its lines (and of the header).
  if (file.Open(this->FileName, error, /*populate=*/request.Pieces <= 1) &&
    meshfree::xyz::LooksBinary(file.Data(), file.Size()))
  {
    vtkErrorMacro("Cannot read '" << this->FileName
                                  << "': it holds binary data (NUL or control bytes), not a text point cloud.");
    return 1;
  }
  if (!error.empty() ||
    !(request.Pieces > 1 ? meshfree::xyz::ParsePiece(file.Data(), file.Size(), request, table, error)
                         : meshfree::xyz::Parse(file.Data(), file.Size(), table, error)))
  {
    vtkErrorMacro("Cannot read '" << this->FileName << "': " << error);
    return 1;
  }
  this->UpdateProgress(0.5);
  const std::size_t cols = table.Names.size();
  std::vector<std::string> names = table.Names;
  if (!table.NamedByHeader && EndsWith(this->FileName, ".pts"))
  {
    // Leica's column layout: x y z [intensity] [r g b].
    if (cols == 4 || cols == 7)
      names[3] = "Intensity";
    if (cols == 6 || cols == 7)
      names[cols - 3] = "r", names[cols - 2] = "g", names[cols - 1] = "b";
  }

  // Rows to keep (all, unless some have a non-finite coordinate).
  const int* xyz = table.Coordinate;
  const double* values = table.Values.data();
  auto finiteRow = [&](std::uint64_t r) {
    const double* v = values + r * cols;
    return std::isfinite(v[xyz[0]]) && std::isfinite(v[xyz[1]]) && std::isfinite(v[xyz[2]]);
  };
  std::vector<vtkIdType> rows; // the kept rows, when some were dropped
  bool dropped = false;
  if (!this->KeepInvalidPoints)
  {
    std::uint64_t firstBad = 0;
    while (firstBad < table.Rows && finiteRow(firstBad))
      ++firstBad;
    if (firstBad < table.Rows)
    {
      dropped = true;
      rows.reserve(table.Rows);
      for (std::uint64_t r = 0; r < table.Rows; ++r)
        if (r < firstBad || (r > firstBad && finiteRow(r)))
          rows.push_back(static_cast<vtkIdType>(r));
      vtkWarningMacro("'" << this->FileName << "': dropped " << table.Rows - rows.size() << " of " << table.Rows
                          << (request.Pieces > 1 ? " points of this piece" : " points")
                          << " whose x, y or z is not a finite number; switch KeepInvalidPoints on to keep them.");
    }
  }
  const vtkIdType n = dropped ? static_cast<vtkIdType>(rows.size()) : static_cast<vtkIdType>(table.Rows);
  auto row = [&](vtkIdType i) { return values + (dropped ? rows[i] : i) * cols; };

  // Every output array in fresh bulk memory that the VTK array adopts (no zero-fill, no per-page faults).
  bool outOfMemory = false;
  auto bulk = [&](auto* array, int components) {
    using T = typename std::remove_pointer<decltype(array->GetPointer(0))>::type;
    auto* p = static_cast<T*>(meshfree::pcd::AllocateBulk(sizeof(T) * std::max<vtkIdType>(1, n * components)));
    outOfMemory = outOfMemory || !p;
    array->SetNumberOfComponents(components);
    if (p)
      meshfree::AdoptBulk(array, p, n * components);
    return p;
  };

  vtkNew<vtkDoubleArray> coordinates;
  if (double* p = bulk(coordinates.Get(), 3))
    for (vtkIdType i = 0; i < n; ++i)
    {
      const double* v = row(i);
      p[3 * i] = v[xyz[0]], p[3 * i + 1] = v[xyz[1]], p[3 * i + 2] = v[xyz[2]];
    }
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  output->SetPoints(points);

  // Colour columns r g b (or red green blue) of integers 0..255 become one unsigned-char array.
  int rgb[3] = { -1, -1, -1 };
  for (std::size_t c = 0; c < cols; ++c)
  {
    const std::string l = Lower(names[c]);
    for (int k = 0; k < 3; ++k)
      if (l == std::string(1, "rgb"[k]) || l == (k == 0 ? "red" : k == 1 ? "green" : "blue"))
        rgb[k] = static_cast<int>(c);
  }
  bool colors = rgb[0] >= 0 && rgb[1] >= 0 && rgb[2] >= 0;
  auto isColor = [&](const double* v) {
    for (int k = 0; k < 3; ++k)
      if (!(v[rgb[k]] >= 0 && v[rgb[k]] <= 255 && v[rgb[k]] == std::floor(v[rgb[k]])))
        return false;
    return true;
  };
  for (vtkIdType i = 0; colors && i < n; ++i)
    colors = isColor(row(i));
  if (colors && request.Pieces > 1)
  {
    // Whether the columns become RGB depends on every kept row of the file: a piece reads the others' rows too
    // (one at a time, nothing kept), up to the first one that is no colour.
    auto visit = [&](const double* v) {
      const bool finite = std::isfinite(v[xyz[0]]) && std::isfinite(v[xyz[1]]) && std::isfinite(v[xyz[2]]);
      if (!finite && !this->KeepInvalidPoints)
        return true; // dropped: no part of the output
      colors = isColor(v);
      return colors;
    };
    if (!meshfree::xyz::ForEachRowElsewhere(file.Data(), file.Size(), table, &file, visit, error))
    {
      vtkErrorMacro("Cannot read '" << this->FileName << "': " << error);
      output->Initialize();
      return 1;
    }
  }
  if (colors)
  {
    vtkNew<vtkUnsignedCharArray> array;
    array->SetName("RGB");
    if (unsigned char* p = bulk(array.Get(), 3))
      for (vtkIdType i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
          p[3 * i + k] = static_cast<unsigned char>(row(i)[rgb[k]]);
    output->GetPointData()->AddArray(array);
  }

  for (std::size_t c = 0; c < cols; ++c)
  {
    const int ci = static_cast<int>(c);
    if (ci == xyz[0] || ci == xyz[1] || ci == xyz[2])
      continue;
    if (colors && (ci == rgb[0] || ci == rgb[1] || ci == rgb[2]))
      continue;
    vtkNew<vtkDoubleArray> array;
    array->SetName(names[c].c_str());
    if (double* p = bulk(array.Get(), 1))
      for (vtkIdType i = 0; i < n; ++i)
        p[i] = row(i)[c];
    output->GetPointData()->AddArray(array);
  }
  if (outOfMemory || !meshfree::AddVertexCells(output, n))
  {
    vtkErrorMacro("Cannot read '" << this->FileName << "': out of memory for " << n << " points.");
    output->Initialize();
  }
  return 1;
}
