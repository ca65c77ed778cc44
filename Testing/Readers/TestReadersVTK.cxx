// The VTK readers and the writer of MeshFree::Readers: outputs (points, vertex cells, typed arrays, colours,
// field data), write -> read round trips in every encoding, and bad files (error message, empty output).
#include "vtkMeshFreePCDReader.h"
#include "vtkMeshFreePCDWriter.h"
#include "vtkMeshFreeXYZReader.h"

#include "ReaderTestSupport.h"

#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkShortArray.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnsignedLongLongArray.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

using namespace meshfree_test;

namespace
{
std::string DataFile(const char* name)
{
  return std::string(MESHFREE_READERS_TEST_DATA) + "/" + name;
}
std::string OutFile(const std::string& name)
{
  return std::string(MESHFREE_READERS_TEST_OUTPUT) + "/" + name;
}
} // namespace

TEST(ReadersVTK, PCDReaderOnPCLFileWithRgbAndNaN)
{
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreePCDReader>(DataFile("pcl_xyzrgb_ascii.pcd"), msg);
  EXPECT_TRUE(msg->Errors.empty()) << msg->Errors;
  EXPECT_NE(msg->Warnings.find("dropped 1 of 4"), std::string::npos) << msg->Warnings;
  ASSERT_EQ(out->GetNumberOfPoints(), 3);
  EXPECT_EQ(out->GetNumberOfVerts(), 3);
  EXPECT_EQ(out->GetPoints()->GetDataType(), VTK_FLOAT);
  EXPECT_FLOAT_EQ(out->GetPoint(2)[2], -0.5f);
  auto* rgb = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("rgb"));
  ASSERT_NE(rgb, nullptr);
  ASSERT_EQ(rgb->GetNumberOfComponents(), 3);
  EXPECT_EQ(rgb->GetTypedComponent(0, 0), 255);
  EXPECT_EQ(rgb->GetTypedComponent(1, 1), 255);
  EXPECT_EQ(rgb->GetTypedComponent(2, 0), 0x10);
  EXPECT_EQ(rgb->GetTypedComponent(2, 1), 0x20);
  EXPECT_EQ(rgb->GetTypedComponent(2, 2), 0x30);
  EXPECT_EQ(out->GetPointData()->GetArray("PixelIndex"), nullptr); // unorganised: no pixel index
  auto* vp = out->GetFieldData()->GetArray("Viewpoint");
  ASSERT_NE(vp, nullptr);
  EXPECT_EQ(vp->GetNumberOfTuples(), 7);
  EXPECT_EQ(vp->GetComponent(3, 0), 1.0);

  vtkNew<MessageCatcher> kept;
  out = Read<vtkMeshFreePCDReader>(DataFile("pcl_xyzrgb_ascii.pcd"), kept, true);
  EXPECT_EQ(out->GetNumberOfPoints(), 4);
  EXPECT_TRUE(std::isnan(out->GetPoint(2)[0]));
  EXPECT_TRUE(kept->Warnings.empty());
}

TEST(ReadersVTK, PCDReaderOrganisedCompressedRgba)
{
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreePCDReader>(DataFile("pcl_xyzrgba_organised_compressed.pcd"), msg);
  ASSERT_EQ(out->GetNumberOfPoints(), 4);
  auto* rgba = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("rgba"));
  ASSERT_NE(rgba, nullptr);
  ASSERT_EQ(rgba->GetNumberOfComponents(), 4);
  EXPECT_EQ(rgba->GetTypedComponent(1, 0), 255); // 0x80FF0000: red, alpha 0x80
  EXPECT_EQ(rgba->GetTypedComponent(1, 3), 0x80);
  auto* dims = out->GetFieldData()->GetArray("OrganizedDimensions");
  ASSERT_NE(dims, nullptr);
  EXPECT_EQ(dims->GetComponent(0, 0), 2);
  EXPECT_EQ(dims->GetComponent(1, 0), 2);
}

