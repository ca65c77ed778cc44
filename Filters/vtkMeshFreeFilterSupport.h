// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file    vtkMeshFreeFilterSupport.h
 * @brief   What the MeshFree filters share when they hand work to the core: progress and abort, and
 *          one-value field arrays. Private to the module (not wrapped, not installed).
 */
#ifndef vtkMeshFreeFilterSupport_h
#define vtkMeshFreeFilterSupport_h

#include "vtkAlgorithm.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkNew.h"

#include "Common/Progress.h"

namespace vtkMeshFreeFilterSupport
{
/// Reports the core's progress as the sub-range [begin, end] of the algorithm's, and passes its abort flag back.
inline meshfree::ProgressCallback Progress(vtkAlgorithm* algorithm, double begin = 0.0, double end = 1.0)
{
  return [algorithm, begin, end](double fraction) {
    algorithm->UpdateProgress(begin + (end - begin) * fraction);
    return !algorithm->GetAbortExecute();
  };
}

/// Adds a one-tuple double array `name` = value to fd.
inline void AddFieldValue(vtkFieldData* fd, const char* name, double value)
{
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->SetNumberOfTuples(1);
  array->SetValue(0, value);
  fd->AddArray(array);
}
} // namespace vtkMeshFreeFilterSupport

#endif
