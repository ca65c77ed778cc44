// The VTK-free .pcd core: round trips of every type and encoding, PCL's own layouts (fixtures written
// byte by byte in Data/), and malformed files that must fail with a message and no data.
#include "PCDFormat.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace meshfree::pcd;

namespace
{
const Encoding AllEncodings[] = { Encoding::Ascii, Encoding::Binary, Encoding::BinaryCompressed };

struct Synthetic
{
  Header Head;
  std::vector<std::vector<unsigned char>> Columns;
  std::vector<const void*> Pointers() const
  {
    std::vector<const void*> p;
    for (const auto& c : this->Columns)
      p.push_back(c.data());
    return p;
  }
};

// Every SIZE/TYPE pair, COUNT > 1 on several, PCL's packed rgb, an organised width x height grid.
// Random bytes for integers (every bit pattern is a valid value) and finite random floats, plus extremes.
Synthetic MakeCloud(std::uint64_t width, std::uint64_t height, unsigned seed)
{
  Synthetic s;
  s.Head.Width = width;
  s.Head.Height = height;
  s.Head.Points = width * height;
  const double vp[7] = { 1.5, -2, 3.25, 0.5, 0.5, -0.5, 0.5 };
  std::copy(vp, vp + 7, s.Head.Viewpoint);
  struct Spec
  {
    const char* Name;
    int Size;
    char Type;
    int Count;
  };
  const Spec specs[] = { { "x", 4, 'F', 1 }, { "y", 4, 'F', 1 }, { "z", 4, 'F', 1 }, { "i8", 1, 'I', 2 },
    { "u8", 1, 'U', 1 }, { "i16", 2, 'I', 3 }, { "u16", 2, 'U', 1 }, { "i32", 4, 'I', 1 },
    { "u32", 4, 'U', 2 }, { "i64", 8, 'I', 1 }, { "u64", 8, 'U', 1 }, { "f32", 4, 'F', 5 },
    { "f64", 8, 'F', 2 }, { "rgb", 4, 'F', 1 }, { "rgba", 4, 'U', 1 } };
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(-1e3, 1e3);
  for (const Spec& sp : specs)
  {
    Field f;
    f.Name = sp.Name, f.Size = sp.Size, f.Type = sp.Type, f.Count = sp.Count;
    s.Head.Fields.push_back(f);
    std::vector<unsigned char> col(s.Head.Points * f.Bytes());
    const std::size_t values = s.Head.Points * f.Count;
    for (std::size_t v = 0; v < values; ++v)
    {
      unsigned char* dst = col.data() + v * f.Size;
      if (f.Type != 'F' || f.Name == std::string("rgb"))
      {
        std::uint64_t bits = rng();
        if (f.Name == std::string("rgb"))
          bits &= 0x00FFFFFFu; // a colour: float bits that are denormals or zero
        std::memcpy(dst, &bits, f.Size);
      }
      else if (f.Size == 4)
      {
        float x = static_cast<float>(uni(rng));
        if (v == 1)
          x = std::numeric_limits<float>::max();
        if (v == 2)
          x = std::numeric_limits<float>::denorm_min();
        std::memcpy(dst, &x, 4);
      }
      else
      {
        double x = uni(rng) * 1e-7;
        if (v == 1)
          x = -std::numeric_limits<double>::max();
        std::memcpy(dst, &x, 8);
      }
    }
    s.Columns.push_back(std::move(col));
  }
  return s;
}

void ExpectSameCloud(const Synthetic& s, const Cloud& c)
{
  ASSERT_EQ(c.Head.Fields.size(), s.Head.Fields.size());
  EXPECT_EQ(c.Head.Width, s.Head.Width);
  EXPECT_EQ(c.Head.Height, s.Head.Height);
  EXPECT_EQ(c.Head.Points, s.Head.Points);
  for (int k = 0; k < 7; ++k)
    EXPECT_EQ(c.Head.Viewpoint[k], s.Head.Viewpoint[k]);
  ASSERT_EQ(c.Columns.size(), s.Columns.size());
  for (std::size_t i = 0; i < s.Columns.size(); ++i)
  {
    const Field& f = c.Head.Fields[c.ColumnField[i]];
    EXPECT_EQ(f.Name, s.Head.Fields[i].Name);
    EXPECT_EQ(f.Size, s.Head.Fields[i].Size);
    EXPECT_EQ(f.Type, s.Head.Fields[i].Type);
    EXPECT_EQ(f.Count, s.Head.Fields[i].Count);
    ASSERT_EQ(c.Columns[i].Bytes(), s.Columns[i].size()) << f.Name;
    EXPECT_EQ(0, std::memcmp(c.Columns[i].Data(), s.Columns[i].data(), s.Columns[i].size()))
      << "field " << f.Name << " differs after the round trip";
  }
}

std::string Encoded(const Synthetic& s, Encoding e)
{
  Header h = s.Head;
  h.Data = e;
  std::string out, error;
  EXPECT_TRUE(Encode(h, s.Pointers(), out, error)) << error;
  return out;
}

std::string DataFile(const char* name)
{
  return std::string(MESHFREE_READERS_TEST_DATA) + "/" + name;
}
} // namespace

