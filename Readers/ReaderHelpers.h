// Small VTK helpers shared by the readers of this module (private header, not wrapped).
#ifndef meshfree_ReaderHelpers_h
#define meshfree_ReaderHelpers_h

#include "vtkCellArray.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkNew.h"
#include "vtkPolyData.h"

#include <cstdio>
#include <string>

namespace meshfree
{
/// One vertex cell per point, built straight into the cell array's offsets/connectivity (32-bit storage
/// when it fits: half the memory traffic of vtkIdType for the largest array of the output).
template <class ArrayT>
void FillVertexCells(vtkPolyData* output, vtkIdType n)
{
  using T = typename ArrayT::ValueType;
  vtkNew<ArrayT> offsets;
  vtkNew<ArrayT> connectivity;
  offsets->SetNumberOfValues(n + 1);
  connectivity->SetNumberOfValues(n);
  T* o = offsets->GetPointer(0);
  T* c = connectivity->GetPointer(0);
  for (vtkIdType i = 0; i < n; ++i)
  {
    o[i] = static_cast<T>(i);
    c[i] = static_cast<T>(i);
  }
  o[n] = static_cast<T>(n);
  vtkNew<vtkCellArray> verts;
  verts->SetData(offsets, connectivity);
  output->SetVerts(verts);
}

inline void AddVertexCells(vtkPolyData* output, vtkIdType n)
{
  if (n < VTK_TYPE_INT32_MAX)
    FillVertexCells<vtkTypeInt32Array>(output, n);
  else
    FillVertexCells<vtkTypeInt64Array>(output, n);
}

/// Reads at most maxBytes from the start of a file (for CanReadFile's sniffing).
inline bool ReadFileStart(const char* filename, std::size_t maxBytes, std::string& bytes)
{
  bytes.clear();
  if (!filename || !*filename)
    return false;
  std::FILE* f = std::fopen(filename, "rb");
  if (!f)
    return false;
  bytes.resize(maxBytes);
  bytes.resize(std::fread(&bytes[0], 1, maxBytes, f));
  std::fclose(f);
  return true;
}
} // namespace meshfree

#endif
