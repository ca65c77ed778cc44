// Image regression: the 2D Wendland kernel from the core, warped by its value and coloured by its Laplacian.
#include "vtkMeshFreeKernelSource.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkDataSetSurfaceFilter.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyDataMapper.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkWarpScalar.h"

int TestKernelSourceImage(int argc, char* argv[])
{
  vtkNew<vtkMeshFreeKernelSource> source;
  source->SetKernel(1); // Wendland
  source->SetDimension(2);
  source->SetSupportRadius(1.0);
  source->SetResolution(81);

  vtkNew<vtkDataSetSurfaceFilter> surface;
  surface->SetInputConnection(source->GetOutputPort());
  vtkNew<vtkWarpScalar> warp;
  warp->SetInputConnection(surface->GetOutputPort());
  warp->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Value");
  warp->SetScaleFactor(0.4);
  warp->Update();
  vtkPointSet* warped = vtkPointSet::SafeDownCast(warp->GetOutput());
  warped->GetPointData()->SetActiveScalars("Laplacian");

  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(vtkPolyData::SafeDownCast(warped));
  mapper->SetScalarModeToUsePointData();
  double range[2];
  warped->GetPointData()->GetArray("Laplacian")->GetRange(range);
  mapper->SetScalarRange(range);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  renderer->SetBackground(1, 1, 1);
  vtkNew<vtkRenderWindow> window;
  window->SetSize(400, 300);
  window->AddRenderer(renderer);
  vtkNew<vtkRenderWindowInteractor> interactor;
  interactor->SetRenderWindow(window);
  renderer->GetActiveCamera()->Elevation(-60);
  renderer->GetActiveCamera()->Azimuth(20);
  renderer->ResetCamera();
  renderer->GetActiveCamera()->Zoom(1.6);
  window->Render();

  int result = vtkRegressionTestImage(window);
  if (result == vtkRegressionTester::DO_INTERACTOR)
  {
    interactor->Start();
  }
  // The test always runs with -V: NOT_RUN (no baseline given) is a failure too.
  return result == vtkRegressionTester::PASSED ? EXIT_SUCCESS : EXIT_FAILURE;
}
