// Stress: the MLS interpolation kernel inside VTK's vtkPointInterpolator, the Point Neighbors filter and the
// MeshFree Kernel source, on hostile clouds and extreme parameters. Each case: no crash, no NaN/Inf out, the
// expected message, a defined result (masked points, zero neighbour counts, clamped parameters).
#include "StressCommon.h"

#include "vtkImageData.h"
#include "vtkMeshFreeKernelSource.h"
#include "vtkMeshFreeMLSKernel.h"
#include "vtkMeshFreePointNeighbors.h"
#include "vtkPointInterpolator.h"

#include <algorithm>

using namespace stress;

namespace
{
vtkSmartPointer<vtkPolyData> Probe(CloudKind k, int m = 30)
{
  double offset, scale;
  Transform(k, offset, scale);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int i = 0; i < m; ++i)
  {
    double x[3] = { 0.2 + 0.6 * Halton(i + 3, 2), 0.2 + 0.6 * Halton(i + 3, 3), 0.2 + 0.6 * Halton(i + 3, 5) };
    if (k == CloudKind::Flat)
    {
      x[2] = 0.0;
    }
    for (double& c : x)
    {
      c = offset + scale * c;
    }
    points->InsertNextPoint(x);
  }
  auto probe = vtkSmartPointer<vtkPolyData>::New();
  probe->SetPoints(points);
  return probe;
}

void MLSKernelCases(Suite& suite)
{
  for (CloudKind kind : AllKinds())
  {
    for (int degree = 0; degree <= 3; ++degree)
    {
      suite.Begin(std::string("MLS kernel, ") + Name(kind) + " degree " + std::to_string(degree));
      vtkNew<vtkMeshFreeMLSKernel> kernel;
      kernel->SetBasisDegree(degree);
      vtkNew<vtkPointInterpolator> interpolator;
      interpolator->SetKernel(kernel);
      interpolator->SetNullPointsStrategyToMaskPoints();
      interpolator->SetNullValue(-7.0);
      interpolator->SetValidPointsMaskArrayName("vtkValidPointMask");
      interpolator->SetInputData(Probe(kind));
      interpolator->SetSourceData(MakeCloud(kind));
      interpolator->Update();
      vtkDataSet* out = interpolator->GetOutput();
      CheckFinite(suite, out);
      suite.ExpectNoError();
      vtkDataArray* mask = out->GetPointData()->GetArray("vtkValidPointMask");
      vtkDataArray* f = out->GetPointData()->GetArray("F");
      if (kind == CloudKind::Empty)
      {
        // vtkPointInterpolator itself returns the probe without arrays for an empty source.
        continue;
      }
      if (!suite.Check(mask && f, "vtkValidPointMask or F missing"))
      {
        continue;
      }
      vtkIdType valid = 0;
      for (vtkIdType i = 0; i < mask->GetNumberOfTuples(); ++i)
      {
        valid += mask->GetComponent(i, 0) != 0;
        if (mask->GetComponent(i, 0) == 0)
        {
          suite.Check(f->GetComponent(i, 0) == -7.0, "a null point without NullValue");
        }
      }
      if (HasNonFiniteCoordinates(kind) || HasNonFiniteValues(kind))
      {
        suite.ExpectWarning("NaN/Inf");
      }
      if (kind == CloudKind::Volume || kind == CloudKind::Offset1e6 || kind == CloudKind::Scale1em6 ||
        kind == CloudKind::Scale1e6 || kind == CloudKind::NaNCoords || kind == CloudKind::NaNValues ||
        kind == CloudKind::Flat)
      {
        suite.Check(valid == mask->GetNumberOfTuples(), "null points inside an ordinary cloud");
      }
    }
  }
  for (double eps : { 1e-300, 1e-12 })
  {
    suite.Begin("MLS kernel, InverseDistance epsilon " + Str(eps) + " at the source points");
    vtkSmartPointer<vtkPolyData> cloud = MakeCloud(CloudKind::Volume, 80);
    vtkNew<vtkPolyData> on;
    on->SetPoints(cloud->GetPoints());
    vtkNew<vtkMeshFreeMLSKernel> kernel;
    kernel->SetWeightFunction(2);
    kernel->SetEpsilon(eps);
    kernel->SetBasisDegree(1);
    vtkNew<vtkPointInterpolator> interpolator;
    interpolator->SetKernel(kernel);
    interpolator->SetInputData(on);
    interpolator->SetSourceData(cloud);
    interpolator->Update();
    CheckFinite(suite, interpolator->GetOutput());
    suite.ExpectNoError();
    vtkDataArray* f = interpolator->GetOutput()->GetPointData()->GetArray("F");
    if (suite.Check(f != nullptr, "F missing"))
    {
      double worst = 0.0;
      for (vtkIdType i = 0; i < f->GetNumberOfTuples(); ++i)
      {
        worst = std::max(worst, std::abs(f->GetComponent(i, 0) - cloud->GetPointData()->GetArray("F")->GetComponent(i, 0)));
      }
      suite.Check(worst < 1e-6, "does not interpolate the data: error " + Str(worst));
    }
  }
  {
    suite.Begin("MLS kernel, SupportRadius 1e-12 (no support anywhere)");
    vtkNew<vtkMeshFreeMLSKernel> kernel;
    kernel->SetSupportRadius(1e-12);
    vtkNew<vtkPointInterpolator> interpolator;
    interpolator->SetKernel(kernel);
    interpolator->SetNullPointsStrategyToMaskPoints();
    interpolator->SetNullValue(-7.0);
    interpolator->SetValidPointsMaskArrayName("vtkValidPointMask");
    interpolator->SetInputData(Probe(CloudKind::Volume));
    interpolator->SetSourceData(MakeCloud(CloudKind::Volume));
    interpolator->Update();
    CheckFinite(suite, interpolator->GetOutput());
    vtkDataArray* mask = interpolator->GetOutput()->GetPointData()->GetArray("vtkValidPointMask");
    if (suite.Check(mask != nullptr, "mask missing"))
    {
      suite.Check(mask->GetRange(0)[1] == 0, "points valid without any support");
    }
  }
}

