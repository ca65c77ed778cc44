// The VTK-free text-cloud parser (.xyz / .pts): layouts seen in the wild, errors with line numbers, and the
// sniffing that tells text clouds from PLOT3D grids and XMol molecules (which also use ".xyz").
#include "XYZFormat.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

using namespace meshfree::xyz;

namespace
{
Table MustParse(const std::string& text)
{
  Table t;
  std::string error;
  EXPECT_TRUE(Parse(text.data(), text.size(), t, error)) << error << "\n" << text;
  return t;
}

std::string MustFail(const std::string& text)
{
  Table t;
  std::string error;
  EXPECT_FALSE(Parse(text.data(), text.size(), t, error)) << text;
  EXPECT_EQ(t.Rows, 0u);
  EXPECT_TRUE(t.Values.empty());
  return error;
}
} // namespace

TEST(XYZFormat, PlainWhitespaceColumns)
{
  Table t = MustParse("1 2 3\n4\t5  6\r\n\n-7e-1 +8 9.5\n");
  ASSERT_EQ(t.Rows, 3u);
  ASSERT_EQ(t.Names.size(), 3u);
  EXPECT_FALSE(t.NamedByHeader);
  EXPECT_EQ(t.Values[6], -0.7);
  EXPECT_EQ(t.Values[7], 8.0);
  EXPECT_EQ(t.DeclaredCount, -1);
}

TEST(XYZFormat, CommaSeparatedWithHeaderInAnyColumnOrder)
{
  Table t = MustParse("intensity, Z, x, y\n0.5, 3, 1, 2\n0.25,6,4,5\n");
  ASSERT_EQ(t.Rows, 2u);
  EXPECT_TRUE(t.NamedByHeader);
  EXPECT_EQ(t.Names[0], "intensity");
  EXPECT_EQ(t.Coordinate[0], 2);
  EXPECT_EQ(t.Coordinate[1], 3);
  EXPECT_EQ(t.Coordinate[2], 1);
  EXPECT_EQ(t.Values[4 + 1], 6.0);
}

TEST(XYZFormat, CloudCompareCommentHeaderAndExtraColumns)
{
  Table t = MustParse("//X Y Z R G B\n1 2 3 255 0 10\n# a comment\n4 5 6 0 128 20\n");
  ASSERT_EQ(t.Rows, 2u);
  EXPECT_TRUE(t.NamedByHeader);
  ASSERT_EQ(t.Names.size(), 6u);
  EXPECT_EQ(t.Names[3], "R");
  EXPECT_EQ(t.Values[10], 128.0);
}

TEST(XYZFormat, LeicaPointCountAndNoHeader)
{
  Table t = MustParse("2\n1 2 3 -1200 10 20 30\n4 5 6 300 40 50 60\n");
  EXPECT_EQ(t.DeclaredCount, 2);
  ASSERT_EQ(t.Rows, 2u);
  EXPECT_EQ(t.Names[3], "Column4");
  EXPECT_EQ(t.Names[6], "Column7");
  EXPECT_NE(MustFail("3\n1 2 3\n4 5 6\n").find("announces 3 points"), std::string::npos);
}

TEST(XYZFormat, NonFiniteValuesAreNumbers)
{
  Table t = MustParse("nan nan nan\n1 inf 3\n");
  ASSERT_EQ(t.Rows, 2u);
  EXPECT_TRUE(std::isnan(t.Values[0]));
  EXPECT_TRUE(std::isinf(t.Values[4]));
}

TEST(XYZFormat, EmptyFileIsAnEmptyCloud)
{
  Table t = MustParse("# nothing here\n\n");
  EXPECT_EQ(t.Rows, 0u);
}

TEST(XYZFormat, MalformedRowsNameTheLine)
{
  EXPECT_NE(MustFail("1 2 3\n4 5\n").find("line 2: 2 columns"), std::string::npos);
  EXPECT_NE(MustFail("1 2 3\n4 5 6 7\n").find("line 2"), std::string::npos);
  EXPECT_NE(MustFail("1 2 3\n4 five 6\n").find("'five' is not a number"), std::string::npos);
  EXPECT_NE(MustFail("1,,3\n").find("empty field"), std::string::npos);
  EXPECT_NE(MustFail("1 2\n3 4\n").find("x y z expected"), std::string::npos);
  EXPECT_NE(MustFail("x y z\na b c\n").find("second header"), std::string::npos);
  EXPECT_NE(MustFail("x y z w\n1 2 3\n").find("header names 4"), std::string::npos);
}

TEST(XYZFormat, SniffingTellsCloudsFromOtherXYZFormats)
{
  const std::string cloud = "0.1 0.2 0.3 7\n0.4 0.5 0.6 8\n";
  EXPECT_TRUE(LooksLikeCloud(cloud.data(), cloud.size()));
  const std::string pts = "2\n1 2 3 4 5 6 7\n1 2 3 4 5 6 7\n";
  EXPECT_TRUE(LooksLikeCloud(pts.data(), pts.size()));
  // PLOT3D, binary: Fortran record markers and raw floats.
  const unsigned char plot3d[] = { 12, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 12, 0, 0, 0, 48, 0, 0, 0,
    0, 0, 128, 63 };
  EXPECT_FALSE(LooksLikeCloud(reinterpret_cast<const char*>(plot3d), sizeof(plot3d)));
  // PLOT3D, ascii: dimensions, then all x, all y, all z.
  const std::string plot3dAscii = "2 2 1\n0 1 0 1\n0 0 1 1\n0 0 0 0\n";
  EXPECT_FALSE(LooksLikeCloud(plot3dAscii.data(), plot3dAscii.size()));
  // XMol molecule: atom count, comment, element symbol then coordinates.
  const std::string xmol = "2\nwater fragment\nO 0.0 0.0 0.0\nH 0.0 0.757 0.587\n";
  EXPECT_FALSE(LooksLikeCloud(xmol.data(), xmol.size()));
  const std::string xmolNoComment = "2\n\nO 0.0 0.0 0.0\nH 0.0 0.757 0.587\n";
  EXPECT_FALSE(LooksLikeCloud(xmolNoComment.data(), xmolNoComment.size()));
  EXPECT_FALSE(LooksLikeCloud("", 0));
  // A long file: only whole lines of the first 64 KB are looked at, the cut last line is not an error.
  std::string big;
  while (big.size() < 100000)
    big += "123.456 789.012 345.678 1\n";
  EXPECT_TRUE(LooksLikeCloud(big.data(), big.size()));
}

