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

vtkMeshFreeXYZReader::vtkMeshFreeXYZReader()
{
  this->SetNumberOfInputPorts(0);
}

vtkMeshFreeXYZReader::~vtkMeshFreeXYZReader()
{
  this->SetFileName(nullptr);
}

int vtkMeshFreeXYZReader::CanReadFile(const char* filename)
{
  std::string start;
  if (!meshfree::ReadFileStart(filename, 64 * 1024, start))
    return 0;
  return meshfree::xyz::LooksLikeCloud(start.data(), start.size()) ? 1 : 0;
}

int vtkMeshFreeXYZReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  output->Initialize();
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("No FileName given.");
    return 1;
  }
  meshfree::pcd::MappedFile file;
  meshfree::xyz::Table table;
  std::string error;
  if (!file.Open(this->FileName, error) || !meshfree::xyz::Parse(file.Data(), file.Size(), table, error))
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

  // Rows to keep.
  const int* xyz = table.Coordinate;
  std::vector<vtkIdType> rows;
  rows.reserve(table.Rows);
  for (std::uint64_t r = 0; r < table.Rows; ++r)
  {
    const double* v = &table.Values[r * cols];
    if (this->KeepInvalidPoints ||
      (std::isfinite(v[xyz[0]]) && std::isfinite(v[xyz[1]]) && std::isfinite(v[xyz[2]])))
      rows.push_back(static_cast<vtkIdType>(r));
  }
  if (rows.size() != table.Rows)
    vtkWarningMacro("'" << this->FileName << "': dropped " << table.Rows - rows.size() << " of " << table.Rows
                        << " points whose x, y or z is not a finite number; switch KeepInvalidPoints on to keep them.");
  const vtkIdType n = static_cast<vtkIdType>(rows.size());

  vtkNew<vtkPoints> points;
  points->SetDataType(VTK_DOUBLE);
  points->SetNumberOfPoints(n);
  double* p = static_cast<double*>(points->GetVoidPointer(0));
  for (vtkIdType i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      p[3 * i + k] = table.Values[rows[i] * cols + xyz[k]];
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
  for (vtkIdType i = 0; colors && i < n; ++i)
    for (int k = 0; k < 3; ++k)
    {
      const double v = table.Values[rows[i] * cols + rgb[k]];
      colors = colors && v >= 0 && v <= 255 && v == std::floor(v);
    }
  if (colors)
  {
    vtkNew<vtkUnsignedCharArray> array;
    array->SetName("RGB");
    array->SetNumberOfComponents(3);
    array->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
        array->SetTypedComponent(i, k, static_cast<unsigned char>(table.Values[rows[i] * cols + rgb[k]]));
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
    array->SetNumberOfValues(n);
    for (vtkIdType i = 0; i < n; ++i)
      array->SetValue(i, table.Values[rows[i] * cols + c]);
    output->GetPointData()->AddArray(array);
  }
  meshfree::AddVertexCells(output, n);
  return 1;
}

void vtkMeshFreeXYZReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "KeepInvalidPoints: " << (this->KeepInvalidPoints ? "On" : "Off") << "\n";
}
