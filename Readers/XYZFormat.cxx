#include "XYZFormat.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <cstring>

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

std::string Lower(std::string s)
{
  for (char& c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool ParseImpl(const char* data, std::size_t size, bool sniff, Table& table, std::string& error)
{
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
      if (!sniff && table.DeclaredCount > 0)
        table.Values.reserve(std::min<std::uint64_t>(table.DeclaredCount, size / 6) * columns);
      for (const auto& f : fields)
      {
        double v;
        ParseDouble(f.first, f.second, v);
        table.Values.push_back(v);
      }
      ++table.Rows;
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
  if (!sniff && table.DeclaredCount >= 0 && static_cast<std::uint64_t>(table.DeclaredCount) != table.Rows)
  {
    error = "the first line announces " + std::to_string(table.DeclaredCount) + " points, the file holds " +
      std::to_string(table.Rows);
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

bool LooksLikeCloud(const char* data, std::size_t size)
{
  std::size_t n = std::min(size, SniffBytes);
  for (std::size_t i = 0; i < n; ++i)
  {
    const unsigned char c = static_cast<unsigned char>(data[i]);
    if (c == 0 || (c < 32 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v'))
      return false; // binary: PLOT3D grids and the like
  }
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
