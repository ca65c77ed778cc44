// Shared helpers of the stress suite (ctest label "stress"): an output window that captures every VTK
// error and warning (so a test can assert that the expected message appeared, and that none appeared where
// none is expected), finiteness checks over every point and array of an output, and generators of hostile
// point clouds.
#ifndef MeshFreeStressCommon_h
#define MeshFreeStressCommon_h

#include "TestFunctions.h"

#include "vtkCellArray.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOutputWindow.h"
#include "vtkPointData.h"
#include "vtkCellData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

namespace stress
{

// Captures VTK's error and warning text instead of printing it. Install() once per test program.
class CaptureWindow : public vtkOutputWindow
{
public:
  static CaptureWindow* New()
  {
    auto* window = new CaptureWindow;
    window->InitializeObjectBase();
    return window;
  }
  vtkTypeMacro(CaptureWindow, vtkOutputWindow);
  void DisplayText(const char* text) override { this->Text += text ? text : ""; }
  void DisplayErrorText(const char* text) override
  {
    ++this->Errors;
    this->Text += "[vtk error] ";
    this->DisplayText(text);
  }
  void DisplayWarningText(const char* text) override
  {
    ++this->Warnings;
    this->Text += "[vtk warning] ";
    this->DisplayText(text);
  }
  void DisplayGenericWarningText(const char* text) override { this->DisplayWarningText(text); }
  void DisplayDebugText(const char* text) override { (void)text; }
  void Clear()
  {
    this->Text.clear();
    this->Errors = this->Warnings = 0;
  }
  std::string Text;
  int Errors = 0;
  int Warnings = 0;
};

inline CaptureWindow* Window()
{
  static vtkSmartPointer<CaptureWindow> window;
  if (!window)
  {
    window = vtkSmartPointer<CaptureWindow>::New();
    vtkOutputWindow::SetInstance(window);
    // vtkLogger would also copy errors to stderr ("ERR| ..."); the captured text is checked instead.
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  }
  return window;
}

struct Suite
{
  int Failures = 0;
  int Cases = 0;
  std::string Case;
  std::chrono::steady_clock::time_point Start = std::chrono::steady_clock::now();

  // Begin a case: clears the captured messages.
  void Begin(const std::string& name)
  {
    this->Case = name;
    ++this->Cases;
    Window()->Clear();
    static const bool verbose = std::getenv("MESHFREE_STRESS_VERBOSE") != nullptr;
    if (verbose)
    {
      const auto now = std::chrono::steady_clock::now();
      static auto last = now;
      std::cout << "  (" << std::chrono::duration<double>(now - last).count() << " s)\ncase: " << name
                << std::endl;
      last = now;
    }
  }
  bool Check(bool ok, const std::string& what)
  {
    if (!ok)
    {
      std::cout << "ERROR: [" << this->Case << "] " << what << std::endl;
      const std::string& text = Window()->Text;
      if (!text.empty())
      {
        std::cout << "  captured VTK output:\n" << text.substr(0, 2000) << std::endl;
      }
      ++this->Failures;
    }
    return ok;
  }
  // The captured errors and warnings mention `word` (case-sensitive substring).
  void ExpectMessage(const std::string& word)
  {
    this->Check(Window()->Errors + Window()->Warnings > 0, "no error or warning was reported");
    this->Check(Window()->Text.find(word) != std::string::npos, "no message mentions '" + word + "'");
  }
  void ExpectWarning(const std::string& word)
  {
    this->Check(Window()->Warnings > 0, "no warning was reported");
    this->Check(Window()->Text.find(word) != std::string::npos, "no message mentions '" + word + "'");
  }
  void ExpectError(const std::string& word)
  {
    this->Check(Window()->Errors > 0, "no error was reported");
    this->Check(Window()->Text.find(word) != std::string::npos, "no message mentions '" + word + "'");
  }
  void ExpectSilent()
  {
    this->Check(Window()->Errors + Window()->Warnings == 0, "an unexpected error or warning was reported");
  }
  void ExpectNoError() { this->Check(Window()->Errors == 0, "an unexpected error was reported"); }
  int Finish(const char* name)
  {
    const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - this->Start).count();
    std::cout << name << ": " << this->Cases << " cases, " << this->Failures << " failures, " << seconds
              << " s" << std::endl;
    return this->Failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
  }
};

