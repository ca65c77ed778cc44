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
