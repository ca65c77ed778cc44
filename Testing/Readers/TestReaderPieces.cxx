// The readers' pieces without MPI: piece p of N asked through the streaming pipeline (UpdatePiece), for N = 1..5,
// concatenated in order, must be the whole read bit for bit (points, every array, field data), every point once;
// empty pieces keep the arrays. PCD in every encoding (organised clouds with invalid points too) and text clouds
// with CRLF, comments, blank lines, a count line, no final newline, colour columns.
#include "vtkMeshFreePCDReader.h"
#include "vtkMeshFreeXYZReader.h"

#include "PCDFormat.h"
#include "ReaderTestSupport.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace meshfree_test;
namespace pcd = meshfree::pcd;

namespace
{
std::string OutFile(const std::string& name)
{
  return std::string(MESHFREE_READERS_TEST_OUTPUT) + "/" + name;
}

// Piece `piece` of `pieces` of a file (a fresh reader each time, as on a rank).
template <class Reader>
vtkSmartPointer<vtkPolyData> ReadPiece(const std::string& path, int piece, int pieces, MessageCatcher* catcher,
  bool keepInvalid = false)
{
  vtkNew<Reader> reader;
  reader->SetFileName(path.c_str());
  reader->SetKeepInvalidPoints(keepInvalid);
  reader->AddObserver(vtkCommand::ErrorEvent, catcher);
  reader->AddObserver(vtkCommand::WarningEvent, catcher);
  reader->UpdatePiece(piece, pieces, 0);
  vtkSmartPointer<vtkPolyData> out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(reader->GetOutput());
  return out;
}

std::size_t Bytes(vtkDataArray* a)
{
  return static_cast<std::size_t>(a->GetDataTypeSize()) * a->GetNumberOfComponents();
}

// Tuples [offset, offset + part's count) of `whole` equal `part`, byte for byte.
void ExpectSameTuples(vtkDataArray* whole, vtkDataArray* part, vtkIdType offset, const std::string& what)
{
  ASSERT_NE(part, nullptr) << what;
  EXPECT_EQ(part->GetDataType(), whole->GetDataType()) << what;
  ASSERT_EQ(part->GetNumberOfComponents(), whole->GetNumberOfComponents()) << what;
  const vtkIdType m = part->GetNumberOfTuples();
  ASSERT_LE(offset + m, whole->GetNumberOfTuples()) << what;
  if (m > 0)
    EXPECT_EQ(std::memcmp(static_cast<const char*>(whole->GetVoidPointer(0)) + offset * Bytes(whole),
                part->GetVoidPointer(0), m * Bytes(whole)),
      0)
      << what << ": values differ";
}

// Reads the whole file and every piece of N = 1..5 and checks that the pieces tile the whole output. largest: the
// largest piece of each N (checks of the shares' sizes).
template <class Reader>
void ExpectPiecesTileTheFile(
  const std::string& path, bool keepInvalid = false, std::vector<vtkIdType>* largest = nullptr, int maxPieces = 5)
{
  vtkNew<MessageCatcher> msg;
  auto whole = Read<Reader>(path, msg, keepInvalid);
  EXPECT_EQ(msg->Errors, "") << path;
  const vtkIdType n = whole->GetNumberOfPoints();
  for (int pieces = 1; pieces <= maxPieces; ++pieces)
  {
    vtkIdType offset = 0, most = 0;
    for (int piece = 0; piece < pieces; ++piece)
    {
      const std::string what = path + ": piece " + std::to_string(piece) + " of " + std::to_string(pieces);
      vtkNew<MessageCatcher> pmsg;
      auto part = ReadPiece<Reader>(path, piece, pieces, pmsg, keepInvalid);
      EXPECT_EQ(pmsg->Errors, "") << what;
      const vtkIdType m = part->GetNumberOfPoints();
      most = std::max(most, m);
      EXPECT_EQ(part->GetNumberOfVerts(), m) << what;
      ASSERT_NE(part->GetPoints(), nullptr) << what;
      ExpectSameTuples(whole->GetPoints()->GetData(), part->GetPoints()->GetData(), offset, what + ", points");
      vtkPointData* wp = whole->GetPointData();
      vtkPointData* pp = part->GetPointData();
      ASSERT_EQ(pp->GetNumberOfArrays(), wp->GetNumberOfArrays()) << what;
      for (int a = 0; a < wp->GetNumberOfArrays(); ++a)
      {
        EXPECT_STREQ(pp->GetArrayName(a), wp->GetArrayName(a)) << what;
        ExpectSameTuples(wp->GetArray(a), pp->GetArray(a), offset, what + ", " + wp->GetArrayName(a));
      }
      EXPECT_EQ(pp->GetNormals() != nullptr, wp->GetNormals() != nullptr) << what;
      vtkFieldData* wf = whole->GetFieldData();
      vtkFieldData* pf = part->GetFieldData();
      ASSERT_EQ(pf->GetNumberOfArrays(), wf->GetNumberOfArrays()) << what;
      for (int a = 0; a < wf->GetNumberOfArrays(); ++a)
      {
        EXPECT_STREQ(pf->GetArrayName(a), wf->GetArrayName(a)) << what;
        ExpectSameTuples(wf->GetArray(a), pf->GetArray(a), 0, what + ", field data " + wf->GetArrayName(a));
        EXPECT_EQ(pf->GetArray(a)->GetNumberOfTuples(), wf->GetArray(a)->GetNumberOfTuples()) << what;
      }
      offset += m;
    }
    EXPECT_EQ(offset, n) << path << ": " << pieces << " pieces hold " << offset << " of " << n << " points";
    if (largest)
      largest->push_back(most);
  }
}

// A cloud of every kind of field PCL files hold: x y z, PCL normals, packed rgb, integers with COUNT > 1, a double.
struct Cloud
{
  pcd::Header Head;
  std::vector<std::vector<unsigned char>> Columns;
};

Cloud MakeCloud(std::uint64_t width, std::uint64_t height, unsigned seed, bool invalid)
{
  Cloud c;
  c.Head.Width = width, c.Head.Height = height, c.Head.Points = width * height;
  const struct
  {
    const char* Name;
    int Size;
    char Type;
    int Count;
  } specs[] = { { "x", 4, 'F', 1 }, { "y", 4, 'F', 1 }, { "z", 4, 'F', 1 }, { "normal_x", 4, 'F', 1 },
    { "normal_y", 4, 'F', 1 }, { "normal_z", 4, 'F', 1 }, { "rgb", 4, 'F', 1 }, { "label", 2, 'I', 3 },
    { "range", 8, 'F', 1 } };
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(-10, 10);
  for (const auto& s : specs)
  {
    pcd::Field f;
    f.Name = s.Name, f.Size = s.Size, f.Type = s.Type, f.Count = s.Count;
    c.Head.Fields.push_back(f);
    std::vector<unsigned char> column(c.Head.Points * f.Bytes());
    for (std::uint64_t i = 0; i < c.Head.Points * f.Count; ++i)
    {
      unsigned char* p = column.data() + i * f.Size;
      if (f.Name == "rgb")
      {
        const std::uint32_t bits = rng() & 0xffffff;
        std::memcpy(p, &bits, 4);
      }
      else if (f.Type == 'I')
      {
        const std::int16_t v = static_cast<std::int16_t>(rng());
        std::memcpy(p, &v, 2);
      }
      else if (f.Size == 8)
      {
        const double v = uni(rng) * 1e-3;
        std::memcpy(p, &v, 8);
      }
      else
      {
        float v = uni(rng);
        if (invalid && f.Name == "y" && i % 7 == 3)
          v = std::numeric_limits<float>::quiet_NaN();
        std::memcpy(p, &v, 4);
      }
    }
    c.Columns.push_back(std::move(column));
  }
  return c;
}

// The cloud as a .pcd file's bytes in the given encoding (empty, with a test failure, if it cannot be encoded).
std::string EncodeCloud(const Cloud& c, pcd::Encoding encoding)
{
  pcd::Header h = c.Head;
  h.Data = encoding;
  std::vector<const void*> columns;
  for (const auto& column : c.Columns)
    columns.push_back(column.data());
  std::string text, error;
  EXPECT_TRUE(pcd::Encode(h, columns, text, error)) << error;
  return text;
}

std::string WriteCloud(const Cloud& c, pcd::Encoding encoding, const std::string& name)
{
  const std::string path = OutFile(name);
  WriteText(path, EncodeCloud(c, encoding));
  return path;
}

// The data section (after the DATA line) of a .pcd text: CRLF line ends, or no final newline.
std::string Rewrite(const std::string& text, bool crlf, bool dropFinalNewline)
{
  const std::size_t data = text.find("DATA ascii\n") + 11;
  std::string out = text.substr(0, data);
  for (std::size_t i = data; i < text.size(); ++i)
    out += (crlf && text[i] == '\n') ? std::string("\r\n") : std::string(1, text[i]);
  while (dropFinalNewline && !out.empty() && (out.back() == '\n' || out.back() == '\r'))
    out.pop_back();
  return out;
}
} // namespace