// Index of the first non-finite value in the array (tuple * components + component), or -1.
inline vtkIdType FirstNonFinite(vtkDataArray* array)
{
  if (!array)
  {
    return -1;
  }
  const int nc = array->GetNumberOfComponents();
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < nc; ++c)
    {
      if (!std::isfinite(array->GetComponent(i, c)))
      {
        return i * nc + c;
      }
    }
  }
  return -1;
}

// Every point coordinate and every numeric array (point, cell, field data) of the data set is finite.
// `what` receives the first offender.
inline bool AllFinite(vtkDataSet* ds, std::string& what)
{
  if (!ds)
  {
    return true;
  }
  for (vtkIdType i = 0; i < ds->GetNumberOfPoints(); ++i)
  {
    double x[3];
    ds->GetPoint(i, x);
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
    {
      what = "point " + std::to_string(i);
      return false;
    }
  }
  vtkFieldData* fields[3] = { ds->GetPointData(), ds->GetCellData(), ds->GetFieldData() };
  for (vtkFieldData* fd : fields)
  {
    for (int a = 0; fd && a < fd->GetNumberOfArrays(); ++a)
    {
      vtkDataArray* array = fd->GetArray(a);
      const vtkIdType bad = FirstNonFinite(array);
      if (bad >= 0)
      {
        what = std::string("array ") + (array->GetName() ? array->GetName() : "?") + " value " + std::to_string(bad);
        return false;
      }
    }
  }
  return true;
}

inline bool AllFinite(vtkDataObject* object, std::string& what)
{
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(object))
  {
    vtkSmartPointer<vtkCompositeDataIterator> it;
    it.TakeReference(composite->NewIterator());
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      if (!AllFinite(vtkDataSet::SafeDownCast(it->GetCurrentDataObject()), what))
      {
        return false;
      }
    }
    return true;
  }
  return AllFinite(vtkDataSet::SafeDownCast(object), what);
}

inline void CheckFinite(Suite& suite, vtkDataObject* object)
{
  std::string what;
  const bool finite = AllFinite(object, what); // before the message is built
  suite.Check(finite, "non-finite output: " + what);
}