TEST(PCDFormat, RoundTripEveryTypeAndEncoding)
{
  const Synthetic s = MakeCloud(7, 3, 1);
  for (Encoding e : AllEncodings)
  {
    SCOPED_TRACE(EncodingName(e));
    const std::string bytes = Encoded(s, e);
    Cloud c;
    std::string error;
    ASSERT_TRUE(Decode(bytes.data(), bytes.size(), c, error)) << error;
    EXPECT_EQ(c.Head.Data, e);
    ExpectSameCloud(s, c);
  }
}

TEST(PCDFormat, RoundTripEmptyAndLargeCompressible)
{
  for (std::uint64_t n : { std::uint64_t(0), std::uint64_t(20000) })
  {
    Synthetic s = MakeCloud(n, 1, 2);
    // Repetitive values: LZF really compresses them (back references, not only literals).
    for (auto& col : s.Columns)
      for (std::size_t b = 0; b < col.size(); ++b)
        col[b] = static_cast<unsigned char>((b / 64) % 7);
    for (Encoding e : AllEncodings)
    {
      const std::string bytes = Encoded(s, e);
      if (e == Encoding::BinaryCompressed && n > 0)
        EXPECT_LT(bytes.size(), n * s.Head.PointBytes(false) / 4);
      Cloud c;
      std::string error;
      ASSERT_TRUE(Decode(bytes.data(), bytes.size(), c, error)) << EncodingName(e) << ": " << error;
      ExpectSameCloud(s, c);
    }
  }
}

TEST(PCDFormat, WriteFileAndReadFile)
{
  const Synthetic s = MakeCloud(11, 1, 3);
  const std::string path = std::string(MESHFREE_READERS_TEST_OUTPUT) + "/TestPCDFormat_roundtrip.pcd";
  Header h = s.Head;
  h.Data = Encoding::BinaryCompressed;
  std::string error;
  ASSERT_TRUE(WriteFile(path, h, s.Pointers(), error)) << error;
  Cloud c;
  ASSERT_TRUE(ReadFile(path, c, error)) << error;
  ExpectSameCloud(s, c);
  EXPECT_FALSE(ReadFile(path + ".missing", c, error));
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
}