TEST(ReaderPieces, ReadersAnnouncePieceRequests)
{
  vtkNew<vtkMeshFreePCDReader> pcdReader;
  vtkNew<vtkMeshFreeXYZReader> xyzReader;
  for (vtkAlgorithm* reader : { static_cast<vtkAlgorithm*>(pcdReader), static_cast<vtkAlgorithm*>(xyzReader) })
  {
    reader->UpdateInformation();
    EXPECT_EQ(reader->GetOutputInformation(0)->Get(vtkAlgorithm::CAN_HANDLE_PIECE_REQUEST()), 1);
  }
}

TEST(ReaderPieces, PCDEveryEncodingTilesTheFile)
{
  const Cloud c = MakeCloud(101, 1, 5, false);
  for (pcd::Encoding e : { pcd::Encoding::Ascii, pcd::Encoding::Binary, pcd::Encoding::BinaryCompressed })
  {
    const std::string path = WriteCloud(c, e, std::string("pieces_") + pcd::EncodingName(e) + ".pcd");
    std::vector<vtkIdType> largest;
    ExpectPiecesTileTheFile<vtkMeshFreePCDReader>(path, false, &largest);
    ASSERT_EQ(largest.size(), 5u);
    for (std::size_t k = 1; k < largest.size(); ++k)
      EXPECT_LT(largest[k], 101) << path << ": " << k + 1 << " pieces";
    if (e != pcd::Encoding::Ascii)
      EXPECT_EQ(largest[2], 34); // floor shares of binary data: 33, 34, 34
  }
}