// A number as %g (std::to_string prints 1e-300 as 0.000000).
inline std::string Str(double v)
{
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

using meshfree::testing::Halton;

// Hostile clouds. Each has point arrays "F" (1 component, a smooth function of the position) and "V"
// (3 components), unless said otherwise.
enum class CloudKind
{
  Empty,
  OnePoint,
  Duplicates,    // n copies of one point
  TwoDuplicates, // half at one point, half at another
  Collinear,     // on a line through 3D space
  Coplanar,      // on a tilted plane in 3D
  Flat,          // z = 0 (a 2D cloud, the ordinary case of the thesis)
  Volume,        // a 3D cloud in the unit cube
  NaNCoords,     // a Volume cloud with some NaN and Inf coordinates
  NaNValues,     // a Volume cloud with some NaN and Inf values in F and V
  Offset1e6,     // a Volume cloud moved by 1e6
  Scale1em6,     // a Volume cloud scaled by 1e-6
  Scale1e6       // a Volume cloud scaled by 1e6
};

inline const char* Name(CloudKind k)
{
  switch (k)
  {
    case CloudKind::Empty: return "empty";
    case CloudKind::OnePoint: return "one-point";
    case CloudKind::Duplicates: return "duplicates";
    case CloudKind::TwoDuplicates: return "two-duplicates";
    case CloudKind::Collinear: return "collinear";
    case CloudKind::Coplanar: return "coplanar";
    case CloudKind::Flat: return "flat";
    case CloudKind::Volume: return "volume";
    case CloudKind::NaNCoords: return "nan-coords";
    case CloudKind::NaNValues: return "nan-values";
    case CloudKind::Offset1e6: return "offset-1e6";
    case CloudKind::Scale1em6: return "scale-1e-6";
    case CloudKind::Scale1e6: return "scale-1e6";
  }
  return "?";
}

inline const std::vector<CloudKind>& AllKinds()
{
  static const std::vector<CloudKind> kinds = { CloudKind::Empty, CloudKind::OnePoint, CloudKind::Duplicates,
    CloudKind::TwoDuplicates, CloudKind::Collinear, CloudKind::Coplanar, CloudKind::Flat, CloudKind::Volume,
    CloudKind::NaNCoords, CloudKind::NaNValues, CloudKind::Offset1e6, CloudKind::Scale1em6,
    CloudKind::Scale1e6 };
  return kinds;
}

// The affine map of a cloud kind (offset and scale applied to unit-cube positions).
inline void Transform(CloudKind k, double& offset, double& scale)
{
  offset = k == CloudKind::Offset1e6 ? 1e6 : 0.0;
  scale = k == CloudKind::Scale1em6 ? 1e-6 : (k == CloudKind::Scale1e6 ? 1e6 : 1.0);
}

inline vtkSmartPointer<vtkPolyData> MakeCloud(CloudKind k, int n = 200)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> f, v;
  f->SetName("F");
  v->SetName("V");
  v->SetNumberOfComponents(3);
  const int count = k == CloudKind::Empty ? 0 : (k == CloudKind::OnePoint ? 1 : n);
  double offset, scale;
  Transform(k, offset, scale);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < count; ++i)
  {
    double u = Halton(i + 1, 2), w = Halton(i + 1, 3), s = Halton(i + 1, 5);
    double x[3] = { u, w, s };
    switch (k)
    {
      case CloudKind::OnePoint:
      case CloudKind::Duplicates: x[0] = 0.3; x[1] = 0.4; x[2] = 0.5; break;
      case CloudKind::TwoDuplicates:
        x[0] = i % 2 ? 0.2 : 0.8; x[1] = 0.5; x[2] = 0.5; break;
      case CloudKind::Collinear: x[0] = u; x[1] = 0.5 * u + 0.1; x[2] = -0.25 * u + 0.7; break;
      case CloudKind::Coplanar: x[0] = u; x[1] = w; x[2] = 0.3 * u - 0.6 * w + 0.4; break;
      case CloudKind::Flat: x[2] = 0.0; break;
      default: break;
    }
    const double value = std::sin(3 * x[0]) + x[1] * x[1] - 0.5 * x[2];
    for (double& c : x)
    {
      c = offset + scale * c;
    }
    double vec[3] = { x[0] - offset, value, 1.0 };
    double fv = value;
    if (k == CloudKind::NaNCoords && i % 17 == 3)
    {
      x[i % 3] = (i % 2) ? nan : inf;
    }
    if (k == CloudKind::NaNValues && i % 13 == 5)
    {
      fv = (i % 2) ? nan : -inf;
      vec[1] = nan;
    }
    points->InsertNextPoint(x);
    f->InsertNextValue(fv);
    v->InsertNextTuple(vec);
  }
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  cloud->SetPoints(points);
  vtkNew<vtkCellArray> verts;
  for (vtkIdType i = 0; i < count; ++i)
  {
    verts->InsertNextCell(1, &i);
  }
  cloud->SetVerts(verts);
  cloud->GetPointData()->AddArray(f);
  cloud->GetPointData()->AddArray(v);
  return cloud;
}

inline bool HasNonFiniteCoordinates(CloudKind k) { return k == CloudKind::NaNCoords; }
inline bool HasNonFiniteValues(CloudKind k) { return k == CloudKind::NaNValues; }

} // namespace stress

#endif
