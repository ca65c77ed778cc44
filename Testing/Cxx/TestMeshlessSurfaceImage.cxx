// Image regression: the surface of the shipped torus scan (Data/scan_torus.pcd, 3,000 points from four
// scanners, no normals) by Meshless Surface, coloured by the scan's intensity approximated onto the vertices.
// WLS with NeighborCount 30 and SupportScale 3 bridges the band the scanners never saw: a closed torus.
#include "vtkMeshFreePCDReader.h"
#include "vtkMeshlessSurface.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkLookupTable.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"

#include <iostream>

int TestMeshlessSurfaceImage(int argc, char* argv[])
{
  vtkNew<vtkMeshFreePCDReader> reader;
  reader->SetFileName(MESHFREE_DATA_DIR "/scan_torus.pcd");
  vtkNew<vtkMeshlessSurface> surface;
  surface->SetInputConnection(reader->GetOutputPort());
  surface->SetMethodToWLS();
  surface->SetNeighborCount(30);
  surface->SetSupportScale(3.0);
  surface->Update();
  vtkPolyData* mesh = surface->GetOutput();
  vtkDataArray* intensity = mesh->GetPointData()->GetArray("intensity");
  if (mesh->GetNumberOfCells() < 1000 || !intensity)
  {
    std::cerr << "ERROR: no surface or no intensity on it (" << mesh->GetNumberOfCells() << " triangles)\n";
    return EXIT_FAILURE;
  }
  mesh->GetPointData()->SetActiveScalars("intensity");

  vtkNew<vtkLookupTable> colours;
  colours->SetHueRange(0.667, 0.0);
  colours->SetTableRange(0.0, 1.0);
  colours->Build();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(mesh);
  mapper->SetLookupTable(colours);
  mapper->SetScalarModeToUsePointData();
  mapper->SetScalarRange(0.0, 1.0);
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
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.0, -3.2, 2.4);
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  renderer->ResetCamera();
  camera->Zoom(1.3);
  window->Render();

  int result = vtkRegressionTestImage(window);
  if (result == vtkRegressionTester::DO_INTERACTOR)
  {
    interactor->Start();
  }
  // The test always runs with -V: NOT_RUN (no baseline given) is a failure too.
  return result == vtkRegressionTester::PASSED ? EXIT_SUCCESS : EXIT_FAILURE;
}