TEST(PCDFormat, PCLModernAsciiWithIntegerRgbAndNaN)
{
  Cloud c;
  std::string error;
  ASSERT_TRUE(ReadFile(DataFile("pcl_xyzrgb_ascii.pcd"), c, error)) << error;
  ASSERT_EQ(c.Head.Points, 4u);
  ASSERT_EQ(c.Columns.size(), 4u);
  const float* x = reinterpret_cast<const float*>(c.Columns[0].Data());
  EXPECT_FLOAT_EQ(x[0], 0.93773f);
  EXPECT_TRUE(std::isnan(x[2]));
  std::uint32_t rgb[4];
  std::memcpy(rgb, c.Columns[3].Data(), 16);
  EXPECT_EQ(rgb[0], 0x00FF0000u);
  EXPECT_EQ(rgb[1], 0x0000FF00u);
  EXPECT_EQ(rgb[3], 0x00102030u);
  std::vector<std::uint64_t> kept;
  EXPECT_EQ(DropInvalidPoints(c, &kept), 1u);
  EXPECT_EQ(c.Head.Points, 3u);
  EXPECT_EQ(kept, (std::vector<std::uint64_t>{ 0, 1, 3 }));
  std::memcpy(rgb, c.Columns[3].Data(), 12);
  EXPECT_EQ(rgb[2], 0x00102030u);
  EXPECT_FLOAT_EQ(reinterpret_cast<const float*>(c.Columns[2].Data())[2], -0.5f);
}

TEST(PCDFormat, PCLOldAsciiWithFloatRgb)
{
  Cloud c;
  std::string error;
  ASSERT_TRUE(ReadFile(DataFile("pcl_xyzrgb_ascii_oldfloat.pcd"), c, error)) << error;
  std::uint32_t rgb[3];
  std::memcpy(rgb, c.Columns[3].Data(), 12);
  EXPECT_EQ(rgb[0], 0x00FF0000u);
  EXPECT_EQ(rgb[1], 0x0000FF00u);
  EXPECT_EQ(rgb[2], 0x00102030u);
}

TEST(PCDFormat, PCLFeatureAndVersion6)
{
  Cloud c;
  std::string error;
  ASSERT_TRUE(ReadFile(DataFile("pcl_fpfh_ascii.pcd"), c, error)) << error;
  ASSERT_EQ(c.Columns.size(), 1u);
  EXPECT_EQ(c.Head.Fields[0].Count, 33);
  const float* v = reinterpret_cast<const float*>(c.Columns[0].Data());
  EXPECT_EQ(v[32], 32.0f);
  EXPECT_EQ(v[33], 100.0f);
  EXPECT_EQ(v[65], -1.5f);

  ASSERT_TRUE(ReadFile(DataFile("pcl_v06_xyzi_ascii.pcd"), c, error)) << error;
  EXPECT_EQ(c.Head.Points, 3u);
  EXPECT_EQ(c.Head.Fields[3].Count, 1); // no COUNT line: 1
  EXPECT_FLOAT_EQ(reinterpret_cast<const float*>(c.Columns[3].Data())[2], 1e-5f);
}

TEST(PCDFormat, PCLBinaryWithPaddingFields)
{
  Cloud c;
  std::string error;
  ASSERT_TRUE(ReadFile(DataFile("pcl_pointnormal_binary.pcd"), c, error)) << error;
  ASSERT_EQ(c.Columns.size(), 7u); // the two "_" fields are skipped
  const float* nx = reinterpret_cast<const float*>(c.Columns[3].Data());
  const float* curvature = reinterpret_cast<const float*>(c.Columns[6].Data());
  EXPECT_EQ(c.Head.Fields[c.ColumnField[3]].Name, "normal_x");
  EXPECT_EQ(nx[1], 0.6f);
  EXPECT_EQ(curvature[0], 0.125f);
  EXPECT_EQ(curvature[3], 0.0f);
  EXPECT_EQ(DropInvalidPoints(c), 1u);
  EXPECT_EQ(reinterpret_cast<const float*>(c.Columns[0].Data())[2], -2.0f);
}

TEST(PCDFormat, InterleavedNormalsFollowTheirPoints)
{
  Cloud c;
  std::string error;
  ASSERT_TRUE(ReadFile(DataFile("pcl_pointnormal_binary.pcd"), c, error, /*interleaveXYZ=*/true)) << error;
  ASSERT_EQ(c.PointsSize, 4);
  ASSERT_EQ(c.NormalsSize, 4);
  ASSERT_EQ(c.Columns.size(), 1u); // curvature
  EXPECT_EQ(c.Head.Fields[c.ColumnField[0]].Name, "curvature");
  EXPECT_EQ(DropInvalidPoints(c), 1u);
  ASSERT_EQ(c.Normals.Bytes(), 3u * 12u);
  const float* n = reinterpret_cast<const float*>(c.Normals.Data());
  const float expected[9] = { 0, 0, 1, 0.6f, 0.8f, 0, 1, 0, 0 };
  for (int i = 0; i < 9; ++i)
    EXPECT_EQ(n[i], expected[i]) << i;
}