void PointNeighborsCases(Suite& suite)
{
  for (CloudKind kind : AllKinds())
  {
    for (int k : { 1, 10, 1000 })
    {
      for (double radius : { 0.0, 1e-12, 0.2, 1e200 })
      {
        suite.Begin(std::string("PointNeighbors, ") + Name(kind) + " k " + std::to_string(k) + " radius " +
          Str(radius));
        vtkNew<vtkMeshFreePointNeighbors> f;
        f->SetNeighborCount(k);
        f->SetSearchRadius(radius);
        vtkSmartPointer<vtkPolyData> cloud = MakeCloud(kind, 150);
        f->SetInputData(cloud);
        f->Update();
        vtkDataSet* out = vtkDataSet::SafeDownCast(f->GetOutputDataObject(0));
        if (!suite.Check(out != nullptr, "no output"))
        {
          continue;
        }
        // The input's points are passed through unchanged (NaN coordinates included, masked): check the
        // arrays the filter computes.
        vtkDataArray* mean = out->GetPointData()->GetArray("MeanNeighborDistance");
        vtkDataArray* mask = out->GetPointData()->GetArray("vtkValidPointMask");
        vtkDataArray* inRadius = out->GetPointData()->GetArray("NeighborsInRadius");
        const vtkIdType n = cloud->GetNumberOfPoints();
        suite.ExpectNoError();
        if (!suite.Check(mean && mask && mean->GetNumberOfTuples() == n && mask->GetNumberOfTuples() == n,
              "MeanNeighborDistance or vtkValidPointMask missing"))
        {
          continue;
        }
        suite.Check(FirstNonFinite(mean) < 0, "non-finite MeanNeighborDistance");
        suite.Check(radius <= 0 || (inRadius && FirstNonFinite(inRadius) < 0), "NeighborsInRadius missing");
        vtkIdType masked = 0;
        for (vtkIdType i = 0; i < n; ++i)
        {
          masked += mask->GetComponent(i, 0) == 0;
          if (mean->GetComponent(i, 0) < 0)
          {
            suite.Check(false, "negative mean distance");
            break;
          }
        }
        if (kind == CloudKind::Empty)
        {
          suite.ExpectWarning("no points");
        }
        else if (HasNonFiniteCoordinates(kind))
        {
          suite.ExpectWarning("NaN or Inf");
          suite.Check(masked > 0, "NaN points not masked");
        }
        else
        {
          suite.Check(masked == 0, "finite points masked");
        }
        if (kind == CloudKind::Duplicates && n > 1)
        {
          suite.Check(mean->GetRange(0)[1] == 0.0, "duplicates have a non-zero neighbour distance");
        }
        if (inRadius && radius > 1e100 && !HasNonFiniteCoordinates(kind) && n > 0)
        {
          suite.Check(inRadius->GetRange(0)[0] == n - 1 && inRadius->GetRange(0)[1] == n - 1,
            "a radius covering the cloud does not count every other point");
        }
        if (inRadius && radius == 1e-12 && kind == CloudKind::Volume)
        {
          suite.Check(inRadius->GetRange(0)[1] == 0, "neighbours within 1e-12 in a cloud without duplicates");
        }
      }
    }
  }
}