TEST(ReadersVTK, PCDReaderKeepsPixelIndexOfOrganisedClouds)
{
  const std::string path = OutFile("organised_nan.pcd");
  WriteText(path, "FIELDS x y z i\nSIZE 8 8 8 2\nTYPE F F F I\nCOUNT 1 1 1 2\nWIDTH 3\nHEIGHT 2\nPOINTS 6\n"
                  "DATA ascii\n0 0 0 1 -1\nnan nan nan 0 0\n2 0 0 3 -3\n0 1 0 4 -4\n1 1 nan 0 0\n2 1 0 6 -6\n");
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreePCDReader>(path, msg);
  ASSERT_EQ(out->GetNumberOfPoints(), 4);
  EXPECT_EQ(out->GetPoints()->GetDataType(), VTK_DOUBLE);
  auto* pixel = vtkIdTypeArray::SafeDownCast(out->GetPointData()->GetArray("PixelIndex"));
  ASSERT_NE(pixel, nullptr);
  EXPECT_EQ(pixel->GetValue(0), 0);
  EXPECT_EQ(pixel->GetValue(1), 2);
  EXPECT_EQ(pixel->GetValue(2), 3);
  EXPECT_EQ(pixel->GetValue(3), 5);
  auto* i = vtkShortArray::SafeDownCast(out->GetPointData()->GetArray("i"));
  ASSERT_NE(i, nullptr);
  ASSERT_EQ(i->GetNumberOfComponents(), 2);
  EXPECT_EQ(i->GetTypedComponent(3, 1), -6);
}

TEST(ReadersVTK, PCDWriterRoundTripsThroughTheReader)
{
  vtkNew<vtkPolyData> pd;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToFloat();
  const int n = 37;
  for (int i = 0; i < n; ++i)
    pts->InsertNextPoint(0.1 * i, -0.25 * i, 1e3 + i);
  pd->SetPoints(pts);
  vtkNew<vtkDoubleArray> normals;
  normals->SetName("Normals with space");
  normals->SetNumberOfComponents(3);
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetName("rgb");
  rgb->SetNumberOfComponents(3);
  vtkNew<vtkIntArray> label;
  label->SetName("label");
  vtkNew<vtkUnsignedLongLongArray> big;
  big->SetName("big");
  for (int i = 0; i < n; ++i)
  {
    normals->InsertNextTuple3(std::sin(i), std::cos(i), 1.0 / (i + 1));
    rgb->InsertNextTuple3(i * 7 % 256, 255 - i, i);
    label->InsertNextValue(-1000 * i);
    big->InsertNextValue(0xFFFFFFFFFFFFull * i);
  }
  pd->GetPointData()->AddArray(normals);
  pd->GetPointData()->AddArray(rgb);
  pd->GetPointData()->AddArray(label);
  pd->GetPointData()->AddArray(big);
  for (int enc = 0; enc < 3; ++enc)
  {
    SCOPED_TRACE(enc);
    const std::string path = OutFile("writer_roundtrip_" + std::to_string(enc) + ".pcd");
    vtkNew<vtkMeshFreePCDWriter> writer;
    writer->SetInputData(pd);
    writer->SetFileName(path.c_str());
    writer->SetEncoding(enc);
    ASSERT_EQ(writer->Write(), 1);
    vtkNew<MessageCatcher> msg;
    auto out = Read<vtkMeshFreePCDReader>(path, msg);
    EXPECT_TRUE(msg->Errors.empty()) << msg->Errors;
    ASSERT_EQ(out->GetNumberOfPoints(), n);
    EXPECT_EQ(out->GetPoints()->GetDataType(), VTK_FLOAT);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(out->GetPoint(i)[k], pd->GetPoint(i)[k]);
    auto* nr = vtkDoubleArray::SafeDownCast(out->GetPointData()->GetArray("Normals_with_space"));
    auto* c = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("rgb"));
    auto* l = vtkIntArray::SafeDownCast(out->GetPointData()->GetArray("label"));
    auto* b = vtkUnsignedLongLongArray::SafeDownCast(out->GetPointData()->GetArray("big"));
    ASSERT_TRUE(nr && c && l && b);
    ASSERT_EQ(nr->GetNumberOfComponents(), 3);
    for (int i = 0; i < n; ++i)
    {
      for (int k = 0; k < 3; ++k)
      {
        ASSERT_EQ(nr->GetTypedComponent(i, k), normals->GetTypedComponent(i, k));
        ASSERT_EQ(c->GetTypedComponent(i, k), rgb->GetTypedComponent(i, k));
      }
      ASSERT_EQ(l->GetValue(i), label->GetValue(i));
      ASSERT_EQ(b->GetValue(i), big->GetValue(i));
    }
  }
}