TEST(PCDFormat, PCLCompressedOrganisedWithoutPaddingBlocks)
{
  Cloud c;
  std::string error;
  ASSERT_TRUE(ReadFile(DataFile("pcl_xyzrgba_organised_compressed.pcd"), c, error)) << error;
  EXPECT_EQ(c.Head.Width, 2u);
  EXPECT_EQ(c.Head.Height, 2u);
  EXPECT_EQ(c.Head.Viewpoint[0], 1.0);
  EXPECT_EQ(c.Head.Viewpoint[6], 0.5);
  ASSERT_EQ(c.Columns.size(), 4u);
  const float* z = reinterpret_cast<const float*>(c.Columns[2].Data());
  EXPECT_EQ(z[3], 2.0f);
  std::uint32_t rgba[4];
  std::memcpy(rgba, c.Columns[3].Data(), 16);
  EXPECT_EQ(rgba[0], 0xFF102030u);
  EXPECT_EQ(rgba[1], 0x80FF0000u);
}

TEST(PCDFormat, BinaryWithPCLsPagePadding)
{
  // PCL 1.13 sizes a binary file to the data plus a page: zero bytes follow the last point.
  const Synthetic s = MakeCloud(3, 1, 10);
  for (std::size_t padding : { std::size_t(1), std::size_t(2), std::size_t(3926), std::size_t(65535) })
  {
    SCOPED_TRACE(padding);
    const std::string bytes = Encoded(s, Encoding::Binary) + std::string(padding, '\0');
    Cloud c;
    std::string error;
    ASSERT_TRUE(Decode(bytes.data(), bytes.size(), c, error)) << error;
    ExpectSameCloud(s, c);
  }
}

TEST(PCDFormat, AsciiPackedRgbIsTheFloatPCLReads)
{
  // PCL 1.13 reads an ascii TYPE F rgb as a float (text "65287" becomes 65287.0f, another colour): colours
  // are written as their float, the bits as an integer only where the float's text would read as one.
  std::vector<std::uint32_t> bits = { 0x0000FF07u, 0x00FF0000u, 0x3F800000u, 0xFFFFFFFFu, 0x80000000u, 0u,
    0x7F800000u };
  for (std::uint32_t c = 1; c < (1u << 24); c += 97)
    bits.push_back(c); // a sample of every 0x00RRGGBB colour, most of them denormal floats
  Synthetic s;
  s.Head.Width = s.Head.Points = bits.size();
  Field f;
  f.Name = "rgb";
  s.Head.Fields.push_back(f);
  s.Columns.emplace_back(bits.size() * 4);
  std::memcpy(s.Columns[0].data(), bits.data(), bits.size() * 4);
  const std::string text = Encoded(s, Encoding::Ascii);
  const std::size_t data = text.find("DATA ascii\n") + 11;
  std::vector<std::string> lines;
  for (std::size_t p = data; p < text.size();)
  {
    const std::size_t nl = text.find('\n', p);
    lines.push_back(text.substr(p, nl - p));
    p = nl + 1;
  }
  EXPECT_EQ(lines[0], "9.1487e-41"); // shortest text that reads back as these bits
  EXPECT_EQ(lines[1], "2.3418052e-38");
  EXPECT_EQ(lines[2], "1065353216"); // 1.0f: "1" would read as the bits 0x00000001
  EXPECT_EQ(lines[3], "4294967295"); // NaN
  EXPECT_EQ(lines[4], "2147483648"); // -0
  EXPECT_EQ(lines[5], "0");
  EXPECT_EQ(lines[6], "2139095040"); // infinity
  Cloud c;
  std::string error;
  ASSERT_TRUE(Decode(text.data(), text.size(), c, error)) << error;
  ExpectSameCloud(s, c);
}

