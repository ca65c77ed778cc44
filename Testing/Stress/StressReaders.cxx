// Stress: the PCD and XYZ readers and the PCD writer through VTK, on malformed files generated here (never
// committed). Each case: no crash, no NaN/Inf point out (KeepInvalidPoints off), and either a clear error
// naming the file with an empty output, or a defined partial result.
#include "StressCommon.h"

#include "vtkMeshFreePCDReader.h"
#include "vtkMeshFreePCDWriter.h"
#include "vtkMeshFreeXYZReader.h"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>

using namespace stress;

namespace
{
std::string Dir()
{
  const char* env = std::getenv("MESHFREE_TEST_OUTPUT");
  return std::string(env && *env ? env : ".");
}

std::string Write(const std::string& name, const std::string& bytes)
{
  const std::string path = Dir() + "/stress_" + name;
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::string PCDHeader(const std::string& fields, const std::string& size, const std::string& type,
  const std::string& count, long width, long points, const std::string& data)
{
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " << fields << "\nSIZE " << size
    << "\nTYPE " << type << "\nCOUNT " << count << "\nWIDTH " << width << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS "
    << points << "\nDATA " << data << "\n";
  return h.str();
}

std::string Floats(std::initializer_list<float> values)
{
  std::string s;
  for (float v : values)
  {
    s.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  return s;
}

std::string U32(std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), sizeof v); }

enum class Expect
{
  Error,   // refused: an error naming the file, an empty output
  Points,  // read: at least one point, finite
  Either   // a defined outcome: one of the two, and never both an error and points
};

template <class Reader>
void Read(Suite& suite, const std::string& name, const std::string& bytes, Expect expect, vtkIdType points = -1,
  const char* word = nullptr, bool nanValues = false)
{
  suite.Begin(name);
  const std::string path = Write(name, bytes);
  vtkNew<Reader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkPolyData* out = reader->GetOutput();
  if (nanValues)
  {
    // NaN/Inf in a value field is data (PCL writes it): the points must still be finite.
    std::string what;
    vtkNew<vtkPolyData> pointsOnly;
    pointsOnly->SetPoints(out->GetPoints());
    const bool finite = AllFinite(pointsOnly.Get(), what);
    suite.Check(finite, "non-finite output: " + what);
  }
  else
  {
    CheckFinite(suite, out);
  }
  const vtkIdType n = out->GetNumberOfPoints();
  const bool error = Window()->Errors > 0;
  suite.Check(!(error && n > 0), "an error, but points are output");
  suite.Check(out->GetNumberOfVerts() == n, "not one vertex per point");
  if (expect == Expect::Error)
  {
    suite.ExpectError(path);
    if (word)
    {
      suite.ExpectError(word);
    }
  }
  else if (expect == Expect::Points)
  {
    suite.ExpectNoError();
    suite.Check(n > 0, "no points read");
    if (word)
    {
      suite.ExpectWarning(word);
    }
  }
  else if (error)
  {
    suite.ExpectError(path);
  }
  if (points >= 0)
  {
    suite.Check(n == points, "read " + std::to_string(n) + " points, expected " + std::to_string(points));
  }
  std::remove(path.c_str());
}

void PCDCases(Suite& suite)
{
  using R = vtkMeshFreePCDReader;
  const std::string xyz = PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 3, 3, "ascii");
  Read<R>(suite, "empty.pcd", "", Expect::Error);
  Read<R>(suite, "garbage.pcd", std::string("\x00\xff\x13\x37 not a pcd\n\n\x01", 20), Expect::Error);
  Read<R>(suite, "header-without-data-line.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n", Expect::Error);
  Read<R>(suite, "ascii-ok.pcd", xyz + "0 0 0\n1 2 3\n4 5 6\n", Expect::Points, 3);
  Read<R>(suite, "ascii-truncated.pcd", xyz + "0 0 0\n1 2", Expect::Either);
  Read<R>(suite, "ascii-non-numeric.pcd", xyz + "0 0 0\nfoo bar baz\n4 5 6\n", Expect::Either);
  Read<R>(suite, "ascii-nan-inf.pcd", xyz + "nan 0 0\n1 inf 3\n4 5 6\n", Expect::Points, 1, "dropped");
  Read<R>(suite, "ascii-overflow.pcd", xyz + "1e400 0 0\n1 2 3\n4 5 6\n", Expect::Either);
  Read<R>(suite, "ascii-all-nan.pcd", xyz + "nan nan nan\nnan 0 0\n0 nan 0\n", Expect::Either, 0);
  Read<R>(suite, "fields-size-mismatch.pcd", PCDHeader("x y z", "4 4", "F F F", "1 1 1", 3, 3, "ascii") + "0 0 0\n",
    Expect::Error);
  Read<R>(suite, "size-3.pcd", PCDHeader("x y z", "3 3 3", "F F F", "1 1 1", 1, 1, "binary") + "123456789",
    Expect::Error);
  Read<R>(suite, "type-X.pcd", PCDHeader("x y z", "4 4 4", "X X X", "1 1 1", 1, 1, "ascii") + "0 0 0\n", Expect::Error);
  Read<R>(suite, "count-0.pcd", PCDHeader("x y z", "4 4 4", "F F F", "0 1 1", 1, 1, "ascii") + "0 0\n", Expect::Either);
  Read<R>(suite, "count-negative.pcd", PCDHeader("x y z", "4 4 4", "F F F", "-1 1 1", 1, 1, "ascii") + "0 0\n",
    Expect::Error);
  Read<R>(suite, "count-huge.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 2000000000", 1, 1, "binary") + "abc",
    Expect::Error);
  Read<R>(suite, "points-huge-ascii.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 1000000000000L, 1000000000000L, "ascii") + "0 0 0\n",
    Expect::Either);
  Read<R>(suite, "points-huge-binary.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 4000000000L, 4000000000L, "binary") + Floats({ 1, 2, 3 }),
    Expect::Error);
  Read<R>(suite, "points-negative.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", -5, -5, "ascii") + "0 0 0\n",
    Expect::Error);
  Read<R>(suite, "width-mismatch.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 7, 3, "ascii") + "0 0 0\n1 1 1\n2 2 2\n",
    Expect::Either);
  Read<R>(suite, "binary-ok.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "binary") + Floats({ 1, 2, 3, 4, 5, 6 }),
    Expect::Points, 2);
  Read<R>(suite, "binary-truncated.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "binary") + Floats({ 1, 2, 3, 4 }),
    Expect::Error);
  Read<R>(suite, "binary-nan.pcd",
    PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "binary") +
      Floats({ std::numeric_limits<float>::quiet_NaN(), 2, 3, 4, 5, std::numeric_limits<float>::infinity() }),
    Expect::Either, 0);
  Read<R>(suite, "compressed-bogus-sizes.pcd",
    PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "binary_compressed") + U32(1000000000u) + U32(24u) + "xx",
    Expect::Error);
  Read<R>(suite, "compressed-zero-sizes.pcd",
    PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "binary_compressed") + U32(0u) + U32(0u), Expect::Error);
  Read<R>(suite, "compressed-garbage-lzf.pcd",
    PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "binary_compressed") + U32(8u) + U32(24u) +
      std::string("\xff\xff\xff\xff\xff\xff\xff\xff", 8),
    Expect::Error);
  Read<R>(suite, "compressed-uncompressed-too-big.pcd",
    PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "binary_compressed") + U32(4u) + U32(4000000000u) + "abcd",
    Expect::Error);
  Read<R>(suite, "unknown-data.pcd", PCDHeader("x y z", "4 4 4", "F F F", "1 1 1", 1, 1, "zip") + "0 0 0\n", Expect::Error);
  Read<R>(suite, "no-xyz-fields.pcd",
    PCDHeader("intensity", "4", "F", "1", 2, 2, "ascii") + "1\n2\n", Expect::Points, 2, "no x, y or z");
  Read<R>(suite, "duplicate-fields.pcd", PCDHeader("x x x", "4 4 4", "F F F", "1 1 1", 1, 1, "ascii") + "1 2 3\n",
    Expect::Either);
  Read<R>(suite, "very-long-line.pcd", xyz + std::string(1 << 20, '7') + " 0 0\n1 2 3\n4 5 6\n", Expect::Either);
  Read<R>(suite, "nan-intensity.pcd",
    PCDHeader("x y z intensity", "4 4 4 4", "F F F F", "1 1 1 1", 2, 2, "ascii") + "0 0 0 nan\n1 1 1 inf\n",
    Expect::Points, 2, nullptr, true);
}