TEST(ReadersVTK, PCDReaderMakesPCLNormalsTheActiveNormals)
{
  // x y z _ normal_x normal_y normal_z _ curvature (PCL's PointNormal, binary); point 2 is invalid (NaN).
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreePCDReader>(DataFile("pcl_pointnormal_binary.pcd"), msg);
  EXPECT_TRUE(msg->Errors.empty()) << msg->Errors;
  ASSERT_EQ(out->GetNumberOfPoints(), 3);
  auto* normals = vtkFloatArray::SafeDownCast(out->GetPointData()->GetNormals());
  ASSERT_NE(normals, nullptr);
  EXPECT_STREQ(normals->GetName(), "Normals");
  ASSERT_EQ(normals->GetNumberOfComponents(), 3);
  EXPECT_EQ(normals->GetTypedComponent(0, 2), 1.0f);
  EXPECT_EQ(normals->GetTypedComponent(1, 0), 0.6f);
  EXPECT_EQ(normals->GetTypedComponent(1, 1), 0.8f);
  EXPECT_EQ(normals->GetTypedComponent(2, 0), 1.0f); // the file's point 3, after the dropped one
  auto* curvature = out->GetPointData()->GetArray("curvature");
  ASSERT_NE(curvature, nullptr);
  EXPECT_EQ(curvature->GetComponent(1, 0), 0.25);
  EXPECT_EQ(out->GetPointData()->GetNumberOfArrays(), 2); // Normals, curvature: no normal_x, no "_"

  // Normals that are not one floating triple stay separate arrays.
  const std::string path = OutFile("normals_mixed.pcd");
  WriteText(path, "FIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 8\nTYPE F F F F F F\nWIDTH 1\nPOINTS 1\n"
                  "DATA ascii\n0 0 0 1 0 0\n");
  out = Read<vtkMeshFreePCDReader>(path, msg);
  EXPECT_EQ(out->GetPointData()->GetNormals(), nullptr);
  EXPECT_NE(out->GetPointData()->GetArray("normal_z"), nullptr);
}