TEST(ReaderPieces, PCDOrganisedCloudWithInvalidPointsKeepsPixelIndexInEveryPiece)
{
  // Invalid points in some rows only: a piece without any still has the PixelIndex of the file's grid.
  Cloud c = MakeCloud(8, 6, 7, true);
  for (pcd::Encoding e : { pcd::Encoding::Ascii, pcd::Encoding::Binary, pcd::Encoding::BinaryCompressed })
  {
    const std::string path = WriteCloud(c, e, std::string("pieces_organised_") + pcd::EncodingName(e) + ".pcd");
    vtkNew<MessageCatcher> msg;
    auto whole = Read<vtkMeshFreePCDReader>(path, msg);
    ASSERT_NE(whole->GetPointData()->GetArray("PixelIndex"), nullptr);
    ExpectPiecesTileTheFile<vtkMeshFreePCDReader>(path);
    ExpectPiecesTileTheFile<vtkMeshFreePCDReader>(path, /*keepInvalid=*/true);
  }
  // Only the last point invalid: the pieces before it add PixelIndex without dropping anything themselves.
  Cloud last = MakeCloud(5, 4, 9, false);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(last.Columns[0].data() + 4 * 19, &nan, 4);
  for (pcd::Encoding e : { pcd::Encoding::Ascii, pcd::Encoding::Binary, pcd::Encoding::BinaryCompressed })
    ExpectPiecesTileTheFile<vtkMeshFreePCDReader>(
      WriteCloud(last, e, std::string("pieces_organised_last_") + pcd::EncodingName(e) + ".pcd"));
}

TEST(ReaderPieces, PCDAsciiLineEndsAndFewPoints)
{
  const Cloud c = MakeCloud(23, 1, 11, false);
  const std::string text = EncodeCloud(c, pcd::Encoding::Ascii);
  ASSERT_FALSE(text.empty());
  for (bool crlf : { false, true })
    for (bool noFinalNewline : { false, true })
    {
      const std::string path = OutFile(std::string("pieces_ascii") + (crlf ? "_crlf" : "") +
        (noFinalNewline ? "_nofinal" : "") + ".pcd");
      WriteText(path, Rewrite(text, crlf, noFinalNewline));
      ExpectPiecesTileTheFile<vtkMeshFreePCDReader>(path);
    }
  // Blank lines between the points.
  std::string blank = Rewrite(text, false, false);
  for (std::size_t at = blank.find("DATA ascii\n") + 11; (at = blank.find('\n', at)) != std::string::npos; at += 30)
    blank.insert(at, "\n  \n");
  WriteText(OutFile("pieces_ascii_blank.pcd"), blank);
  ExpectPiecesTileTheFile<vtkMeshFreePCDReader>(OutFile("pieces_ascii_blank.pcd"));
  // One point, and none: most pieces are empty and still have every array and the field data.
  for (std::uint64_t n : { 1, 0 })
  {
    const Cloud one = MakeCloud(n, 1, 13, false);
    for (pcd::Encoding e : { pcd::Encoding::Ascii, pcd::Encoding::Binary, pcd::Encoding::BinaryCompressed })
      ExpectPiecesTileTheFile<vtkMeshFreePCDReader>(WriteCloud(
        one, e, "pieces_" + std::to_string(n) + "_point_" + std::string(pcd::EncodingName(e)) + ".pcd"));
  }
}