void KernelSourceCases(Suite& suite)
{
  for (int kernel = 0; kernel <= 11; ++kernel)
  {
    for (int dim = 1; dim <= 3; ++dim)
    {
      for (double radius : { 1e-300, 1e-100, 1e-6, 1.0, 1e6, 1e100, 1e300 })
      {
        for (double eps : { 1e-12, 1e6 })
        {
          if (eps != 1e-12 && kernel != 2)
          {
            continue;
          }
          suite.Begin("KernelSource kernel " + std::to_string(kernel) + " dim " + std::to_string(dim) + " h " +
            Str(radius) + " eps " + Str(eps));
          vtkNew<vtkMeshFreeKernelSource> source;
          source->SetKernel(kernel);
          source->SetDimension(dim);
          source->SetSupportRadius(radius);
          source->SetEpsilon(eps);
          source->SetResolution(9);
          source->Update();
          vtkImageData* out = source->GetOutput();
          CheckFinite(suite, out);
          vtkDataArray* value = out->GetPointData()->GetArray("Value");
          if (std::abs(std::log10(radius)) <= 10)
          {
            suite.ExpectSilent();
            suite.Check(value && value->GetNumberOfTuples() == 81, "an ordinary support gives no 9x9 Value image");
          }
          else if (!value)
          {
            // An extreme support may be refused, but then with a clear error naming it.
            suite.ExpectError("support radius");
          }
        }
      }
    }
  }
  {
    suite.Begin("KernelSource out-of-range settings are clamped");
    vtkNew<vtkMeshFreeKernelSource> source;
    source->SetKernel(99);
    source->SetDimension(7);
    source->SetSupportRadius(-1.0);
    source->SetEpsilon(0.0);
    source->SetResolution(1);
    suite.Check(source->GetKernel() == 11 && source->GetDimension() == 3 && source->GetSupportRadius() > 0 &&
        source->GetEpsilon() > 0 && source->GetResolution() == 2,
      "out-of-range settings not clamped");
    source->Update();
    CheckFinite(suite, source->GetOutput());
  }
}
}

int StressKernelsNeighbors(int, char*[])
{
  Suite suite;
  Window();
  MLSKernelCases(suite);
  PointNeighborsCases(suite);
  KernelSourceCases(suite);
  return suite.Finish("StressKernelsNeighbors");
}
