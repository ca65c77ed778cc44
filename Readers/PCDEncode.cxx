// Writing .pcd: the header PCL writes, and the three encodings (binary_compressed with LZF, as PCL does).
#include "PCDFormat.h"
#include "PCDInternal.h"

#include <lzf.h>

#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

namespace meshfree
{
namespace pcd
{
using namespace detail;

bool Encode(const Header& header, const std::vector<const void*>& columns, std::string& out,
  std::string& error)
{
  if (header.Fields.empty() || columns.size() != header.Fields.size())
  {
    error = "one column per field is needed";
    return false;
  }
  for (const Field& f : header.Fields)
  {
    if (f.Name.empty() || f.IsPadding() || Tokens(f.Name.data(), f.Name.data() + f.Name.size()).size() != 1)
    {
      error = "invalid field name '" + f.Name + "'";
      return false;
    }
    if (!ValidateField(f, error))
      return false;
  }
  std::uint64_t wh = 0;
  if (MulOverflows(header.Width, header.Height, wh) || wh != header.Points)
  {
    error = "WIDTH x HEIGHT differs from POINTS";
    return false;
  }
  const std::uint64_t n = header.Points;
  std::string fields, sizes, types, counts;
  for (const Field& f : header.Fields)
  {
    fields += " " + f.Name;
    sizes += " " + std::to_string(f.Size);
    types += std::string(" ") + f.Type;
    counts += " " + std::to_string(f.Count);
  }
  std::string viewpoint;
  for (double v : header.Viewpoint)
  {
    char buf[32];
    auto r = std::to_chars(buf, buf + sizeof(buf), v);
    viewpoint += " " + std::string(buf, r.ptr);
  }
  out += "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS" + fields + "\nSIZE" + sizes +
    "\nTYPE" + types + "\nCOUNT" + counts + "\nWIDTH " + std::to_string(header.Width) + "\nHEIGHT " +
    std::to_string(header.Height) + "\nVIEWPOINT" + viewpoint + "\nPOINTS " + std::to_string(n) +
    "\nDATA " + EncodingName(header.Data) + "\n";

  const std::size_t recordBytes = header.PointBytes(false);
  if (header.Data == Encoding::Ascii)
    detail::EncodeAscii(header, columns, out);
  else if (header.Data == Encoding::Binary)
  {
    const std::size_t start = out.size();
    out.resize(start + n * recordBytes);
    std::size_t offset = 0;
    for (std::size_t i = 0; i < header.Fields.size(); ++i)
    {
      const std::size_t b = header.Fields[i].Bytes();
      StridedCopy(static_cast<const unsigned char*>(columns[i]), b, n, b,
        reinterpret_cast<unsigned char*>(&out[start + offset]), recordBytes);
      offset += b;
    }
  }
  else
  {
    const std::uint64_t total = n * recordBytes;
    if (total > std::numeric_limits<std::uint32_t>::max() / 2)
    {
      error = "too many points for binary_compressed (its sizes are 32-bit)";
      return false;
    }
    std::string soa;
    soa.reserve(total);
    for (std::size_t i = 0; i < header.Fields.size(); ++i)
      soa.append(static_cast<const char*>(columns[i]), n * header.Fields[i].Bytes());
    std::string packed(total + total / 16 + 64, '\0');
    unsigned int got = total == 0 ? 0 :
      lzf_compress(soa.data(), static_cast<unsigned int>(total), &packed[0], static_cast<unsigned int>(packed.size()));
    if (total > 0 && got == 0)
    {
      error = "LZF compression failed";
      return false;
    }
    std::uint32_t sizesWords[2] = { got, static_cast<std::uint32_t>(total) };
    out.append(reinterpret_cast<const char*>(sizesWords), 8);
    out.append(packed.data(), got);
  }
  return true;
}

bool WriteFile(const std::string& path, const Header& header,
  const std::vector<const void*>& columns, std::string& error)
{
  std::string bytes;
  if (!Encode(header, columns, bytes, error))
    return false;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f)
  {
    error = "cannot create '" + path + "': " + std::strerror(errno);
    return false;
  }
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  ok = (std::fclose(f) == 0) && ok;
  if (!ok)
    error = "cannot write '" + path + "'";
  return ok;
}


} // namespace pcd
} // namespace meshfree
