#include "vtkMeshFreePCDWriter.h"

#include "PCDFormat.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMeshFreePCDWriter);

namespace
{
// (SIZE, TYPE) of a VTK array type; false for types .pcd cannot hold.
bool PCDType(int vtkType, int& size, char& type)
{
  switch (vtkType)
  {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR: size = 1, type = 'I'; return true;
    case VTK_UNSIGNED_CHAR: size = 1, type = 'U'; return true;
    case VTK_SHORT: size = 2, type = 'I'; return true;
    case VTK_UNSIGNED_SHORT: size = 2, type = 'U'; return true;
    case VTK_INT: size = 4, type = 'I'; return true;
    case VTK_UNSIGNED_INT: size = 4, type = 'U'; return true;
    case VTK_LONG:
    case VTK_LONG_LONG:
    case VTK_ID_TYPE: size = 8, type = 'I'; return true;
    case VTK_UNSIGNED_LONG:
    case VTK_UNSIGNED_LONG_LONG: size = 8, type = 'U'; return true;
    case VTK_FLOAT: size = 4, type = 'F'; return true;
    case VTK_DOUBLE: size = 8, type = 'F'; return true;
    default: return false;
  }
}

bool IsNormalsArray(vtkDataArray* a)
{
  return a && a->GetNumberOfComponents() == 3 && (a->GetDataType() == VTK_FLOAT || a->GetDataType() == VTK_DOUBLE);
}

std::string FieldName(const char* name, std::size_t index)
{
  std::string s = name ? name : "";
  for (char& c : s)
    if (std::isspace(static_cast<unsigned char>(c)))
      c = '_';
  if (s.empty() || s == "_")
    s = "array" + std::to_string(index);
  return s;
}
} // namespace

vtkMeshFreePCDWriter::vtkMeshFreePCDWriter() = default;

vtkMeshFreePCDWriter::~vtkMeshFreePCDWriter()
{
  this->SetFileName(nullptr);
}

int vtkMeshFreePCDWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