TEST(PCDFormat, MalformedFilesFailWithAMessage)
{
  const std::string head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  struct Case
  {
    std::string Text;
    const char* Expect;
  };
  const Case cases[] = {
    { "", "no DATA line" },
    { "hello world\n", "unknown header keyword" },
    { head + "WIDTH 2\nPOINTS 2\nDATA ascii\n1 2 3\n", "ends after 1 of 2" },
    { head + "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n4 5 6\n", "more data after" },
    { head + "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2\n", "fewer values" },
    { head + "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3 4\n", "more values" },
    { head + "WIDTH 1\nPOINTS 1\nDATA ascii\n1 two 3\n", "not a valid value" },
    { head + "WIDTH 3\nHEIGHT 2\nPOINTS 5\nDATA ascii\n", "differs from POINTS" },
    { head + "WIDTH 1\nPOINTS 1\nDATA lzma\n", "unknown encoding" },
    { "FIELDS x y\nSIZE 4 4 4\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2\n", "3 values for 2 FIELDS" },
    { "FIELDS x\nSIZE 3\nTYPE F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1\n", "SIZE 3" },
    { "FIELDS x\nSIZE 4\nTYPE Q\nWIDTH 1\nPOINTS 1\nDATA ascii\n1\n", "unknown TYPE" },
    { "FIELDS x\nSIZE 2\nTYPE F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1\n", "TYPE F with SIZE 2" },
    { "FIELDS x\nSIZE 1\nTYPE U\nWIDTH 1\nPOINTS 1\nDATA ascii\n256\n", "not a valid value" },
    { "FIELDS x\nSIZE 1\nTYPE I\nWIDTH 1\nPOINTS 1\nDATA ascii\n-129\n", "not a valid value" },
    { "FIELDS x\nCOUNT 0\nWIDTH 1\nPOINTS 1\nDATA ascii\n\n", "COUNT 0" },
    { "SIZE 4\nFIELDS x\nWIDTH 1\nPOINTS 1\nDATA ascii\n1\n", "before FIELDS" },
    { head + "WIDTH 1\nVIEWPOINT 0 0 0 1 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n", "7 values" },
    { head + "WIDTH 100000000000\nPOINTS 100000000000\nDATA ascii\n1 2 3\n", "truncated ascii" },
    { head + "WIDTH 18446744073709551615\nPOINTS 18446744073709551615\nDATA binary\n", "too large" },
    { head + "WIDTH 2\nPOINTS 2\nDATA binary\n" + std::string(23, '\0'), "truncated binary" },
    { head + "WIDTH 1\nPOINTS 1\nDATA binary\n" + std::string(12 + 4, '\0') + "\x01", "POINTS does not match" },
    { head + "WIDTH 1\nPOINTS 1\nDATA binary\n" + std::string(12, '\0') + "\n\n\n", "are not padding" },
    { head + "WIDTH 1\nPOINTS 1\nDATA binary\n" + std::string(12 + (64 << 10), '\0'), "are not padding" },
    { head + "WIDTH 1\nPOINTS 1\nDATA binary_compressed\n" + std::string(4, '\0'), "no size words" },
  };
  for (const Case& c : cases)
  {
    Cloud cloud;
    std::string error;
    EXPECT_FALSE(Decode(c.Text.data(), c.Text.size(), cloud, error)) << c.Text;
    EXPECT_NE(error.find(c.Expect), std::string::npos) << "error '" << error << "' lacks '" << c.Expect << "'";
    EXPECT_TRUE(cloud.Columns.empty());
    EXPECT_EQ(cloud.Head.Points, 0u);
  }
}