TEST(ReadersVTK, PCDWriterWritesNormalsAsPCLsFieldsAndFloatsByDefault)
{
  vtkNew<vtkPolyData> pd;
  vtkNew<vtkPoints> pts; // double points, as VTK pipelines make them
  vtkNew<vtkDoubleArray> normals;
  normals->SetName("MyNormals");
  normals->SetNumberOfComponents(3);
  for (int i = 0; i < 10; ++i)
  {
    pts->InsertNextPoint(0.1 * i, 1.0 / 3.0, -2.0 * i);
    normals->InsertNextTuple3(0.6, 0.0, -0.8);
  }
  pd->SetPoints(pts);
  pd->GetPointData()->SetNormals(normals);
  const std::string path = OutFile("writer_normals.pcd");
  vtkNew<vtkMeshFreePCDWriter> writer;
  writer->SetInputData(pd);
  writer->SetFileName(path.c_str());
  EXPECT_EQ(writer->GetWriteDoubleCoordinates(), 0);
  ASSERT_EQ(writer->Write(), 1);
  EXPECT_NE(ReadBytes(path).find("FIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\nTYPE F F F F F F\n"),
    std::string::npos);
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreePCDReader>(path, msg);
  ASSERT_EQ(out->GetNumberOfPoints(), 10);
  EXPECT_EQ(out->GetPoints()->GetDataType(), VTK_FLOAT);
  for (int i = 0; i < 10; ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(out->GetPoint(i)[k], static_cast<float>(pts->GetPoint(i)[k]));
  ASSERT_NE(out->GetPointData()->GetNormals(), nullptr);
  EXPECT_EQ(out->GetPointData()->GetNormals()->GetComponent(9, 2), -0.8f);
}

TEST(ReadersVTK, PCDWriterDoubleCoordinatesOnRequest)
{
  // Far from the origin floats move points by centimetres: the writer warns, and keeps doubles on request.
  vtkNew<vtkPolyData> cloud;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int i = 0; i < 20; ++i)
    points->InsertNextPoint(512345.678 + 0.001 * i, 4123456.789 - 0.002 * i, 12.5 + 1e-6 * i);
  cloud->SetPoints(points);
  vtkNew<vtkMeshFreePCDWriter> writer;
  vtkNew<MessageCatcher> msg;
  writer->AddObserver(vtkCommand::WarningEvent, msg);
  writer->SetInputData(cloud);
  writer->SetFileName(OutFile("far.pcd").c_str());
  ASSERT_EQ(writer->Write(), 1);
  EXPECT_NE(msg->Warnings.find("WriteDoubleCoordinates"), std::string::npos) << msg->Warnings;
  EXPECT_NE(ReadBytes(OutFile("far.pcd")).find("SIZE 4 4 4"), std::string::npos);
  writer->WriteDoubleCoordinatesOn();
  vtkNew<MessageCatcher> quiet;
  writer->AddObserver(vtkCommand::WarningEvent, quiet);
  ASSERT_EQ(writer->Write(), 1);
  EXPECT_TRUE(quiet->Warnings.empty()) << quiet->Warnings;
  EXPECT_NE(ReadBytes(OutFile("far.pcd")).find("SIZE 8 8 8"), std::string::npos);
  vtkNew<MessageCatcher> rmsg;
  auto out = Read<vtkMeshFreePCDReader>(OutFile("far.pcd"), rmsg);
  ASSERT_EQ(out->GetNumberOfPoints(), 20);
  EXPECT_EQ(out->GetPoints()->GetDataType(), VTK_DOUBLE);
  for (vtkIdType i = 0; i < 20; ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(out->GetPoint(i)[k], points->GetPoint(i)[k]);
}

TEST(ReadersVTK, BadFilesGiveAnErrorAndAnEmptyOutput)
{
  const std::string truncated = OutFile("truncated.pcd");
  WriteText(truncated, "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nPOINTS 3\nDATA binary\n0123456789");
  const std::string badxyz = OutFile("bad.xyz");
  WriteText(badxyz, "1 2 3\n4 5 six\n");
  struct Case
  {
    std::string Path;
    bool Pcd;
    const char* Expect;
  };
  const Case cases[] = { { truncated, true, "truncated binary" }, { badxyz, false, "line 2" },
    { OutFile("does_not_exist.pcd"), true, "cannot open" }, { OutFile("does_not_exist.xyz"), false, "cannot open" } };
  for (const Case& c : cases)
  {
    vtkNew<MessageCatcher> msg;
    auto out = c.Pcd ? Read<vtkMeshFreePCDReader>(c.Path, msg) : Read<vtkMeshFreeXYZReader>(c.Path, msg);
    EXPECT_NE(msg->Errors.find(c.Expect), std::string::npos) << msg->Errors;
    EXPECT_EQ(out->GetNumberOfPoints(), 0);
    EXPECT_EQ(out->GetPointData()->GetNumberOfArrays(), 0);
  }
  vtkNew<vtkMeshFreePCDReader> pcd;
  EXPECT_EQ(pcd->CanReadFile(truncated.c_str()), 1); // the header is fine; the data is not
  EXPECT_EQ(pcd->CanReadFile(badxyz.c_str()), 0);
  vtkNew<vtkMeshFreeXYZReader> xyz;
  EXPECT_EQ(xyz->CanReadFile(truncated.c_str()), 0);
  EXPECT_EQ(xyz->CanReadFile(OutFile("does_not_exist.xyz").c_str()), 0);
}

TEST(ReadersVTK, XYZReaderLeicaPtsWithIntensityAndColour)
{
  const std::string path = OutFile("leica.pts");
  WriteText(path, "3\n1 2 3 -200 255 0 10\n4 5 6 100 0 128 20\nnan 0 0 5 1 2 3\n");
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreeXYZReader>(path, msg);
  EXPECT_TRUE(msg->Errors.empty()) << msg->Errors;
  EXPECT_NE(msg->Warnings.find("dropped 1 of 3"), std::string::npos) << msg->Warnings;
  ASSERT_EQ(out->GetNumberOfPoints(), 2);
  EXPECT_EQ(out->GetNumberOfVerts(), 2);
  EXPECT_EQ(out->GetPoints()->GetDataType(), VTK_DOUBLE);
  auto* intensity = out->GetPointData()->GetArray("Intensity");
  auto* rgb = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("RGB"));
  ASSERT_TRUE(intensity && rgb);
  EXPECT_EQ(intensity->GetComponent(0, 0), -200);
  EXPECT_EQ(rgb->GetTypedComponent(1, 1), 128);
  EXPECT_EQ(out->GetPointData()->GetNumberOfArrays(), 2);
}