void XYZCases(Suite& suite)
{
  using R = vtkMeshFreeXYZReader;
  Read<R>(suite, "empty.xyz", "", Expect::Either, 0);
  Read<R>(suite, "ok.xyz", "0 0 0\n1 2 3\n", Expect::Points, 2);
  Read<R>(suite, "crlf.pts", "0 0 0 5\r\n1 2 3 6\r\n", Expect::Points, 2);
  Read<R>(suite, "text.xyz", "hello world\nthis is not a cloud\n", Expect::Either, 0);
  Read<R>(suite, "two-columns.xyz", "0 0\n1 2\n", Expect::Either);
  Read<R>(suite, "ragged.xyz", "0 0 0\n1 2 3 4 5\n6 7\n8 9 10\n", Expect::Either);
  Read<R>(suite, "nan-inf.xyz", "nan 0 0\n0 inf 0\n1 2 3\n-inf 1 1\n", Expect::Points, 1, "dropped");
  Read<R>(suite, "overflow.xyz", "1e400 0 0\n1 2 3\n", Expect::Either);
  Read<R>(suite, "commas.xyz", "0,0,0\n1,2,3\n", Expect::Either);
  Read<R>(suite, "binary.xyz", std::string("\x00\x01\x02\xff\xfe\n\x00\x00", 8), Expect::Either, 0);
  std::string wide;
  for (int i = 0; i < 2000; ++i)
  {
    wide += std::to_string(i) + " ";
  }
  Read<R>(suite, "2000-columns.xyz", wide + "\n" + wide + "\n", Expect::Either);
  Read<R>(suite, "nan-values.xyz", "0 0 0 nan\n1 1 1 inf\n", Expect::Points, 2, nullptr, true);
  {
    suite.Begin("missing file");
    vtkNew<R> reader;
    reader->SetFileName((Dir() + "/stress_does_not_exist.xyz").c_str());
    reader->Update();
    suite.ExpectError("does_not_exist");
    suite.Check(reader->GetOutput()->GetNumberOfPoints() == 0, "points from a missing file");
  }
  {
    suite.Begin("no file name");
    vtkNew<vtkMeshFreePCDReader> reader;
    reader->Update();
    suite.ExpectError("FileName");
  }
}