TEST(PCDFormat, CompressedSizesThatLie)
{
  Synthetic s = MakeCloud(50, 1, 4);
  const std::string good = Encoded(s, Encoding::BinaryCompressed);
  const std::size_t words = good.find("DATA binary_compressed\n") + std::strlen("DATA binary_compressed\n");
  std::uint32_t sizes[2];
  std::memcpy(sizes, good.data() + words, 8);
  auto with = [&](std::uint32_t compressed, std::uint32_t uncompressed) {
    std::string bad = good;
    std::uint32_t w[2] = { compressed, uncompressed };
    std::memcpy(&bad[words], w, 8);
    Cloud c;
    std::string error;
    EXPECT_FALSE(Decode(bad.data(), bad.size(), c, error));
    EXPECT_TRUE(c.Columns.empty());
    return error;
  };
  EXPECT_NE(with(sizes[0] + 1, sizes[1]).find("truncated"), std::string::npos);
  EXPECT_NE(with(sizes[0] - 1, sizes[1]).find("corrupt"), std::string::npos);
  EXPECT_NE(with(sizes[0], sizes[1] + 4).find("announces"), std::string::npos);
  EXPECT_NE(with(0xFFFFFFF0u, sizes[1]).find("truncated"), std::string::npos);
  // A flipped byte inside the LZF stream either decodes to the right size or is refused; never a crash.
  std::string corrupt = good;
  corrupt[words + 8 + 3] ^= 0x5A;
  Cloud c;
  std::string error;
  if (!Decode(corrupt.data(), corrupt.size(), c, error))
    EXPECT_FALSE(error.empty());
}

TEST(PCDFormat, EveryTruncationIsRefused)
{
  const Synthetic s = MakeCloud(4, 2, 5);
  for (Encoding e : AllEncodings)
  {
    const std::string full = Encoded(s, e);
    // In ascii, a cut inside the very last value still reads as a (shorter) number: text cannot tell.
    const std::size_t undetectable = e == Encoding::Ascii ? full.rfind(' ') + 2 : full.size() - 1;
    for (std::size_t len = 0; len < undetectable; ++len)
    {
      Cloud c;
      std::string error;
      const bool ok = Decode(full.data(), len, c, error);
      EXPECT_FALSE(ok) << EncodingName(e) << " truncated to " << len << " of " << full.size() << " bytes";
      if (!ok)
        EXPECT_FALSE(error.empty());
    }
  }
}

TEST(PCDFormat, DropInvalidPointsKeepsIndices)
{
  Synthetic s = MakeCloud(5, 1, 6);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::memcpy(s.Columns[0].data() + 4 * 1, &nan, 4);
  std::memcpy(s.Columns[2].data() + 4 * 4, &inf, 4);
  const std::string bytes = Encoded(s, Encoding::Binary);
  Cloud c;
  std::string error;
  ASSERT_TRUE(Decode(bytes.data(), bytes.size(), c, error)) << error;
  std::vector<std::uint64_t> kept;
  EXPECT_EQ(DropInvalidPoints(c, &kept), 2u);
  EXPECT_EQ(kept, (std::vector<std::uint64_t>{ 0, 2, 3 }));
  for (std::size_t col = 0; col < c.Columns.size(); ++col)
  {
    const std::size_t b = s.Head.Fields[col].Bytes();
    ASSERT_EQ(c.Columns[col].Bytes(), 3 * b);
    for (std::size_t k = 0; k < kept.size(); ++k)
      EXPECT_EQ(0, std::memcmp(c.Columns[col].Data() + k * b, s.Columns[col].data() + kept[k] * b, b));
  }
}