TEST(ReadersVTK, XYZReaderHeaderNamesArrays)
{
  const std::string path = OutFile("named.xyz");
  WriteText(path, "x,y,z,temperature,r,g,b\n0,0,0,20.5,0.5,0.1,0.2\n1,0,0,21.5,1,0.2,0.3\n");
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreeXYZReader>(path, msg);
  ASSERT_EQ(out->GetNumberOfPoints(), 2);
  ASSERT_NE(out->GetPointData()->GetArray("temperature"), nullptr);
  EXPECT_EQ(out->GetPointData()->GetArray("temperature")->GetComponent(1, 0), 21.5);
  // r g b that are not 0-255 integers stay separate double arrays.
  EXPECT_EQ(out->GetPointData()->GetArray("RGB"), nullptr);
  ASSERT_NE(out->GetPointData()->GetArray("g"), nullptr);
  EXPECT_EQ(out->GetPointData()->GetArray("g")->GetComponent(0, 0), 0.1);
}

TEST(ReadersVTK, XYZReaderDropsOrKeepsInvalidRowsWithAlignedArrays)
{
  const std::string path = OutFile("invalid_rows.xyz");
  WriteText(path, "x y z v\n0 0 0 10\n1 nan 0 11\n2 0 0 12\ninf 0 0 13\n4 0 0 14\n");
  for (bool keep : { false, true })
  {
    SCOPED_TRACE(keep);
    vtkNew<MessageCatcher> msg;
    auto out = Read<vtkMeshFreeXYZReader>(path, msg, keep);
    EXPECT_TRUE(msg->Errors.empty()) << msg->Errors;
    EXPECT_EQ(msg->Warnings.find("dropped 2 of 5") != std::string::npos, !keep) << msg->Warnings;
    const vtkIdType n = keep ? 5 : 3;
    ASSERT_EQ(out->GetNumberOfPoints(), n);
    ASSERT_EQ(out->GetNumberOfVerts(), n);
    auto* v = out->GetPointData()->GetArray("v");
    ASSERT_NE(v, nullptr);
    ASSERT_EQ(v->GetNumberOfTuples(), n);
    const double kept[] = { 10, 12, 14 };
    for (vtkIdType i = 0; i < n; ++i)
    {
      // The value column stays with its point: v = 10 + x wherever x is finite.
      EXPECT_EQ(v->GetComponent(i, 0), keep ? 10.0 + i : kept[i]);
      if (std::isfinite(out->GetPoint(i)[0]))
        EXPECT_EQ(v->GetComponent(i, 0), 10.0 + out->GetPoint(i)[0]);
    }
  }
  WriteText(path, "nan 0 0\n0 nan 0\n");
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreeXYZReader>(path, msg);
  EXPECT_NE(msg->Warnings.find("dropped 2 of 2"), std::string::npos) << msg->Warnings;
  EXPECT_EQ(out->GetNumberOfPoints(), 0);
  EXPECT_EQ(out->GetNumberOfVerts(), 0);
}

TEST(ReadersVTK, XYZReaderClaimsAndRefusesDamagedBinaryFiles)
{
  const std::string path = OutFile("damaged.xyz");
  WriteText(path, std::string("\x00\x01\x02\xff\xfe\n\x00\x00", 8));
  vtkNew<vtkMeshFreeXYZReader> probe;
  EXPECT_EQ(probe->CanReadFile(path.c_str()), 1); // not left to the PLOT3D reader, which aborts on it
  vtkNew<MessageCatcher> msg;
  auto out = Read<vtkMeshFreeXYZReader>(path, msg);
  EXPECT_NE(msg->Errors.find("binary data"), std::string::npos) << msg->Errors;
  EXPECT_EQ(out->GetNumberOfPoints(), 0);
  EXPECT_EQ(out->GetNumberOfCells(), 0);
  // A PLOT3D grid (Fortran records) is still declined.
  const unsigned char grid[] = { 12, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 12, 0, 0, 0, 48, 0, 0, 0 };
  WriteText(path, std::string(reinterpret_cast<const char*>(grid), sizeof(grid)));
  EXPECT_EQ(probe->CanReadFile(path.c_str()), 0);
}