TEST(ReaderPieces, PCDBadFilesFailOnEveryPiece)
{
  const Cloud c = MakeCloud(40, 1, 17, false);
  const std::string text = EncodeCloud(c, pcd::Encoding::Ascii);
  ASSERT_FALSE(text.empty());
  // POINTS larger than the lines (a truncated file), a binary file cut short, a broken header.
  std::string truncated = text;
  truncated.replace(truncated.find("POINTS 40"), 9, "POINTS 41");
  truncated.replace(truncated.find("WIDTH 40"), 8, "WIDTH 41");
  std::string binary = EncodeCloud(c, pcd::Encoding::Binary);
  ASSERT_GT(binary.size(), 10u);
  binary.resize(binary.size() - 10);
  const std::pair<std::string, std::string> bad[] = { { "pieces_bad_truncated.pcd", truncated },
    { "pieces_bad_binary.pcd", binary }, { "pieces_bad_header.pcd", "FIELDS x y z\nSIZE 4 4\nDATA ascii\n1 2 3\n" } };
  for (const auto& b : bad)
  {
    const std::string path = OutFile(b.first);
    WriteText(path, b.second);
    for (int pieces = 1; pieces <= 4; ++pieces)
      for (int piece = 0; piece < pieces; ++piece)
      {
        vtkNew<MessageCatcher> msg;
        auto out = ReadPiece<vtkMeshFreePCDReader>(path, piece, pieces, msg);
        EXPECT_NE(msg->Errors.find("Cannot read"), std::string::npos)
          << b.first << " piece " << piece << " of " << pieces;
        EXPECT_EQ(out->GetNumberOfPoints(), 0);
      }
  }
}

TEST(ReaderPieces, XYZTextVariantsTileTheFile)
{
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-5, 5);
  std::string rows, colours;
  for (int i = 0; i < 57; ++i)
  {
    char line[200];
    std::snprintf(line, sizeof(line), "%.17g %.17g %.17g %.9g\n", uni(rng), uni(rng), uni(rng), uni(rng));
    rows += line;
    std::snprintf(line, sizeof(line), "%.17g,%.17g,%.17g,%d,%d,%d\n", uni(rng), uni(rng), uni(rng),
      static_cast<int>(rng() % 256), static_cast<int>(rng() % 256), static_cast<int>(rng() % 256));
    colours += line;
  }
  auto crlf = [](std::string s) {
    std::string out;
    for (char ch : s)
      out += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
    return out;
  };
  auto noFinal = [](std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r'))
      s.pop_back();
    return s;
  };
  auto commented = [](std::string s) {
    std::string out;
    int k = 0;
    for (std::size_t b = 0, e; b < s.size(); b = e + 1)
    {
      e = s.find('\n', b);
      out += s.substr(b, e - b + 1);
      if (++k % 5 == 0)
        out += (k % 10 ? "# a comment\n" : "\n   \n// another\n");
    }
    return out;
  };
  const std::pair<std::string, std::string> files[] = { { "pieces_plain.xyz", rows },
    { "pieces_crlf.xyz", crlf(rows) }, { "pieces_nofinal.xyz", noFinal(rows) },
    { "pieces_crlf_nofinal.xyz", noFinal(crlf(rows)) },
    { "pieces_header_comments.xyz", "# scanned\n\nx y z intensity\n" + commented(rows) },
    { "pieces_count.pts", "57\n" + rows }, { "pieces_colour.xyz", "//X,Y,Z,R,G,B\n" + colours },
    { "pieces_one.xyz", "# one point\n1 2 3 4\n" }, { "pieces_one_nofinal.xyz", "1 2 3" },
    { "pieces_none.xyz", "# nothing\n" } };
  for (const auto& f : files)
  {
    const std::string path = OutFile(f.first);
    WriteText(path, f.second);
    ExpectPiecesTileTheFile<vtkMeshFreeXYZReader>(path);
  }
  vtkNew<MessageCatcher> msg;
  EXPECT_NE(Read<vtkMeshFreeXYZReader>(OutFile("pieces_colour.xyz"), msg)->GetPointData()->GetArray("RGB"), nullptr);
  // More pieces than bytes: most byte ranges are empty, the colour columns (Leica's r g b) agree everywhere.
  WriteText(OutFile("pieces_tiny.pts"), "1 2 3 4 5 6 7");
  ExpectPiecesTileTheFile<vtkMeshFreeXYZReader>(OutFile("pieces_tiny.pts"), false, nullptr, 16);
  WriteText(OutFile("pieces_tiny_not_colour.pts"), "1 2 3 4 5 6 7\n1 2 3 4 5 6 700\n");
  ExpectPiecesTileTheFile<vtkMeshFreeXYZReader>(OutFile("pieces_tiny_not_colour.pts"), false, nullptr, 40);
  EXPECT_NE(Read<vtkMeshFreeXYZReader>(OutFile("pieces_tiny.pts"), msg)->GetPointData()->GetArray("RGB"), nullptr);
}

