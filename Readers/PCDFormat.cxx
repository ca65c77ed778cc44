#include "PCDFormat.h"
#include "PCDInternal.h"

#include <lzf.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace meshfree
{
namespace pcd
{
namespace detail
{
// LZF's longest back reference expands 3 bytes into 264: no valid stream grows more than 88 times.
// A header announcing more is lying, and is refused before anything is allocated.
constexpr std::uint64_t MaxLzfRatio = 100;
constexpr int MaxCount = 1 << 20;

struct Line
{
  const char* Begin;
  const char* End; // without the newline
};

std::vector<std::string> Tokens(const char* b, const char* e)
{
  std::vector<std::string> out;
  while (b < e)
  {
    while (b < e && detail::IsSpace(*b))
      ++b;
    const char* t = b;
    while (b < e && !detail::IsSpace(*b))
      ++b;
    if (b > t)
      out.emplace_back(t, b);
  }
  return out;
}

template <class T>
bool ToNumber(const std::string& s, T& value)
{
  const char* b = s.data();
  const char* e = b + s.size();
  if (b < e && *b == '+')
    ++b;
  auto r = std::from_chars(b, e, value);
  return r.ec == std::errc() && r.ptr == e;
}

bool MulOverflows(std::uint64_t a, std::uint64_t b, std::uint64_t& product)
{
  return __builtin_mul_overflow(a, b, &product);
}

// Copies n values of `bytes` bytes from src (every srcStride bytes) to dst (every dstStride bytes): one
// field out of the records of binary data, or into the interleaved points.
template <std::size_t B>
void StridedCopy(const unsigned char* src, std::size_t srcStride, std::uint64_t n, unsigned char* dst,
  std::size_t dstStride)
{
  for (std::uint64_t i = 0; i < n; ++i)
    std::memcpy(dst + i * dstStride, src + i * srcStride, B);
}

void StridedCopy(const unsigned char* src, std::size_t srcStride, std::uint64_t n, std::size_t bytes,
  unsigned char* dst, std::size_t dstStride)
{
  if (srcStride == bytes && dstStride == bytes)
  {
    std::memcpy(dst, src, n * bytes);
    return;
  }
  switch (bytes)
  {
    case 1: StridedCopy<1>(src, srcStride, n, dst, dstStride); return;
    case 2: StridedCopy<2>(src, srcStride, n, dst, dstStride); return;
    case 4: StridedCopy<4>(src, srcStride, n, dst, dstStride); return;
    case 8: StridedCopy<8>(src, srcStride, n, dst, dstStride); return;
    case 12: StridedCopy<12>(src, srcStride, n, dst, dstStride); return;
    case 16: StridedCopy<16>(src, srcStride, n, dst, dstStride); return;
    default:
      for (std::uint64_t i = 0; i < n; ++i)
        std::memcpy(dst + i * dstStride, src + i * srcStride, bytes);
  }
}

// What may follow the records of a binary data section: PCL's writers size binary files beyond the data
// (PCL 1.13 leaves up to a page of zero bytes after the last point), and other writers end with a newline.
// Anything else, or more zeros than the largest page size, means that POINTS does not describe the data.
bool IsTrailingPadding(const char* tail, std::size_t bytes)
{
  constexpr std::size_t MaxPageBytes = std::size_t(64) << 10;
  if (bytes <= 2 && std::all_of(tail, tail + bytes, [](char c) { return c == '\n' || c == '\r'; }))
    return true;
  return bytes < MaxPageBytes && std::all_of(tail, tail + bytes, [](char c) { return c == '\0'; });
}

bool ValidateField(const Field& f, std::string& error)
{
  if (f.Size != 1 && f.Size != 2 && f.Size != 4 && f.Size != 8)
  {
    error = "field '" + f.Name + "' has SIZE " + std::to_string(f.Size) + " (1, 2, 4 or 8 expected)";
    return false;
  }
  if (f.Type != 'I' && f.Type != 'U' && f.Type != 'F')
  {
    error = "field '" + f.Name + "' has unknown TYPE '" + std::string(1, f.Type) + "' (I, U or F expected)";
    return false;
  }
  if (f.Type == 'F' && f.Size != 4 && f.Size != 8)
  {
    error = "field '" + f.Name + "' is TYPE F with SIZE " + std::to_string(f.Size) + " (4 or 8 expected)";
    return false;
  }
  if (f.Count < 1 || f.Count > MaxCount)
  {
    error = "field '" + f.Name + "' has COUNT " + std::to_string(f.Count);
    return false;
  }
  return true;
}
} // namespace detail

using namespace detail;

const char* EncodingName(Encoding encoding)
{
  switch (encoding)
  {
    case Encoding::Ascii: return "ascii";
    case Encoding::Binary: return "binary";
    case Encoding::BinaryCompressed: return "binary_compressed";
  }
  return "?";
}

std::size_t Header::PointBytes(bool withPadding) const
{
  std::size_t bytes = 0;
  for (const Field& f : this->Fields)
    if (withPadding || !f.IsPadding())
      bytes += f.Bytes();
  return bytes;
}

int Header::FieldIndex(const std::string& name) const
{
  for (std::size_t i = 0; i < this->Fields.size(); ++i)
    if (this->Fields[i].Name == name)
      return static_cast<int>(i);
  return -1;
}

bool ParseHeader(const char* data, std::size_t size, Header& header, std::string& error)
{
  header = Header();
  bool haveFields = false, haveSize = false, haveType = false, haveCount = false;
  bool haveWidth = false, haveHeight = false, havePoints = false;
  const char* p = data;
  const char* end = data + size;
  int lineNumber = 0;
  while (p < end)
  {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', end - p));
    Line line{ p, nl ? nl : end };
    p = nl ? nl + 1 : end;
    ++lineNumber;
    std::vector<std::string> tok = Tokens(line.Begin, line.End);
    if (tok.empty() || tok[0][0] == '#')
      continue;
    const std::string& key = tok[0];
    const std::size_t nvalues = tok.size() - 1;
    auto bad = [&](const std::string& what) {
      error = "header line " + std::to_string(lineNumber) + " (" + key + "): " + what;
      return false;
    };
    if (key == "VERSION")
      continue;
    if (key == "FIELDS" || key == "COLUMNS")
    {
      if (nvalues == 0)
        return bad("no field names");
      header.Fields.assign(nvalues, Field());
      for (std::size_t i = 0; i < nvalues; ++i)
        header.Fields[i].Name = tok[i + 1];
      haveFields = true;
      continue;
    }
    if (key == "SIZE" || key == "TYPE" || key == "COUNT")
    {
      if (!haveFields)
        return bad("comes before FIELDS");
      if (nvalues != header.Fields.size())
        return bad(std::to_string(nvalues) + " values for " + std::to_string(header.Fields.size()) +
          " FIELDS");
      for (std::size_t i = 0; i < nvalues; ++i)
      {
        Field& f = header.Fields[i];
        if (key == "TYPE")
        {
          if (tok[i + 1].size() != 1)
            return bad("'" + tok[i + 1] + "' is not a type (I, U or F)");
          f.Type = tok[i + 1][0];
        }
        else
        {
          int v = 0;
          if (!ToNumber(tok[i + 1], v))
            return bad("'" + tok[i + 1] + "' is not an integer");
          (key == "SIZE" ? f.Size : f.Count) = v;
        }
      }
      (key == "SIZE" ? haveSize : key == "TYPE" ? haveType : haveCount) = true;
      continue;
    }
    if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS")
    {
      std::uint64_t v = 0;
      if (nvalues != 1 || !ToNumber(tok[1], v))
        return bad("one non-negative integer expected");
      if (key == "WIDTH")
        header.Width = v, haveWidth = true;
      else if (key == "HEIGHT")
        header.Height = v, haveHeight = true;
      else
        header.Points = v, havePoints = true;
      continue;
    }
    if (key == "VIEWPOINT")
    {
      if (nvalues != 7)
        return bad("7 values expected (tx ty tz qw qx qy qz)");
      for (int i = 0; i < 7; ++i)
        if (!ToNumber(tok[i + 1], header.Viewpoint[i]) || !std::isfinite(header.Viewpoint[i]))
          return bad("'" + tok[i + 1] + "' is not a finite number");
      continue;
    }
    if (key == "DATA")
    {
      if (nvalues != 1)
        return bad("one of ascii, binary, binary_compressed expected");
      if (tok[1] == "ascii")
        header.Data = Encoding::Ascii;
      else if (tok[1] == "binary")
        header.Data = Encoding::Binary;
      else if (tok[1] == "binary_compressed")
        header.Data = Encoding::BinaryCompressed;
      else
        return bad("unknown encoding '" + tok[1] + "'");
      header.DataStart = static_cast<std::size_t>(p - data);
      if (!haveFields)
        return bad("no FIELDS line before DATA");
      (void)haveSize;
      (void)haveType;
      (void)haveCount;
      for (const Field& f : header.Fields)
        if (!ValidateField(f, error))
          return false;
      if (!haveHeight)
        header.Height = 1;
      if (!havePoints)
      {
        if (!haveWidth)
          return bad("neither POINTS nor WIDTH given");
        if (MulOverflows(header.Width, header.Height, header.Points))
          return bad("WIDTH x HEIGHT overflows");
      }
      if (!haveWidth)
        header.Width = header.Height > 0 ? header.Points / header.Height : 0;
      std::uint64_t wh = 0;
      if (MulOverflows(header.Width, header.Height, wh) || wh != header.Points)
      {
        error = "WIDTH (" + std::to_string(header.Width) + ") x HEIGHT (" +
          std::to_string(header.Height) + ") differs from POINTS (" + std::to_string(header.Points) + ")";
        return false;
      }
      std::uint64_t total = 0;
      if (MulOverflows(header.Points, header.PointBytes(true), total) ||
        total > std::numeric_limits<std::size_t>::max() / 2)
      {
        error = "POINTS (" + std::to_string(header.Points) + ") is too large";
        return false;
      }
      return true;
    }
    return bad("unknown header keyword (not a .pcd file?)");
  }
  error = "no DATA line: not a .pcd file, or its header is truncated";
  return false;
}

namespace
{
// floor(n * k / pieces) without overflow.
std::uint64_t Share(std::uint64_t n, int k, int pieces)
{
  return static_cast<std::uint64_t>(static_cast<unsigned __int128>(n) * static_cast<unsigned>(k) /
    static_cast<unsigned>(pieces));
}

bool IsCoordinate(const Field& f)
{
  return (f.Name == "x" || f.Name == "y" || f.Name == "z") && f.Type == 'F' && f.Count == 1;
}

bool IsFinite(const unsigned char* p, int size)
{
  if (size == 4)
  {
    float v;
    std::memcpy(&v, p, 4);
    return std::isfinite(v);
  }
  double v;
  std::memcpy(&v, p, 8);
  return std::isfinite(v);
}

// request null: the whole file (Decode); otherwise a piece (DecodePiece).
bool DecodeImpl(const char* data, std::size_t size, Cloud& cloud, std::string& error, bool interleaveXYZ,
  const PieceRequest* request)
{
  cloud = Cloud();
  Header header;
  if (!ParseHeader(data, size, header, error))
    return false;
  const std::uint64_t n = header.Points;
  const std::size_t available = size - header.DataStart;
  const auto* body = reinterpret_cast<const unsigned char*>(data + header.DataStart);

  // Cheap size checks before any allocation, so that a lying header cannot ask for gigabytes.
  const std::size_t recordBytes = header.PointBytes(true);
  std::size_t compressedBytes = 0;
  std::uint32_t uncompressed = 0;
  bool withPadding = true;
  if (header.Data == Encoding::Binary)
  {
    const std::uint64_t need = n * recordBytes;
    if (available < need)
    {
      error = "truncated binary data: " + std::to_string(available) + " bytes for " +
        std::to_string(n) + " points of " + std::to_string(recordBytes) + " bytes (" +
        std::to_string(need) + " needed)";
      return false;
    }
    const std::size_t extra = available - need;
    if (!IsTrailingPadding(data + header.DataStart + need, extra))
    {
      error = std::to_string(extra) + " bytes after the " + std::to_string(n) +
        " points are not padding: POINTS does not match the data";
      return false;
    }
  }
  else if (header.Data == Encoding::BinaryCompressed && (n > 0 || available >= 8))
  {
    std::uint32_t sizes[2];
    if (available < 8)
    {
      error = "truncated binary_compressed data: no size words";
      return false;
    }
    std::memcpy(sizes, body, 8);
    compressedBytes = sizes[0];
    uncompressed = sizes[1];
    if (compressedBytes > available - 8)
    {
      error = "truncated binary_compressed data: " + std::to_string(available - 8) +
        " bytes where the header announces " + std::to_string(compressedBytes);
      return false;
    }
    const std::uint64_t noPad = n * header.PointBytes(false);
    const std::uint64_t pad = n * recordBytes;
    if (uncompressed == noPad)
      withPadding = false;
    else if (uncompressed != pad)
    {
      error = "binary_compressed data announces " + std::to_string(uncompressed) +
        " uncompressed bytes, but " + std::to_string(n) + " points of these FIELDS need " +
        std::to_string(noPad);
      return false;
    }
    if (uncompressed > MaxLzfRatio * compressedBytes + 16)
    {
      error = "binary_compressed sizes lie: " + std::to_string(compressedBytes) +
        " LZF bytes cannot expand to " + std::to_string(uncompressed);
      return false;
    }
  }
  else if (header.Data == Encoding::Ascii)
  {
    std::size_t values = 0;
    for (const Field& f : header.Fields)
      if (!f.IsPadding())
        values += f.Count;
    // Every value takes at least one character and one separator or newline.
    if (values > 0 && n > 0 && (n - 1) > available / (2 * values))
    {
      error = "truncated ascii data: " + std::to_string(available) + " bytes cannot hold " +
        std::to_string(n) + " points";
      return false;
    }
  }

  // The share of a piece: the points [first, first + count).
  std::uint64_t first = 0, count = n;
  const bool piece = request && request->Pieces > 1;
  detail::AsciiPiece lines;
  if (piece)
  {
    if (request->Piece < 0 || request->Piece >= request->Pieces)
    {
      error = "piece " + std::to_string(request->Piece) + " of " + std::to_string(request->Pieces) + " does not exist";
      return false;
    }
    if (header.Data == Encoding::Ascii)
    {
      if (!detail::AsciiPieceBounds(data, size, header, *request, lines, error))
        return false;
      first = lines.First, count = lines.Count;
    }
    else
    {
      first = Share(n, request->Piece, request->Pieces);
      count = Share(n, request->Piece + 1, request->Pieces) - first;
    }
  }

  cloud.Head = header;
  // Where each field goes: x, y, z and normal_x, normal_y, normal_z (each triple one floating type, COUNT 1)
  // into the interleaved points and normals when asked, every other non-padding field into its own column.
  std::vector<detail::Target> targets(header.Fields.size());
  auto outOfMemory = [&] {
    cloud = Cloud();
    error = "out of memory for " + std::to_string(n) + " points";
    return false;
  };
  struct Triple
  {
    const char* Names[3];
    Buffer Cloud::*Storage;
    int Cloud::*Size;
  };
  const Triple triples[] = { { { "x", "y", "z" }, &Cloud::Points, &Cloud::PointsSize },
    { { "normal_x", "normal_y", "normal_z" }, &Cloud::Normals, &Cloud::NormalsSize } };
  for (const Triple& t : triples)
  {
    int field[3] = { -1, -1, -1 };
    bool interleave = interleaveXYZ;
    for (int k = 0; k < 3 && interleave; ++k)
    {
      field[k] = header.FieldIndex(t.Names[k]);
      interleave = field[k] >= 0 && header.Fields[field[k]].Type == 'F' && header.Fields[field[k]].Count == 1 &&
        header.Fields[field[k]].Size == header.Fields[field[0]].Size;
    }
    if (!interleave)
      continue;
    const std::size_t s = static_cast<std::size_t>(header.Fields[field[0]].Size);
    Buffer& storage = cloud.*t.Storage;
    if (!storage.Allocate(count * 3 * s))
      return outOfMemory();
    cloud.*t.Size = static_cast<int>(s);
    for (int k = 0; k < 3; ++k)
      targets[field[k]] = { storage.Data() + k * s, 3 * s };
  }
  for (std::size_t i = 0; i < header.Fields.size(); ++i)
  {
    if (header.Fields[i].IsPadding() || targets[i].Base)
      continue;
    cloud.ColumnField.push_back(static_cast<int>(i));
    cloud.Columns.emplace_back();
    if (!cloud.Columns.back().Allocate(count * header.Fields[i].Bytes()))
      return outOfMemory();
    targets[i] = { cloud.Columns.back().Data(), header.Fields[i].Bytes() };
  }

  bool ok = true;
  bool invalidElsewhere = false;
  const bool findInvalid = piece && request->FindInvalid && header.Height > 1;
  if (header.Data == Encoding::Ascii)
  {
    ok = piece ? detail::DecodeAsciiPiece(data, header, targets, lines, error)
               : detail::DecodeAscii(data, size, header, targets, error);
    if (ok && findInvalid)
      ok = detail::AsciiInvalidElsewhere(data, size, header, lines, request->Mapping, invalidElsewhere, error);
  }
  else if (header.Data == Encoding::Binary)
  {
    std::size_t offset = 0;
    for (std::size_t i = 0; i < header.Fields.size(); ++i)
    {
      const Field& f = header.Fields[i];
      if (targets[i].Base)
        StridedCopy(body + first * recordBytes + offset, recordBytes, count, f.Bytes(), targets[i].Base,
          targets[i].Stride);
      offset += f.Bytes();
    }
    if (findInvalid)
    {
      // The coordinates of the records outside the share, in windows whose pages are given back afterwards.
      constexpr std::uint64_t Window = 1 << 16;
      const std::uint64_t ranges[2][2] = { { 0, first }, { first + count, n } };
      for (const auto& r : ranges)
        for (std::uint64_t b = r[0]; b < r[1] && !invalidElsewhere; b += Window)
        {
          const std::uint64_t e = std::min(r[1], b + Window);
          std::size_t fieldOffset = 0;
          for (const Field& f : header.Fields)
          {
            if (IsCoordinate(f))
              for (std::uint64_t i = b; i < e; ++i)
                invalidElsewhere = invalidElsewhere || !IsFinite(body + i * recordBytes + fieldOffset, f.Size);
            fieldOffset += f.Bytes();
          }
          if (request->Mapping)
            request->Mapping->Release(header.DataStart + b * recordBytes, header.DataStart + e * recordBytes);
        }
    }
  }
  else if (n > 0)
  {
    Buffer expanded;
    if (!expanded.Allocate(uncompressed))
    {
      error = "out of memory for " + std::to_string(uncompressed) + " uncompressed bytes";
      ok = false;
    }
    else
    {
      unsigned int got = uncompressed == 0 ? 0 :
        lzf_decompress(body + 8, static_cast<unsigned int>(compressedBytes), expanded.Data(), uncompressed);
      if (got != uncompressed)
      {
        error = "corrupt binary_compressed data: the LZF stream of " + std::to_string(compressedBytes) +
          " bytes does not expand to the announced " + std::to_string(uncompressed) + " bytes";
        ok = false;
      }
      else
      {
        // Structure of arrays: one block of n values per field; a piece copies its share of each block.
        std::size_t offset = 0;
        for (std::size_t i = 0; i < header.Fields.size(); ++i)
        {
          const Field& f = header.Fields[i];
          if (f.IsPadding() && !withPadding)
            continue;
          const unsigned char* block = expanded.Data() + offset;
          if (targets[i].Base)
            StridedCopy(block + first * f.Bytes(), f.Bytes(), count, f.Bytes(), targets[i].Base, targets[i].Stride);
          if (findInvalid && IsCoordinate(f))
          {
            for (std::uint64_t k = 0; k < first && !invalidElsewhere; ++k)
              invalidElsewhere = !IsFinite(block + k * f.Size, f.Size);
            for (std::uint64_t k = first + count; k < n && !invalidElsewhere; ++k)
              invalidElsewhere = !IsFinite(block + k * f.Size, f.Size);
          }
          offset += n * f.Bytes();
        }
      }
    }
  }
  if (!ok)
  {
    cloud = Cloud();
    return false;
  }
  cloud.Head.Points = count;
  cloud.First = first;
  cloud.FilePoints = n;
  cloud.InvalidElsewhere = invalidElsewhere;
  return true;
}
} // namespace

bool Decode(const char* data, std::size_t size, Cloud& cloud, std::string& error, bool interleaveXYZ)
{
  return DecodeImpl(data, size, cloud, error, interleaveXYZ, nullptr);
}

bool DecodePiece(const char* data, std::size_t size, const PieceRequest& request, Cloud& cloud, std::string& error,
  bool interleaveXYZ)
{
  return DecodeImpl(data, size, cloud, error, interleaveXYZ, &request);
}

bool ReadPiece(const std::string& path, PieceRequest request, Cloud& cloud, std::string& error, bool interleaveXYZ)
{
  cloud = Cloud();
  MappedFile file;
  // One piece of several: mapped only, so that the rank reads the pages of its share alone.
  if (!file.Open(path, error, /*populate=*/request.Pieces <= 1))
    return false;
  request.Mapping = &file;
  return DecodePiece(file.Data(), file.Size(), request, cloud, error, interleaveXYZ);
}

void TextPiece(const char* data, std::size_t begin, std::size_t end, int piece, int pieces, std::size_t& pieceBegin,
  std::size_t& pieceEnd)
{
  // The first line start at or after byte `at` of the section.
  auto lineStart = [&](std::size_t at) {
    if (at <= begin)
      return begin;
    if (at >= end)
      return end;
    if (data[at - 1] == '\n')
      return at;
    const char* nl = static_cast<const char*>(std::memchr(data + at, '\n', end - at));
    return nl ? static_cast<std::size_t>(nl - data) + 1 : end;
  };
  if (pieces < 1)
    pieces = 1;
  const std::uint64_t bytes = end > begin ? end - begin : 0;
  pieceBegin = piece <= 0 ? begin : lineStart(begin + static_cast<std::size_t>(Share(bytes, piece, pieces)));
  pieceEnd = piece + 1 >= pieces ? std::max(end, begin)
                                 : lineStart(begin + static_cast<std::size_t>(Share(bytes, piece + 1, pieces)));
}

bool ReadFile(const std::string& path, Cloud& cloud, std::string& error, bool interleaveXYZ)
{
  cloud = Cloud();
  MappedFile file;
  if (!file.Open(path, error))
    return false;
  return Decode(file.Data(), file.Size(), cloud, error, interleaveXYZ);
}

} // namespace pcd
} // namespace meshfree
