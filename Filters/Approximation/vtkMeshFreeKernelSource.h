/**
 * @class   vtkMeshFreeKernelSource
 * @brief   samples one of MeshFree's weight functions on a plane, for plotting and inspection
 *
 * Produces a `vtkImageData` slice (z = 0) over [-1.2 h, 1.2 h]² with point arrays `Value` (W), `Gradient`
 * (∇W, 3 components) and `Laplacian` (∇²W) of the kernel chosen by `Kernel`, evaluated by the VTK-free core
 * (meshfree::Kernel) with its normalisation for `Dimension` (1, 2 or 3; in 1D only the x axis matters).
 * Kernel numbers follow meshfree::KernelType: 0 Gaussian, 1 Wendland, 2 InverseDistance, 3 Poly6, 4 W2,
 * 5 W3, 6 W4, 7 W5, 8 Lucy, 9 Spiky, 10 Viscosity, 11 CubicSpline.
 */
#ifndef vtkMeshFreeKernelSource_h
#define vtkMeshFreeKernelSource_h

#include "MeshFreeFiltersModule.h"
#include "vtkImageAlgorithm.h"

class MESHFREEFILTERS_EXPORT vtkMeshFreeKernelSource : public vtkImageAlgorithm
{
public:
  static vtkMeshFreeKernelSource* New();
  vtkTypeMacro(vtkMeshFreeKernelSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /** Which weight function (see the class description). Default 1 (Wendland). */
  vtkSetClampMacro(Kernel, int, 0, 11);
  vtkGetMacro(Kernel, int);
  ///@}

  ///@{
  /** Dimension of the normalisation and of the Laplacian: 1, 2 or 3. Default 2. */
  vtkSetClampMacro(Dimension, int, 1, 3);
  vtkGetMacro(Dimension, int);
  ///@}

  ///@{
  /** Support radius h: every compactly supported kernel vanishes for r ≥ h. Default 1. */
  vtkSetClampMacro(SupportRadius, double, 1e-300, VTK_DOUBLE_MAX);
  vtkGetMacro(SupportRadius, double);
  ///@}

  ///@{
  /** ε of the inverse-distance weight, relative to h. Default 0.1. */
  vtkSetClampMacro(Epsilon, double, 1e-12, VTK_DOUBLE_MAX);
  vtkGetMacro(Epsilon, double);
  ///@}

  ///@{
  /** Samples along each axis of the plane. Default 101. */
  vtkSetClampMacro(Resolution, int, 2, 10000);
  vtkGetMacro(Resolution, int);
  ///@}

protected:
  vtkMeshFreeKernelSource();
  ~vtkMeshFreeKernelSource() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Kernel = 1;
  int Dimension = 2;
  double SupportRadius = 1.0;
  double Epsilon = 0.1;
  int Resolution = 101;

private:
  vtkMeshFreeKernelSource(const vtkMeshFreeKernelSource&) = delete;
  void operator=(const vtkMeshFreeKernelSource&) = delete;
};

#endif
