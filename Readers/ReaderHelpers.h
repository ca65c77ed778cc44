// Small VTK helpers shared by the readers of this module (private header, not wrapped).
#ifndef meshfree_ReaderHelpers_h
#define meshfree_ReaderHelpers_h

#include "PCDFormat.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkNew.h"
#include "vtkPolyData.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace meshfree
{
/// Hands a block of pcd::AllocateBulk holding `values` values to a VTK array, which frees it with FreeBulk.
inline void AdoptBulk(vtkDataArray* array, void* block, vtkIdType values)
{
  array->SetVoidArray(block, values, 0, vtkAbstractArray::VTK_DATA_ARRAY_USER_DEFINED);
  array->SetArrayFreeFunction(&pcd::FreeBulk);
}

/// One vertex cell per point, built straight into the cell array's offsets/connectivity (32-bit storage
/// when it fits: half the memory traffic of vtkIdType for the largest array of the output).
template <class ArrayT>
bool FillVertexCells(vtkPolyData* output, vtkIdType n)
{
  using T = typename ArrayT::ValueType;
  // Fresh bulk memory (huge pages, prefaulted), adopted by the arrays: no page fault per 4 KB on filling.
  T* o = static_cast<T*>(pcd::AllocateBulk(sizeof(T) * static_cast<std::size_t>(n + 1)));
  T* c = static_cast<T*>(pcd::AllocateBulk(sizeof(T) * static_cast<std::size_t>(n > 0 ? n : 1)));
  if (!o || !c)
  {
    pcd::FreeBulk(o);
    pcd::FreeBulk(c);
    return false;
  }
  for (vtkIdType i = 0; i < n; ++i)
  {
    o[i] = static_cast<T>(i);
    c[i] = static_cast<T>(i);
  }
  o[n] = static_cast<T>(n);
  vtkNew<ArrayT> offsets;
  vtkNew<ArrayT> connectivity;
  AdoptBulk(offsets.Get(), o, n + 1);
  AdoptBulk(connectivity.Get(), c, n);
  vtkNew<vtkCellArray> verts;
  verts->SetData(offsets, connectivity);
  output->SetVerts(verts);
  return true;
}

/// False when out of memory (the output then has no cells).
inline bool AddVertexCells(vtkPolyData* output, vtkIdType n)
{
  if (n < VTK_TYPE_INT32_MAX)
    return FillVertexCells<vtkTypeInt32Array>(output, n);
  return FillVertexCells<vtkTypeInt64Array>(output, n);
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