TEST(ReaderPieces, XYZColoursAndInvalidRowsDependOnTheWholeFile)
{
  // One row, in the last piece, is not a colour: no piece may make RGB of the columns.
  std::string text = "x y z r g b\n";
  for (int i = 0; i < 30; ++i)
    text += std::to_string(i) + " 1 2 " + std::to_string(i) + " 7 " + (i == 29 ? "7.5" : "8") + "\n";
  WriteText(OutFile("pieces_not_colour.xyz"), text);
  vtkNew<MessageCatcher> msg;
  EXPECT_EQ(Read<vtkMeshFreeXYZReader>(OutFile("pieces_not_colour.xyz"), msg)->GetPointData()->GetArray("RGB"),
    nullptr);
  ExpectPiecesTileTheFile<vtkMeshFreeXYZReader>(OutFile("pieces_not_colour.xyz"));
  // The same with that row's x NaN: dropped, so the colours hold (unless the invalid rows are kept).
  text.replace(text.rfind("29 1 2"), 2, "nan");
  WriteText(OutFile("pieces_colour_nan.xyz"), text);
  EXPECT_NE(Read<vtkMeshFreeXYZReader>(OutFile("pieces_colour_nan.xyz"), msg)->GetPointData()->GetArray("RGB"),
    nullptr);
  ExpectPiecesTileTheFile<vtkMeshFreeXYZReader>(OutFile("pieces_colour_nan.xyz"));
  ExpectPiecesTileTheFile<vtkMeshFreeXYZReader>(OutFile("pieces_colour_nan.xyz"), /*keepInvalid=*/true);
}

TEST(ReaderPieces, XYZBadFiles)
{
  // A count line that does not match fails on every piece; a bad row fails on the piece that holds it.
  std::string rows;
  for (int i = 0; i < 20; ++i)
    rows += std::to_string(i) + " 0 0\n";
  WriteText(OutFile("pieces_bad_count.pts"), "21\n" + rows);
  std::string broken = rows;
  broken.replace(broken.find("17 0 0"), 6, "17 0 q");
  WriteText(OutFile("pieces_bad_row.xyz"), broken);
  for (int pieces = 1; pieces <= 4; ++pieces)
  {
    int failed = 0;
    for (int piece = 0; piece < pieces; ++piece)
    {
      vtkNew<MessageCatcher> msg;
      auto out = ReadPiece<vtkMeshFreeXYZReader>(OutFile("pieces_bad_count.pts"), piece, pieces, msg);
      EXPECT_NE(msg->Errors.find("announces 21 points"), std::string::npos) << msg->Errors;
      EXPECT_EQ(out->GetNumberOfPoints(), 0);
      vtkNew<MessageCatcher> row;
      ReadPiece<vtkMeshFreeXYZReader>(OutFile("pieces_bad_row.xyz"), piece, pieces, row);
      if (!row->Errors.empty())
      {
        ++failed;
        EXPECT_NE(row->Errors.find("line 18: 'q' is not a number"), std::string::npos) << row->Errors;
      }
    }
    EXPECT_EQ(failed, 1) << pieces << " pieces";
  }
}