void WriterCases(Suite& suite)
{
  for (int encoding = 0; encoding <= 2; ++encoding)
  {
    for (CloudKind kind : { CloudKind::Empty, CloudKind::OnePoint, CloudKind::NaNCoords, CloudKind::NaNValues,
           CloudKind::Offset1e6, CloudKind::Scale1e6, CloudKind::Scale1em6 })
    {
      suite.Begin(std::string("PCD writer round trip, encoding ") + std::to_string(encoding) + ", " + Name(kind));
      vtkSmartPointer<vtkPolyData> cloud = MakeCloud(kind, 100);
      const std::string path = Dir() + "/stress_roundtrip_" + std::to_string(encoding) + Name(kind) + ".pcd";
      vtkNew<vtkMeshFreePCDWriter> writer;
      writer->SetInputData(cloud);
      writer->SetFileName(path.c_str());
      writer->SetEncoding(encoding);
      writer->Write();
      suite.ExpectNoError();
      vtkNew<vtkMeshFreePCDReader> reader;
      reader->SetFileName(path.c_str());
      reader->Update();
      vtkPolyData* out = reader->GetOutput();
      if (kind != CloudKind::NaNValues)
      {
        CheckFinite(suite, out);
      }
      // Points must be finite; NaN values in F and V are data (PCL keeps them) and travel unchanged.
      bool finitePoints = true;
      for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
      {
        const double* x = out->GetPoint(i);
        finitePoints = finitePoints && std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
      }
      suite.Check(finitePoints, "non-finite point read back");
      vtkIdType finiteIn = 0;
      for (vtkIdType i = 0; i < cloud->GetNumberOfPoints(); ++i)
      {
        const double* x = cloud->GetPoint(i);
        finiteIn += std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
      }
      suite.Check(out->GetNumberOfPoints() == finiteIn, "read back " + std::to_string(out->GetNumberOfPoints()) +
          " points of " + std::to_string(finiteIn) + " finite ones");
      if (kind == CloudKind::NaNCoords)
      {
        suite.ExpectWarning("dropped");
      }
      // Coordinates survive to float precision (PCD stores x, y, z as float by default).
      double worst = 0.0;
      for (vtkIdType i = 0, j = 0; i < cloud->GetNumberOfPoints() && j < out->GetNumberOfPoints(); ++i)
      {
        const double* x = cloud->GetPoint(i);
        if (!(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])))
        {
          continue;
        }
        double a[3] = { x[0], x[1], x[2] };
        const double* b = out->GetPoint(j++);
        for (int c = 0; c < 3; ++c)
        {
          worst = std::max(worst, std::abs(a[c] - b[c]) / std::max(1.0, std::abs(a[c])));
        }
      }
      suite.Check(worst < 1e-6, "coordinates changed by a relative " + Str(worst));
      std::remove(path.c_str());
    }
  }
  {
    suite.Begin("PCD writer to an unwritable path");
    vtkNew<vtkMeshFreePCDWriter> writer;
    writer->SetInputData(MakeCloud(CloudKind::Volume, 10));
    const std::string path = Dir() + "/no_such_directory/x.pcd";
    writer->SetFileName(path.c_str());
    writer->Write();
    suite.ExpectError("no_such_directory");
  }
}
}

int StressReaders(int, char*[])
{
  Suite suite;
  Window();
  PCDCases(suite);
  XYZCases(suite);
  WriterCases(suite);
  return suite.Finish("StressReaders");
}