void vtkMeshFreePCDWriter::WriteData()
{
  namespace pcd = meshfree::pcd;
  vtkPointSet* input = vtkPointSet::SafeDownCast(this->GetInput());
  if (!input)
  {
    vtkErrorMacro("The input is not a point set.");
    return;
  }
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("No FileName given.");
    return;
  }
  const vtkIdType n = input->GetNumberOfPoints();
  pcd::Header header;
  header.Points = static_cast<std::uint64_t>(n);
  header.Width = header.Points;
  header.Height = 1;
  header.Data = this->Encoding == ASCII ? pcd::Encoding::Ascii
    : this->Encoding == BINARY          ? pcd::Encoding::Binary
                                        : pcd::Encoding::BinaryCompressed;
  std::vector<const void*> columns;
  std::vector<std::vector<unsigned char>> storage; // columns that had to be converted
  std::vector<vtkSmartPointer<vtkDataArray>> keep;
  storage.reserve(4 + input->GetPointData()->GetNumberOfArrays());

  // x, y, z as 4-byte floats, the format's convention that PCL's point types read; 8-byte doubles only when
  // asked (and the points are double).
  vtkPoints* points = input->GetPoints();
  const bool doublePoints = this->WriteDoubleCoordinates && points && points->GetDataType() != VTK_FLOAT;
  double worstRounding = 0.0;
  auto addComponentFields = [&](vtkDataArray* source, const std::string& prefix, bool asDouble) {
    for (int k = 0; k < 3; ++k)
    {
      pcd::Field f;
      f.Name = prefix + "xyz"[k];
      f.Size = asDouble ? 8 : 4;
      header.Fields.push_back(f);
      storage.emplace_back(static_cast<std::size_t>(n) * f.Size);
      unsigned char* dst = storage.back().data();
      for (vtkIdType i = 0; i < n; ++i)
      {
        const double v = source->GetComponent(i, k);
        const float x = static_cast<float>(v);
        std::memcpy(dst + f.Size * i, asDouble ? static_cast<const void*>(&v) : &x, f.Size);
        if (!asDouble && std::isfinite(v))
          worstRounding = std::max(worstRounding, std::abs(static_cast<double>(x) - v));
      }
      columns.push_back(dst);
    }
  };
  addComponentFields(n > 0 ? points->GetData() : nullptr, "", doublePoints);
  const double size = n > 0 ? input->GetLength() : 0.0; // the bounding box's diagonal
  if (size > 0.0 && worstRounding > 1e-5 * size) // a single point (size 0) has no scale to lose
    vtkWarningMacro("'" << this->FileName << "': x, y, z written as 4-byte floats (the .pcd convention that PCL "
                        << "reads) move points by up to " << worstRounding << " (the cloud spans " << size
                        << "); switch WriteDoubleCoordinates on to keep doubles (most PCL tools cannot read those).");

  // The normals (the active ones, or a 3-component array named Normals) as PCL's normal_x, normal_y, normal_z,
  // in the precision of the coordinates.
  vtkPointData* pd = input->GetPointData();
  vtkDataArray* normals = pd->GetNormals();
  if (!IsNormalsArray(normals))
    normals = pd->GetArray("Normals");
  if (!IsNormalsArray(normals))
    normals = nullptr;
  if (normals)
    addComponentFields(normals, "normal_", doublePoints && normals->GetDataType() == VTK_DOUBLE);

  std::set<std::string> used;
  for (const pcd::Field& f : header.Fields)
    used.insert(f.Name);
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = pd->GetArray(a);
    if (!array || array == normals)
      continue;
    const std::string name = FieldName(array->GetName(), static_cast<std::size_t>(a));
    const int comps = array->GetNumberOfComponents();
    pcd::Field f;
    if (array->GetDataType() == VTK_UNSIGNED_CHAR && ((name == "rgb" && comps == 3) || (name == "rgba" && comps == 4)))
    {
      // PCL's packed colour: 0xAARRGGBB in a float (rgb) or uint32 (rgba).
      f.Name = name, f.Size = 4, f.Type = name == "rgb" ? 'F' : 'U', f.Count = 1;
      storage.emplace_back(static_cast<std::size_t>(n) * 4);
      unsigned char* dst = storage.back().data();
      for (vtkIdType i = 0; i < n; ++i)
      {
        std::uint32_t bits = (static_cast<std::uint32_t>(array->GetComponent(i, 0)) << 16) |
          (static_cast<std::uint32_t>(array->GetComponent(i, 1)) << 8) |
          static_cast<std::uint32_t>(array->GetComponent(i, 2));
        if (comps == 4)
          bits |= static_cast<std::uint32_t>(array->GetComponent(i, 3)) << 24;
        std::memcpy(dst + 4 * i, &bits, 4);
      }
      columns.push_back(dst);
    }
    else
    {
      if (!PCDType(array->GetDataType(), f.Size, f.Type))
      {
        vtkWarningMacro("Point array '" << name << "' of type " << array->GetDataTypeAsString()
                                        << " has no .pcd type: not written.");
        continue;
      }
      f.Name = name;
      f.Count = comps;
      vtkSmartPointer<vtkDataArray> aos = array;
      if (!array->HasStandardMemoryLayout())
      {
        aos.TakeReference(vtkDataArray::CreateDataArray(array->GetDataType()));
        aos->DeepCopy(array);
      }
      keep.push_back(aos);
      columns.push_back(aos->GetVoidPointer(0));
    }
    for (int k = 1; used.count(f.Name); ++k)
      f.Name = name + "_" + std::to_string(k);
    used.insert(f.Name);
    header.Fields.push_back(f);
  }

  if (auto* vp = input->GetFieldData()->GetArray("Viewpoint"))
    if (vp->GetNumberOfTuples() * vp->GetNumberOfComponents() == 7)
      for (int k = 0; k < 7; ++k)
        header.Viewpoint[k] = vp->GetComponent(k / vp->GetNumberOfComponents(), k % vp->GetNumberOfComponents());
  if (auto* dims = input->GetFieldData()->GetArray("OrganizedDimensions"))
    if (dims->GetNumberOfTuples() * dims->GetNumberOfComponents() == 2)
    {
      const auto w = static_cast<std::uint64_t>(dims->GetComponent(0, 0));
      const auto h = static_cast<std::uint64_t>(dims->GetNumberOfComponents() == 2 ? dims->GetComponent(0, 1) : dims->GetComponent(1, 0));
      if (w * h == header.Points)
        header.Width = w, header.Height = h;
    }

  std::string error;
  if (!pcd::WriteFile(this->FileName, header, columns, error))
  {
    vtkErrorMacro("Cannot write '" << this->FileName << "': " << error);
    this->SetErrorCode(1);
  }
}

void vtkMeshFreePCDWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Encoding: " << this->Encoding << "\n";
  os << indent << "WriteDoubleCoordinates: " << this->WriteDoubleCoordinates << "\n";
}
