#include "XYZFormat.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace meshfree
{
namespace xyz
{
namespace
{
constexpr std::size_t SniffBytes = 64 * 1024;

inline bool IsBlank(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
inline bool IsSeparator(char c)
{
  return IsBlank(c) || c == ',' || c == ';';
}

bool ParseDouble(const char* b, const char* e, double& v)
{
  if (b < e && *b == '+')
    ++b;
  auto r = std::from_chars(b, e, v);
  if (r.ec == std::errc::result_out_of_range)
  {
    v = std::strtod(std::string(b, e).c_str(), nullptr);
    return true;
  }
  return r.ec == std::errc() && r.ptr == e;
}

// Splits one line into fields. A run of separators counts once, but two commas (or semicolons) in a
// row mean an empty field, which is an error. Returns false with a message on that.
bool SplitLine(const char* b, const char* e, std::vector<std::pair<const char*, const char*>>& out,
  std::string& error)
{
  out.clear();
  while (b < e && IsBlank(*b))
    ++b;
  while (b < e)
  {
    const char* t = b;
    while (b < e && !IsSeparator(*b))
      ++b;
    if (b == t)
    {
      error = "empty field";
      return false;
    }
    out.emplace_back(t, b);
    int hard = 0;
    for (; b < e && IsSeparator(*b); ++b)
      hard += (*b == ',' || *b == ';');
    if (hard > 1 || (hard == 1 && b == e))
    {
      error = "empty field";
      return false;
    }
  }
  return true;
}

// A line of the data section that holds a row: not blank, not a comment (# or //).
inline bool IsRowLine(const char* b, const char* e)
{
  while (b < e && IsBlank(*b))
    ++b;
  return b < e && *b != '#' && !(e - b >= 2 && b[0] == '/' && b[1] == '/');
}

// One row of `columns` numbers into out, without building a field list: the hot loop of a large file.
// False on anything unusual; RowError then says what (with the same rules as SplitLine).
inline bool FastRow(const char* p, const char* e, std::size_t columns, double* out)
{
  while (p < e && IsBlank(*p))
    ++p;
  std::size_t k = 0;
  while (p < e)
  {
    const char* t = p;
    while (p < e && !IsSeparator(*p))
      ++p;
    if (p == t || k == columns)
      return false;
    const char* b = t + (*t == '+');
    auto r = std::from_chars(b, p, out[k]);
    if (r.ec != std::errc() || r.ptr != p)
    {
      if (r.ec != std::errc::result_out_of_range)
        return false;
      out[k] = std::strtod(std::string(b, p).c_str(), nullptr); // denormal or overflow: still a number
    }
    ++k;
    int hard = 0;
    for (; p < e && IsSeparator(*p); ++p)
      hard += (*p == ',' || *p == ';');
    if (hard > 1 || (hard == 1 && p == e))
      return false;
  }
  return k == columns;
}

// Rows and newlines in [b, e) (both ends at line boundaries).
void CountRows(const char* b, const char* e, std::uint64_t& rows, std::size_t& newlines)
{
  rows = 0, newlines = 0;
  while (b < e)
  {
    const char* nl = static_cast<const char*>(std::memchr(b, '\n', e - b));
    const char* le = nl ? nl : e;
    rows += IsRowLine(b, le);
    newlines += (nl != nullptr);
    b = nl ? nl + 1 : e;
  }
}

// What is wrong with a row FastRow refused (the messages of the line-by-line rules).
std::string RowError(const char* b, const char* e, std::size_t columns)
{
  std::vector<std::pair<const char*, const char*>> fields;
  std::string error;
  if (!SplitLine(b, e, fields, error))
    return error;
  if (fields.size() != columns)
    return std::to_string(fields.size()) + " columns where the cloud has " + std::to_string(columns);
  for (const auto& f : fields)
  {
    double v;
    if (!ParseDouble(f.first, f.second, v))
      return "'" + std::string(f.first, std::min<std::ptrdiff_t>(f.second - f.first, 40)) + "' is not a number";
  }
  return "unreadable row";
}

// Parses the rows of [b, e) into out (advance: one row after the other; otherwise every row into the same
// scratch row, to find the first error without the memory). line: the number of the line before b.
bool ParseRows(const char* b, const char* e, std::size_t columns, double* out, bool advance, std::size_t line,
  std::string& error)
{
  while (b < e)
  {
    const char* nl = static_cast<const char*>(std::memchr(b, '\n', e - b));
    const char* le = nl ? nl : e;
    ++line;
    if (IsRowLine(b, le))
    {
      if (!FastRow(b, le, columns, out))
      {
        error = "line " + std::to_string(line) + ": " + RowError(b, le, columns);
        return false;
      }
      out += advance ? columns : 0;
    }
    b = nl ? nl + 1 : e;
  }
  return true;
}

// The data rows after the first one (already in table.Values): counted, allocated once, parsed in place;
// large files in pieces split at line boundaries, one thread each. line: the number of the first row's line.
bool ParseData(const char* b, const char* e, std::size_t columns, std::size_t line, Table& table,
  std::string& error)
{
  const std::size_t bytes = static_cast<std::size_t>(e - b);
  unsigned threads = std::min(8u, std::max(1u, std::thread::hardware_concurrency()));
  if (bytes < (std::size_t(4) << 20))
    threads = 1;
  std::vector<const char*> cut(threads + 1, e);
  cut[0] = b;
  for (unsigned k = 1; k < threads; ++k)
  {
    const char* q = std::max(b + bytes * k / threads, cut[k - 1]);
    const char* nl = static_cast<const char*>(std::memchr(q, '\n', e - q));
    cut[k] = nl ? nl + 1 : e;
  }
  std::vector<std::uint64_t> rows(threads);
  std::vector<std::size_t> newlines(threads);
  auto run = [threads](const auto& work) {
    if (threads == 1)
      return work(0u);
    std::vector<std::thread> pool;
    for (unsigned k = 0; k < threads; ++k)
      pool.emplace_back(work, k);
    for (auto& t : pool)
      t.join();
  };
  run([&](unsigned k) { CountRows(cut[k], cut[k + 1], rows[k], newlines[k]); });
  std::uint64_t total = 1;
  for (unsigned k = 0; k < threads; ++k)
    total += rows[k];
  // Each row of `columns` numbers takes at least 2 * columns - 1 characters: a count beyond that means
  // short rows, an error found without allocating for them.
  if ((total - 1) > bytes / (2 * columns - 1) + 1)
  {
    std::vector<double> row(columns);
    if (!ParseRows(b, e, columns, row.data(), false, line, error))
      return false;
    error = "line " + std::to_string(line) + ": rows too short for " + std::to_string(columns) + " columns";
    return false;
  }
  try
  {
    table.Values.resize(total * columns);
  }
  catch (const std::bad_alloc&)
  {
    error = "out of memory for " + std::to_string(total) + " rows of " + std::to_string(columns) + " columns";
    return false;
  }
  std::vector<std::string> errors(threads);
  std::vector<char> ok(threads, 1);
  std::vector<std::uint64_t> firstRow(threads, 1);
  std::vector<std::size_t> firstLine(threads, line);
  for (unsigned k = 1; k < threads; ++k)
  {
    firstRow[k] = firstRow[k - 1] + rows[k - 1];
    firstLine[k] = firstLine[k - 1] + newlines[k - 1];
  }
  double* values = table.Values.data();
  run([&](unsigned k) {
    ok[k] = ParseRows(cut[k], cut[k + 1], columns, values + firstRow[k] * columns, true, firstLine[k], errors[k]);
  });
  for (unsigned k = 0; k < threads; ++k)
    if (!ok[k])
    {
      error = errors[k];
      return false;
    }
  table.Rows = total;
  return true;
}

// CountRows over [b, e) of data, a window at a time (pcd::ScanTextReleasing).
std::uint64_t CountRowsReleasing(const char* data, std::size_t b, std::size_t e, const pcd::MappedFile* mapping)
{
  std::uint64_t total = 0;
  pcd::ScanTextReleasing(data, b, e, mapping, [&](const char* begin, const char* end) {
    std::uint64_t rows = 0;
    std::size_t newlines = 0;
    CountRows(begin, end, rows, newlines);
    total += rows;
  });
  return total;
}

// The line number of the line before data + at.
std::size_t LinesBefore(const char* data, std::size_t at)
{
  return static_cast<std::size_t>(std::count(data, data + at, '\n'));
}

// The rows of [table.PieceBegin, table.PieceEnd) of a piece: counted, allocated once, parsed in place.
bool ParsePieceRows(const char* data, std::size_t columns, Table& table, std::string& error)
{
  const char* b = data + table.PieceBegin;
  const char* e = data + table.PieceEnd;
  std::uint64_t rows = 0;
  std::size_t newlines = 0;
  CountRows(b, e, rows, newlines);
  try
  {
    table.Values.resize(rows * columns);
  }
  catch (const std::bad_alloc&)
  {
    error = "out of memory for " + std::to_string(rows) + " rows of " + std::to_string(columns) + " columns";
    return false;
  }
  // Line numbers cost a pass over the file before the piece: counted only for a message.
  if (!ParseRows(b, e, columns, table.Values.data(), true, 0, error))
  {
    ParseRows(b, e, columns, table.Values.data(), false, LinesBefore(data, table.PieceBegin), error);
    return false;
  }
  table.Rows = rows;
  return true;
}

std::string Lower(std::string s)
{
  for (char& c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// request: a piece (ParsePiece), null: the whole data.
bool ParseImpl(const char* data, std::size_t size, bool sniff, Table& table, std::string& error,
  const pcd::PieceRequest* request = nullptr)
{
  std::uint64_t fileRows = 0; // a piece: the rows of the whole file, counted only for a Leica count
  table = Table();
  const char* p = data;
  const char* end = data + size;
  if (size >= 3 && std::memcmp(p, "\xEF\xBB\xBF", 3) == 0)
    p += 3;
  std::vector<std::pair<const char*, const char*>> fields;
  std::size_t columns = 0, line = 0;
  bool inData = false;
  auto fail = [&](const std::string& what) {
    error = "line " + std::to_string(line) + ": " + what;
    table = Table();
    return false;
  };
  while (p < end)
  {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', end - p));
    const char* lineBegin = p;
    const char* b = p;
    const char* e = nl ? nl : end;
    p = nl ? nl + 1 : end;
    ++line;
    while (b < e && IsBlank(*b))
      ++b;
    if (b == e)
      continue;
    bool comment = (*b == '#') || (e - b >= 2 && b[0] == '/' && b[1] == '/');
    if (comment)
    {
      if (inData || !table.Names.empty())
        continue;
      b += (*b == '#') ? 1 : 2;
    }
    if (!SplitLine(b, e, fields, error))
    {
      if (comment)
        continue;
      return fail(error);
    }
    if (fields.empty())
      continue;

    if (inData)
    {
      if (fields.size() != columns)
        return fail(std::to_string(fields.size()) + " columns where the cloud has " + std::to_string(columns));
      for (const auto& f : fields)
      {
        double v;
        if (!ParseDouble(f.first, f.second, v))
          return fail("'" + std::string(f.first, std::min<std::ptrdiff_t>(f.second - f.first, 40)) +
            "' is not a number");
        table.Values.push_back(v);
      }
      ++table.Rows;
      continue;
    }

    std::size_t numeric = 0;
    for (const auto& f : fields)
    {
      double v;
      numeric += ParseDouble(f.first, f.second, v);
    }
    if (comment)
    {
      // "# x y z intensity" or CloudCompare's "//X Y Z R G B" names the columns; other comments do not.
      std::vector<std::string> names;
      for (const auto& f : fields)
        names.push_back(Lower(std::string(f.first, f.second)));
      const bool named = numeric == 0 && names.size() >= 3 &&
        std::find(names.begin(), names.end(), "x") != names.end() &&
        std::find(names.begin(), names.end(), "y") != names.end() &&
        std::find(names.begin(), names.end(), "z") != names.end();
      if (!named)
        continue;
    }
    if (numeric == fields.size() && !comment)
    {
      std::int64_t count = 0;
      auto r = std::from_chars(fields[0].first, fields[0].second, count);
      if (fields.size() == 1 && table.DeclaredCount < 0 && table.Names.empty() &&
        r.ec == std::errc() && r.ptr == fields[0].second && count >= 0)
      {
        table.DeclaredCount = count; // Leica .pts: the number of points comes first
        continue;
      }
      if (fields.size() < 3)
        return fail(std::to_string(fields.size()) + " columns: x y z expected");
      if (!table.Names.empty() && fields.size() != table.Names.size())
        return fail(std::to_string(fields.size()) + " columns where the header names " +
          std::to_string(table.Names.size()));
      columns = fields.size();
      inData = true;
      for (const auto& f : fields)
      {
        double v;
        ParseDouble(f.first, f.second, v);
        table.Values.push_back(v);
      }
      ++table.Rows;
      if (!sniff && request && request->Pieces > 1)
      {
        // A piece: the data section starts at this row's line; every piece parsed the lines before it alike.
        table.Values.clear();
        table.Rows = 0;
        table.IsPiece = true;
        table.DataBegin = static_cast<std::size_t>(lineBegin - data);
        pcd::TextPiece(data, table.DataBegin, size, request->Piece, request->Pieces, table.PieceBegin, table.PieceEnd);
        if (table.DeclaredCount >= 0)
          fileRows = CountRowsReleasing(data, table.DataBegin, table.PieceBegin, request->Mapping) +
            CountRowsReleasing(data, table.PieceEnd, size, request->Mapping);
        if (!ParsePieceRows(data, columns, table, error))
        {
          table = Table();
          return false;
        }
        fileRows += table.Rows;
        break;
      }
      if (!sniff)
      {
        // The rest is data: in bulk.
        if (!ParseData(p, end, columns, line, table, error))
        {
          table = Table();
          return false;
        }
        break;
      }
      continue;
    }
    if (!table.Names.empty())
      return fail("a second header line, or a row that is not numbers");
    if (fields.size() < 3)
      return fail("a header of " + std::to_string(fields.size()) + " names: x y z expected");
    for (const auto& f : fields)
      table.Names.emplace_back(f.first, f.second);
    table.NamedByHeader = true;
  }
  if (table.NamedByHeader)
  {
    for (int k = 0; k < 3; ++k)
    {
      const std::string want(1, "xyz"[k]);
      for (std::size_t c = 0; c < table.Names.size(); ++c)
        if (Lower(table.Names[c]) == want)
        {
          table.Coordinate[k] = static_cast<int>(c);
          break;
        }
    }
    if (table.Coordinate[0] == table.Coordinate[1] || table.Coordinate[1] == table.Coordinate[2] ||
      table.Coordinate[0] == table.Coordinate[2])
      table.Coordinate[0] = 0, table.Coordinate[1] = 1, table.Coordinate[2] = 2;
  }
  else
  {
    for (std::size_t c = 0; c < columns; ++c)
      table.Names.push_back(c < 3 ? std::string(1, "xyz"[c]) : "Column" + std::to_string(c + 1));
  }
  if (!(request && request->Pieces > 1 && inData))
    fileRows = table.Rows;
  if (!sniff && table.DeclaredCount >= 0 && static_cast<std::uint64_t>(table.DeclaredCount) != fileRows)
  {
    error = "the first line announces " + std::to_string(table.DeclaredCount) + " points, the file holds " +
      std::to_string(fileRows);
    table = Table();
    return false;
  }
  return true;
}
} // namespace

bool Parse(const char* data, std::size_t size, Table& table, std::string& error)
{
  return ParseImpl(data, size, false, table, error);
}

bool ParsePiece(const char* data, std::size_t size, const pcd::PieceRequest& request, Table& table, std::string& error)
{
  if (request.Pieces > 1 && (request.Piece < 0 || request.Piece >= request.Pieces))
  {
    table = Table();
    error = "piece " + std::to_string(request.Piece) + " of " + std::to_string(request.Pieces) + " does not exist";
    return false;
  }
  return ParseImpl(data, size, false, table, error, &request);
}

bool ForEachRowElsewhere(const char* data, std::size_t size, const Table& table, const pcd::MappedFile* mapping,
  const std::function<bool(const double*)>& visit, std::string& error)
{
  if (!table.IsPiece)
    return true; // the whole file, or a file without rows
  const std::size_t columns = table.Names.size();
  std::vector<double> row(columns);
  const std::size_t ranges[2][2] = { { table.DataBegin, table.PieceBegin }, { table.PieceEnd, size } };
  for (const auto& r : ranges)
  {
    std::size_t at = r[0], released = r[0];
    while (at < r[1])
    {
      const char* b = data + at;
      const char* nl = static_cast<const char*>(std::memchr(b, '\n', r[1] - at));
      const char* le = nl ? nl : data + r[1];
      if (IsRowLine(b, le))
      {
        if (!FastRow(b, le, columns, row.data()))
        {
          error = "line " + std::to_string(LinesBefore(data, at) + 1) + ": " + RowError(b, le, columns);
          return false;
        }
        if (!visit(row.data()))
          return true;
      }
      at = nl ? static_cast<std::size_t>(nl - data) + 1 : r[1];
      if (mapping && at - released > (std::size_t(32) << 20))
        mapping->Release(released, at), released = at;
    }
    if (mapping)
      mapping->Release(released, r[1]);
  }
  return true;
}

bool LooksBinary(const char* data, std::size_t size)
{
  const std::size_t n = std::min(size, SniffBytes);
  for (std::size_t i = 0; i < n; ++i)
  {
    const unsigned char c = static_cast<unsigned char>(data[i]);
    if (c == 0 || (c < 32 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v'))
      return true;
  }
  return false;
}

bool LooksLikePlot3D(const char* data, std::size_t size)
{
  auto word = [&](std::size_t at, bool big) {
    unsigned char b[4];
    std::memcpy(b, data + at, 4);
    const std::uint32_t u = big ? (std::uint32_t(b[0]) << 24 | std::uint32_t(b[1]) << 16 | std::uint32_t(b[2]) << 8 | b[3])
                                : (std::uint32_t(b[3]) << 24 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[1]) << 8 | b[0]);
    return static_cast<std::int64_t>(static_cast<std::int32_t>(u));
  };
  constexpr std::int64_t MaxCount = 100000000;
  for (bool big : { false, true })
  {
    if (size < 8)
      continue;
    const std::int64_t first = word(0, big), second = word(4, big);
    // Fortran unformatted: <n> n bytes <n>.
    if (first > 0 && first % 4 == 0 && static_cast<std::uint64_t>(first) + 8 <= size &&
      word(4 + static_cast<std::size_t>(first), big) == first)
      return true;
    // C binary: the number of grids, or the first dimensions, as positive counts.
    if (first >= 1 && first <= MaxCount && second >= 1 && second <= MaxCount)
      return true;
  }
  return false;
}

bool LooksLikeCloud(const char* data, std::size_t size)
{
  std::size_t n = std::min(size, SniffBytes);
  if (LooksBinary(data, n))
    return false; // binary: PLOT3D grids and the like
  if (n < size)
  {
    // Only whole lines of the window.
    while (n > 0 && data[n - 1] != '\n')
      --n;
  }
  Table table;
  std::string error;
  return ParseImpl(data, n, true, table, error) && table.Rows > 0;
}

} // namespace xyz
} // namespace meshfree
