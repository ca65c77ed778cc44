// The ascii encoding of .pcd: a hand-written tokenizer over the file in memory and std::from_chars /
// std::to_chars (shortest round-trip form), no iostreams: this is what makes millions of points per second.
#include "PCDInternal.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <thread>

namespace meshfree
{
namespace pcd
{
namespace detail
{
namespace
{

template <class T>
bool ParseInteger(const char* b, const char* e, unsigned char* dst)
{
  if (b < e && *b == '+')
    ++b;
  T v;
  auto r = std::from_chars(b, e, v);
  if (r.ec != std::errc() || r.ptr != e)
    return false;
  std::memcpy(dst, &v, sizeof(T));
  return true;
}

template <class T>
bool ParseFloat(const char* b, const char* e, unsigned char* dst)
{
  if (b < e && *b == '+')
    ++b;
  T v;
  auto r = std::from_chars(b, e, v);
  if (r.ec == std::errc::result_out_of_range)
  {
    // Denormals and overflow: from_chars refuses them; they are still valid numbers of the file.
    double d = std::strtod(std::string(b, e).c_str(), nullptr);
    v = static_cast<T>(d);
    r.ptr = e;
    r.ec = std::errc();
  }
  if (r.ec != std::errc() || r.ptr != e)
    return false;
  std::memcpy(dst, &v, sizeof(T));
  return true;
}

// One value of a field, written in the field's own binary type at dst.
bool ParseValue(const char* b, const char* e, const Field& f, bool packedColor, unsigned char* dst)
{
  if (packedColor)
  {
    // PCL >= 1.8 writes the bits as an unsigned integer; older versions wrote the float itself.
    if (ParseInteger<std::uint32_t>(b, e, dst))
      return true;
    return f.Type == 'F' && ParseFloat<float>(b, e, dst);
  }
  switch (f.Type)
  {
    case 'F':
      return f.Size == 4 ? ParseFloat<float>(b, e, dst) : ParseFloat<double>(b, e, dst);
    case 'I':
      switch (f.Size)
      {
        case 1: return ParseInteger<std::int8_t>(b, e, dst);
        case 2: return ParseInteger<std::int16_t>(b, e, dst);
        case 4: return ParseInteger<std::int32_t>(b, e, dst);
        default: return ParseInteger<std::int64_t>(b, e, dst);
      }
    default:
      switch (f.Size)
      {
        case 1: return ParseInteger<std::uint8_t>(b, e, dst);
        case 2: return ParseInteger<std::uint16_t>(b, e, dst);
        case 4: return ParseInteger<std::uint32_t>(b, e, dst);
        default: return ParseInteger<std::uint64_t>(b, e, dst);
      }
  }
}

std::size_t CountTokens(const char* p, const char* e)
{
  std::size_t n = 0;
  while (p < e)
  {
    while (p < e && IsSpace(*p))
      ++p;
    if (p < e)
      ++n;
    while (p < e && !IsSpace(*p))
      ++p;
  }
  return n;
}

template <class T>
void AppendNumber(std::string& out, T v)
{
  char buf[40];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, r.ptr);
}

void AppendValue(std::string& out, const Field& f, bool packedColor, const unsigned char* src)
{
  if (packedColor)
  {
    // A TYPE F colour is written as the float it is (what PCL 1.13's ascii reader and any reader that takes
    // TYPE F literally expect) unless that text would read as an integer, i.e. as the bits themselves (PCL >=
    // 1.8's convention: 0, integral values, NaN and infinities); TYPE U as the integer.
    std::uint32_t bits;
    std::memcpy(&bits, src, 4);
    if (f.Type == 'F')
    {
      float v;
      std::memcpy(&v, src, 4);
      char buf[40];
      char* end = std::to_chars(buf, buf + sizeof(buf), v).ptr;
      if (std::isfinite(v) && std::find_if(buf, end, [](char c) { return c == '.' || c == 'e'; }) != end)
      {
        out.append(buf, static_cast<std::size_t>(end - buf));
        return;
      }
    }
    AppendNumber(out, bits);
    return;
  }
#define MESHFREE_APPEND(T)                                                                          \
  {                                                                                                 \
    T v;                                                                                            \
    std::memcpy(&v, src, sizeof(T));                                                                \
    AppendNumber(out, v);                                                                           \
    return;                                                                                         \
  }
  switch (f.Type)
  {
    case 'F':
      if (f.Size == 4)
        MESHFREE_APPEND(float)
      MESHFREE_APPEND(double)
    case 'I':
      switch (f.Size)
      {
        case 1: MESHFREE_APPEND(std::int8_t)
        case 2: MESHFREE_APPEND(std::int16_t)
        case 4: MESHFREE_APPEND(std::int32_t)
        default: MESHFREE_APPEND(std::int64_t)
      }
    default:
      switch (f.Size)
      {
        case 1: MESHFREE_APPEND(std::uint8_t)
        case 2: MESHFREE_APPEND(std::uint16_t)
        case 4: MESHFREE_APPEND(std::uint32_t)
        default: MESHFREE_APPEND(std::uint64_t)
      }
  }
#undef MESHFREE_APPEND
}
} // namespace

namespace
{
// What every range of the ascii data needs to know about the fields.
struct AsciiLayout
{
  const Header* Head = nullptr;
  std::vector<Target> Targets; // per field; Base null for padding
  std::vector<char> Packed;     // per field: PCL's packed colour
  std::size_t ValuesNoPad = 0, ValuesPad = 0;
  bool HasPadding = false;
};

// Parses the points [first, first + count) from the lines starting at p. On success p is after the last
// point's line; line counts the newlines passed. False with a message naming the line on any problem.
// The targets hold point i at index i - targetFirst.
bool ParseRange(const AsciiLayout& L, const char*& p, const char* end, std::uint64_t first,
  std::uint64_t count, std::size_t& line, std::string& error, std::uint64_t targetFirst = 0)
{
  const Header& h = *L.Head;
  auto fail = [&](const std::string& what) {
    error = "ascii data, line " + std::to_string(line) + ": " + what;
    return false;
  };
  for (std::uint64_t i = first; i < first + count;)
  {
    while (p < end && IsSpace(*p))
      ++p;
    if (p == end)
      return fail("the data ends after " + std::to_string(i) + " of " + std::to_string(h.Points) +
        " points (truncated, or POINTS does not match)");
    if (*p == '\n')
    {
      ++p, ++line;
      continue;
    }
    bool readPadding = false;
    if (L.HasPadding)
    {
      // PCL writes no padding values in ascii but its reader expects them: accept both layouts.
      const char* nl = static_cast<const char*>(std::memchr(p, '\n', end - p));
      const std::size_t n = CountTokens(p, nl ? nl : end);
      readPadding = (n == L.ValuesPad);
      if (n != L.ValuesPad && n != L.ValuesNoPad)
        return fail(std::to_string(n) + " values where the FIELDS and COUNT announce " +
          std::to_string(L.ValuesNoPad));
    }
    for (std::size_t fi = 0; fi < h.Fields.size(); ++fi)
    {
      const Field& f = h.Fields[fi];
      const bool pad = L.Targets[fi].Base == nullptr;
      if (pad && !readPadding)
        continue;
      const std::size_t size = static_cast<std::size_t>(f.Size);
      for (int k = 0; k < f.Count; ++k)
      {
        while (p < end && IsSpace(*p))
          ++p;
        if (p == end || *p == '\n')
          return fail("point " + std::to_string(i) + " has fewer values than the FIELDS and COUNT announce (" +
            std::to_string(L.ValuesNoPad) + ")");
        const char* t = p;
        while (p < end && !IsSpace(*p) && *p != '\n')
          ++p;
        if (pad)
          continue;
        unsigned char* out = L.Targets[fi].Base + (i - targetFirst) * L.Targets[fi].Stride + k * size;
        if (!ParseValue(t, p, f, L.Packed[fi], out))
          return fail("'" + std::string(t, std::min<std::size_t>(p - t, 40)) + "' is not a valid value of field '" +
            f.Name + "' (TYPE " + std::string(1, f.Type) + ", SIZE " + std::to_string(f.Size) + ")");
      }
    }
    while (p < end && IsSpace(*p))
      ++p;
    if (p < end && *p != '\n')
      return fail("point " + std::to_string(i) + " has more values than the FIELDS and COUNT announce (" +
        std::to_string(L.ValuesNoPad) + ")");
    if (p < end)
      ++p, ++line;
    ++i;
  }
  return true;
}

AsciiLayout Layout(const Header& h, const std::vector<Target>& targets)
{
  AsciiLayout L;
  L.Head = &h;
  L.Targets = targets;
  L.Packed.assign(h.Fields.size(), 0);
  for (std::size_t i = 0; i < h.Fields.size(); ++i)
  {
    L.Packed[i] = IsPackedColor(h.Fields[i]);
    L.ValuesPad += h.Fields[i].Count;
    if (h.Fields[i].IsPadding())
      L.HasPadding = true;
    else
      L.ValuesNoPad += h.Fields[i].Count;
  }
  return L;
}

// Lines holding something other than blanks, and newlines, in [b, e). Line ends are found with memchr
// (vectorised) and only the start of each line is looked at: a byte-by-byte pass here used to cost a third
// of the whole ascii decoding.
void CountLines(const char* b, const char* e, std::uint64_t& points, std::size_t& newlines)
{
  points = 0, newlines = 0;
  while (b < e)
  {
    const char* nl = static_cast<const char*>(std::memchr(b, '\n', e - b));
    const char* le = nl ? nl : e;
    while (b < le && IsSpace(*b))
      ++b;
    points += (b < le);
    newlines += (nl != nullptr);
    b = nl ? nl + 1 : e;
  }
}
// CountLines over [b, e), a window at a time (ScanTextReleasing): a pass over the whole file keeps none of it.
void CountLinesReleasing(const char* data, std::size_t b, std::size_t e, const MappedFile* mapping,
  std::uint64_t& points, std::size_t& newlines)
{
  points = 0, newlines = 0;
  ScanTextReleasing(data, b, e, mapping, [&](const char* begin, const char* end) {
    std::uint64_t p = 0;
    std::size_t n = 0;
    CountLines(begin, end, p, n);
    points += p, newlines += n;
  });
}
} // namespace

bool AsciiPieceBounds(const char* data, std::size_t size, const Header& h, const PieceRequest& request,
  AsciiPiece& piece, std::string& error)
{
  TextPiece(data, h.DataStart, size, request.Piece, request.Pieces, piece.Begin, piece.End);
  std::uint64_t after = 0;
  std::size_t newlines = 0, skip = 0;
  CountLinesReleasing(data, h.DataStart, piece.Begin, request.Mapping, piece.First, newlines);
  CountLines(data + piece.Begin, data + piece.End, piece.Count, skip);
  CountLinesReleasing(data, piece.End, size, request.Mapping, after, skip);
  piece.Line = 1 + newlines;
  for (const char* q = data; q < data + h.DataStart; ++q)
    piece.Line += (*q == '\n');
  const std::uint64_t total = piece.First + piece.Count + after;
  if (total < h.Points)
  {
    error = "ascii data: the data ends after " + std::to_string(total) + " of " + std::to_string(h.Points) +
      " points (truncated, or POINTS does not match)";
    return false;
  }
  if (total > h.Points)
  {
    error = "ascii data: " + std::to_string(total) + " lines of points, more data than the " +
      std::to_string(h.Points) + " points of POINTS";
    return false;
  }
  return true;
}

bool DecodeAsciiPiece(const char* data, const Header& h, const std::vector<Target>& targets, const AsciiPiece& piece,
  std::string& error)
{
  const AsciiLayout L = Layout(h, targets);
  const char* p = data + piece.Begin;
  std::size_t line = piece.Line;
  return ParseRange(L, p, data + piece.End, piece.First, piece.Count, line, error, piece.First);
}

bool AsciiInvalidElsewhere(const char* data, std::size_t size, const Header& h, const AsciiPiece& piece,
  const MappedFile* mapping, bool& found, std::string& error)
{
  // The lines outside the piece, parsed in chunks into scratch columns and checked like DropInvalidPoints: this
  // is a full parse of the rest of the file (kept: one chunk).
  constexpr std::uint64_t Chunk = 4096;
  found = false;
  std::vector<std::vector<unsigned char>> scratch(h.Fields.size());
  std::vector<Target> targets(h.Fields.size());
  std::vector<int> coordinates;
  for (std::size_t i = 0; i < h.Fields.size(); ++i)
  {
    const Field& f = h.Fields[i];
    if (f.IsPadding())
      continue;
    scratch[i].resize(Chunk * f.Bytes());
    targets[i] = { scratch[i].data(), f.Bytes() };
    if ((f.Name == "x" || f.Name == "y" || f.Name == "z") && f.Type == 'F' && f.Count == 1)
      coordinates.push_back(static_cast<int>(i));
  }
  if (coordinates.empty())
    return true;
  const AsciiLayout L = Layout(h, targets);
  struct Range
  {
    std::size_t Begin, End;
    std::uint64_t First, Count;
    std::size_t Line;
  };
  std::size_t firstLine = 1;
  for (const char* q = data; q < data + h.DataStart; ++q)
    firstLine += (*q == '\n');
  const Range ranges[] = { { h.DataStart, piece.Begin, 0, piece.First, firstLine },
    { piece.End, size, piece.First + piece.Count, h.Points - piece.First - piece.Count, 0 } };
  for (const Range& r : ranges)
  {
    const char* p = data + r.Begin;
    std::size_t line = r.Line;
    if (&r != &ranges[0])
    {
      line = piece.Line;
      for (const char* q = data + piece.Begin; q < p; ++q)
        line += (*q == '\n');
    }
    for (std::uint64_t i = r.First; i < r.First + r.Count && !found;)
    {
      const std::uint64_t n = std::min(Chunk, r.First + r.Count - i);
      const char* before = p;
      if (!ParseRange(L, p, data + r.End, i, n, line, error, i))
        return false;
      for (std::uint64_t k = 0; k < n && !found; ++k)
        for (int c : coordinates)
        {
          const Field& f = h.Fields[c];
          double v;
          if (f.Size == 4)
          {
            float x;
            std::memcpy(&x, scratch[c].data() + 4 * k, 4);
            v = x;
          }
          else
            std::memcpy(&v, scratch[c].data() + 8 * k, 8);
          found = found || !std::isfinite(v);
        }
      if (mapping)
        mapping->Release(static_cast<std::size_t>(before - data), static_cast<std::size_t>(p - data));
      i += n;
    }
  }
  return true;
}

bool DecodeAscii(const char* data, std::size_t size, const Header& h, const std::vector<Target>& targets,
  std::string& error)
{
  const char* p = data + h.DataStart;
  const char* const end = data + size;
  std::size_t line = 1;
  for (const char* q = data; q < p; ++q)
    line += (*q == '\n');

  const AsciiLayout L = Layout(h, targets);

  // Large files: split the data at line boundaries and parse the pieces on all cores. Each piece's
  // first point and line number come from a (parallel) count of its lines. If the counts do not add up
  // to POINTS, the serial pass below reports exactly where the file goes wrong.
  const unsigned threads = std::min(8u, std::max(1u, std::thread::hardware_concurrency()));
  if (threads > 1 && static_cast<std::size_t>(end - p) > (4u << 20))
  {
    std::vector<const char*> cut(threads + 1, end);
    cut[0] = p;
    for (unsigned k = 1; k < threads; ++k)
    {
      const char* q = p + (end - p) * k / threads;
      q = std::max(q, cut[k - 1]);
      const char* nl = static_cast<const char*>(std::memchr(q, '\n', end - q));
      cut[k] = nl ? nl + 1 : end;
    }
    std::vector<std::uint64_t> points(threads);
    std::vector<std::size_t> newlines(threads);
    {
      std::vector<std::thread> pool;
      for (unsigned k = 0; k < threads; ++k)
        pool.emplace_back([&, k] { CountLines(cut[k], cut[k + 1], points[k], newlines[k]); });
      for (auto& t : pool)
        t.join();
    }
    std::uint64_t total = 0;
    for (unsigned k = 0; k < threads; ++k)
      total += points[k];
    if (total == h.Points)
    {
      std::vector<std::string> errors(threads);
      std::vector<char> ok(threads, 1);
      std::vector<std::thread> pool;
      std::uint64_t first = 0;
      std::size_t firstLine = line;
      for (unsigned k = 0; k < threads; ++k)
      {
        pool.emplace_back([&, k, first, firstLine] {
          const char* q = cut[k];
          std::size_t l = firstLine;
          ok[k] = ParseRange(L, q, cut[k + 1], first, points[k], l, errors[k]);
        });
        first += points[k];
        firstLine += newlines[k];
      }
      for (auto& t : pool)
        t.join();
      for (unsigned k = 0; k < threads; ++k)
        if (!ok[k])
        {
          error = errors[k];
          return false;
        }
      return true;
    }
  }

  if (!ParseRange(L, p, end, 0, h.Points, line, error))
    return false;
  while (p < end && (IsSpace(*p) || *p == '\n'))
    line += (*p++ == '\n');
  if (p != end)
  {
    error = "ascii data, line " + std::to_string(line) + ": more data after the " + std::to_string(h.Points) +
      " points of POINTS";
    return false;
  }
  return true;
}

void EncodeAscii(const Header& h, const std::vector<const void*>& columns, std::string& out)
{
  std::size_t values = 0;
  for (const Field& f : h.Fields)
    values += f.Count;
  out.reserve(out.size() + h.Points * values * 12);
  std::vector<char> packed(h.Fields.size());
  for (std::size_t i = 0; i < h.Fields.size(); ++i)
    packed[i] = IsPackedColor(h.Fields[i]);
  for (std::uint64_t i = 0; i < h.Points; ++i)
  {
    bool first = true;
    for (std::size_t fi = 0; fi < h.Fields.size(); ++fi)
    {
      const Field& f = h.Fields[fi];
      const auto* src = static_cast<const unsigned char*>(columns[fi]) + i * f.Bytes();
      for (int k = 0; k < f.Count; ++k)
      {
        if (!first)
          out.push_back(' ');
        first = false;
        AppendValue(out, f, packed[fi], src + k * f.Size);
      }
    }
    out.push_back('\n');
  }
}

} // namespace detail
} // namespace pcd
} // namespace meshfree