// Large files: the data rows are counted and parsed in pieces (several threads above 4 MB); the values, the
// row count and the line numbers of errors must be those of a line-by-line reading.
TEST(XYZFormat, LargeFileParsedInPiecesMatchesLineByLine)
{
  std::string text = "# scan\nx y z intensity\n";
  const int rows = 300000;
  for (int i = 0; i < rows; ++i)
  {
    text += std::to_string(i) + " " + std::to_string(i % 97) + ".25 -" + std::to_string(i % 13) + " " +
      std::to_string(i * 0.5) + (i % 5 == 0 ? "\r\n" : "\n");
    if (i % 1000 == 999)
      text += "# a comment inside the data\n\n";
  }
  ASSERT_GT(text.size(), std::size_t(5) << 20);
  Table t = MustParse(text);
  ASSERT_EQ(t.Rows, static_cast<std::uint64_t>(rows));
  ASSERT_EQ(t.Values.size(), 4u * rows);
  for (int i : { 0, 1, 999, 1000, 123457, rows - 1 })
  {
    EXPECT_EQ(t.Values[4 * i], double(i)) << i;
    EXPECT_EQ(t.Values[4 * i + 1], (i % 97) + 0.25) << i;
    EXPECT_EQ(t.Values[4 * i + 2], -double(i % 13)) << i;
    EXPECT_EQ(t.Values[4 * i + 3], i * 0.5) << i;
  }
  // An error deep in the file names its line: data row r is on line 2 + r + 1 + 2 * (r / 1000).
  const int bad = 250123;
  const std::size_t line = 2 + bad + 1 + 2 * (bad / 1000);
  std::size_t at = 0;
  for (std::size_t l = 1; l < line; ++l)
    at = text.find('\n', at) + 1;
  std::string broken = text;
  broken.insert(broken.find('\n', at), " 7");
  EXPECT_NE(MustFail(broken).find("line " + std::to_string(line) + ": 5 columns where the cloud has 4"),
    std::string::npos)
    << MustFail(broken);
  broken = text;
  broken.replace(at, 1, "q");
  EXPECT_NE(MustFail(broken).find("line " + std::to_string(line) + ": 'q"), std::string::npos) << MustFail(broken);
}

// A wide first row followed by many short lines must fail with the line of the first short row, without
// allocating rows x columns for them.
TEST(XYZFormat, ShortRowsAfterAWideRowFailWithoutAllocating)
{
  std::string text;
  for (int c = 0; c < 5000; ++c)
    text += "1 ";
  text += "\n";
  for (int i = 0; i < 200000; ++i)
    text += "1\n";
  EXPECT_NE(MustFail(text).find("line 2: 1 columns where the cloud has 5000"), std::string::npos) << MustFail(text);
}

// Damaged binary ".xyz" files: not a text cloud and not a PLOT3D grid (the text-cloud reader claims them, to
// refuse them itself: ParaView's PLOT3D reader aborts on them). Real PLOT3D grids keep going to PLOT3D.
TEST(XYZFormat, BinaryFilesThatCannotBePlot3DGrids)
{
  const std::string garbage("\x00\x01\x02\xff\xfe\n\x00\x00", 8); // STRESS's reproducer
  EXPECT_TRUE(LooksBinary(garbage.data(), garbage.size()));
  EXPECT_FALSE(LooksLikeCloud(garbage.data(), garbage.size()));
  EXPECT_FALSE(LooksLikePlot3D(garbage.data(), garbage.size()));
  const unsigned char tiny[] = { 0xff, 0xff, 0xff, 0xff };
  EXPECT_FALSE(LooksLikePlot3D(reinterpret_cast<const char*>(tiny), sizeof(tiny)));
  // Fortran records, little and big endian: 12 | 3 ints | 12 | ...
  const unsigned char fortranLE[] = { 12, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 12, 0, 0, 0, 48, 0, 0, 0 };
  const unsigned char fortranBE[] = { 0, 0, 0, 12, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 12, 0, 0, 0, 48 };
  EXPECT_TRUE(LooksLikePlot3D(reinterpret_cast<const char*>(fortranLE), sizeof(fortranLE)));
  EXPECT_TRUE(LooksLikePlot3D(reinterpret_cast<const char*>(fortranBE), sizeof(fortranBE)));
  // C binary without record markers: ni nj nk first.
  const unsigned char plain[] = { 3, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0 };
  EXPECT_TRUE(LooksLikePlot3D(reinterpret_cast<const char*>(plain), sizeof(plain)));
  const std::string text = "1 2 3\n";
  EXPECT_FALSE(LooksBinary(text.data(), text.size()));
}