TEST(PCDFormat, LargeAsciiIsParsedInParallelPiecesWithExactLineNumbers)
{
  // Over 4 MB of ascii data: the decoder splits it at line boundaries and parses the pieces on all cores.
  const std::uint64_t n = 300000;
  Synthetic s;
  s.Head.Width = s.Head.Points = n;
  for (const char* name : { "x", "y", "z", "label" })
  {
    Field f;
    f.Name = name;
    f.Type = name[0] == 'l' ? 'I' : 'F';
    s.Head.Fields.push_back(f);
    s.Columns.emplace_back(n * 4);
  }
  std::mt19937 rng(8);
  for (auto& col : s.Columns)
    for (std::size_t i = 0; i < n; ++i)
    {
      const float v = std::uniform_real_distribution<float>(-1e4f, 1e4f)(rng);
      const std::int32_t k = static_cast<std::int32_t>(rng());
      std::memcpy(col.data() + 4 * i, &col == &s.Columns[3] ? static_cast<const void*>(&k) : &v, 4);
    }
  std::string text = Encoded(s, Encoding::Ascii);
  ASSERT_GT(text.size(), 8u << 20);
  Cloud c;
  std::string error;
  ASSERT_TRUE(Decode(text.data(), text.size(), c, error)) << error;
  ExpectSameCloud(s, c);

  // A bad value far into the file: the message names its line as a serial reader would.
  const std::size_t headerLines = 11; // the writer's header
  const std::uint64_t badPoint = 234567;
  std::size_t pos = 0;
  for (std::uint64_t l = 0; l < headerLines + badPoint; ++l)
    pos = text.find('\n', pos) + 1;
  text[pos] = 'q';
  ASSERT_FALSE(Decode(text.data(), text.size(), c, error));
  EXPECT_NE(error.find("line " + std::to_string(headerLines + badPoint + 1) + ":"), std::string::npos) << error;

  // Blank lines between points are allowed; a missing point is reported.
  std::string gappy = Encoded(s, Encoding::Ascii);
  gappy.insert(gappy.find('\n', gappy.size() / 2) + 1, "\n\n  \n");
  ASSERT_TRUE(Decode(gappy.data(), gappy.size(), c, error)) << error;
  ExpectSameCloud(s, c);
  const std::size_t lastLine = gappy.rfind('\n', gappy.size() - 2) + 1;
  gappy.erase(lastLine);
  ASSERT_FALSE(Decode(gappy.data(), gappy.size(), c, error));
  EXPECT_NE(error.find("ends after 299999 of 300000"), std::string::npos) << error;
}

TEST(PCDFormat, InterleavedPointsMatchTheColumns)
{
  Synthetic s = MakeCloud(9, 2, 9);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(s.Columns[1].data() + 4 * 5, &nan, 4); // point 5 is invalid
  for (Encoding e : AllEncodings)
  {
    SCOPED_TRACE(EncodingName(e));
    const std::string bytes = Encoded(s, e);
    Cloud plain, inter;
    std::string error;
    ASSERT_TRUE(Decode(bytes.data(), bytes.size(), plain, error)) << error;
    ASSERT_TRUE(Decode(bytes.data(), bytes.size(), inter, error, true)) << error;
    ASSERT_EQ(inter.PointsSize, 4);
    ASSERT_EQ(inter.Columns.size() + 3, plain.Columns.size()); // x, y, z have no column
    for (std::uint64_t i = 0; i < s.Head.Points; ++i)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(0, std::memcmp(inter.Points.Data() + 12 * i + 4 * k, plain.Columns[k].Data() + 4 * i, 4));
    std::vector<std::uint64_t> a, b;
    EXPECT_EQ(DropInvalidPoints(plain, &a), 1u);
    EXPECT_EQ(DropInvalidPoints(inter, &b), 1u);
    EXPECT_EQ(a, b);
    ASSERT_EQ(inter.Points.Bytes(), 12 * a.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(0, std::memcmp(inter.Points.Data() + 12 * i + 4 * k, plain.Columns[k].Data() + 4 * i, 4));
    for (std::size_t c = 0; c < inter.Columns.size(); ++c)
      EXPECT_EQ(0, std::memcmp(inter.Columns[c].Data(), plain.Columns[c + 3].Data(), inter.Columns[c].Bytes()));
  }
  // Mixed precisions: no interleaving, the columns stay.
  s.Head.Fields[2].Size = 8;
  s.Columns[2].assign(s.Head.Points * 8, 0);
  const std::string mixed = Encoded(s, Encoding::Binary);
  Cloud c;
  std::string error;
  ASSERT_TRUE(Decode(mixed.data(), mixed.size(), c, error, true)) << error;
  EXPECT_EQ(c.PointsSize, 0);
  EXPECT_EQ(c.Columns.size(), s.Columns.size());
}
