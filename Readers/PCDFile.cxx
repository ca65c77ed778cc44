// .pcd files in memory: buffers VTK arrays can adopt, the whole-file map/read, and dropping invalid points.
#include "PCDFormat.h"
#include "PCDInternal.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace meshfree
{
namespace pcd
{

namespace
{
// Every bulk block starts Header bytes after its allocation, which records how to give it back.
struct BulkHeader
{
  std::size_t Mapped; // bytes of the anonymous mapping, 0 when malloc'ed
  std::size_t Padding[7];
};
constexpr std::size_t HeaderBytes = sizeof(BulkHeader);
static_assert(HeaderBytes == 64, "bulk blocks are 64-byte aligned");
} // namespace

void* AllocateBulk(std::size_t bytes)
{
  // Fresh memory costs one page fault per 4 KB page on first touch; in a virtual machine each fault also
  // exits to the host, and for a cold read of a binary file those faults, not the copying, were the main
  // cost (measured: 128 MB touched through 4 KB faults took 3-4 s, through 2 MB pages about 0.1 s).
  // Large blocks are therefore their own anonymous mappings (the kernel aligns those to 2 MB), offered to
  // transparent huge pages and prefaulted in one call. malloc would place them, after the first free, on
  // its heap in 4 KB pages, that a trim returns and the next read faults in again one by one. Both calls
  // are advice: on a kernel without them the pages fault in as usual.
  constexpr std::size_t Large = std::size_t(4) << 20;
  if (bytes > std::numeric_limits<std::size_t>::max() - (std::size_t(4) << 20))
    return nullptr;
  const std::size_t total = bytes + HeaderBytes;
  BulkHeader* h = nullptr;
  if (bytes < Large)
  {
    h = static_cast<BulkHeader*>(std::aligned_alloc(HeaderBytes, (total + HeaderBytes - 1) / HeaderBytes * HeaderBytes));
    if (!h)
      return nullptr;
    h->Mapped = 0;
#ifdef MADV_POPULATE_WRITE
    constexpr std::size_t Page = 4096;
    const auto begin = (reinterpret_cast<std::uintptr_t>(h) + Page - 1) & ~(Page - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(h) + total) & ~(Page - 1);
    if (bytes >= 16 * Page && end > begin)
      madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);
#endif
    return reinterpret_cast<unsigned char*>(h) + HeaderBytes;
  }
  void* p = mmap(nullptr, total, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED)
    return nullptr;
#ifdef MADV_HUGEPAGE
  madvise(p, total, MADV_HUGEPAGE);
#endif
#ifdef MADV_POPULATE_WRITE
  madvise(p, total, MADV_POPULATE_WRITE);
#endif
  h = static_cast<BulkHeader*>(p);
  h->Mapped = total;
  return static_cast<unsigned char*>(p) + HeaderBytes;
}

void FreeBulk(void* block)
{
  if (!block)
    return;
  auto* h = reinterpret_cast<BulkHeader*>(static_cast<unsigned char*>(block) - HeaderBytes);
  if (h->Mapped)
    munmap(h, h->Mapped);
  else
    std::free(h);
}

bool Buffer::Allocate(std::size_t bytes)
{
  this->Ptr.reset(static_cast<unsigned char*>(AllocateBulk(bytes)));
  this->Size = this->Ptr ? bytes : 0;
  return this->Ptr != nullptr;
}

unsigned char* Buffer::Release()
{
  this->Size = 0;
  return this->Ptr.release();
}

bool LoadFile(const std::string& path, Buffer& bytes, std::string& error)
{
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f)
  {
    error = "cannot open '" + path + "': " + std::strerror(errno);
    return false;
  }
  bool ok = std::fseek(f, 0, SEEK_END) == 0;
  long length = ok ? std::ftell(f) : -1;
  ok = ok && length >= 0 && std::fseek(f, 0, SEEK_SET) == 0;
  if (ok && !bytes.Allocate(static_cast<std::size_t>(length)))
  {
    std::fclose(f);
    error = "out of memory reading '" + path + "'";
    return false;
  }
  ok = ok && std::fread(bytes.Data(), 1, bytes.Bytes(), f) == bytes.Bytes();
  std::fclose(f);
  if (!ok)
    error = "cannot read '" + path + "'";
  return ok;
}

MappedFile::~MappedFile()
{
  if (this->Mapped)
    munmap(const_cast<char*>(this->Ptr), this->Length);
}

bool MappedFile::Open(const std::string& path, std::string& error, bool populate)
{
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0)
  {
    error = "cannot open '" + path + "': " + std::strerror(errno);
    return false;
  }
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
  {
    ::close(fd);
    error = "'" + path + "' is not a regular file";
    return false;
  }
  this->Length = static_cast<std::size_t>(st.st_size);
  if (this->Length > 0)
  {
    void* p = mmap(nullptr, this->Length, PROT_READ, MAP_PRIVATE | (populate ? MAP_POPULATE : 0), fd, 0);
    if (p == MAP_FAILED)
    {
      ::close(fd);
      this->Length = 0;
      error = "cannot map '" + path + "': " + std::strerror(errno);
      return false;
    }
    this->Ptr = static_cast<const char*>(p);
    this->Mapped = true;
#ifdef MADV_POPULATE_READ
    if (populate)
      madvise(p, this->Length, MADV_POPULATE_READ); // page tables in one call, not one fault per page
#endif
  }
  ::close(fd);
  return true;
}

void MappedFile::Release(std::size_t begin, std::size_t end) const
{
  const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  const auto base = reinterpret_cast<std::uintptr_t>(this->Ptr);
  end = std::min(end, this->Length);
  // The mapping starts at a page; only whole pages inside the range go.
  const std::size_t b = (begin + page - 1) / page * page, e = end / page * page;
  if (this->Mapped && e > b)
    madvise(reinterpret_cast<void*>(base + b), e - b, MADV_DONTNEED);
}

std::uint64_t DropInvalidPoints(Cloud& cloud, std::vector<std::uint64_t>* keptIndex)
{
  const std::uint64_t n = cloud.Head.Points;
  // The coordinates: (data, size in bytes, stride in bytes) of x, y, z where they are floating point.
  struct Coordinate
  {
    const unsigned char* Data;
    int Size;
    std::size_t Stride;
  };
  std::vector<Coordinate> coords;
  if (cloud.PointsSize)
    for (int k = 0; k < 3; ++k)
      coords.push_back({ cloud.Points.Data() + k * cloud.PointsSize, cloud.PointsSize,
        3 * static_cast<std::size_t>(cloud.PointsSize) });
  for (std::size_t c = 0; c < cloud.Columns.size(); ++c)
  {
    const Field& f = cloud.Head.Fields[cloud.ColumnField[c]];
    if ((f.Name == "x" || f.Name == "y" || f.Name == "z") && f.Type == 'F' && f.Count == 1)
      coords.push_back({ cloud.Columns[c].Data(), f.Size, static_cast<std::size_t>(f.Size) });
  }
  auto valid = [&](std::uint64_t i) {
    for (const Coordinate& c : coords)
    {
      double v;
      if (c.Size == 4)
      {
        float x;
        std::memcpy(&x, c.Data + c.Stride * i, 4);
        v = x;
      }
      else
        std::memcpy(&v, c.Data + c.Stride * i, 8);
      if (!std::isfinite(v))
        return false;
    }
    return true;
  };
  std::vector<std::uint64_t> kept;
  std::uint64_t firstBad = n;
  bool search = true;
  if (cloud.PointsSize)
  {
    // The usual case, interleaved x y z of one floating type: one branch-free pass over the exponent bits
    // (all ones: NaN or infinite) that the compiler vectorises; the point-by-point search below runs only
    // when it finds something.
    bool any = false;
    if (cloud.PointsSize == 4)
    {
      const unsigned char* p = cloud.Points.Data();
      for (std::uint64_t i = 0; i < 3 * n; ++i)
      {
        std::uint32_t bits;
        std::memcpy(&bits, p + 4 * i, 4);
        any |= (bits & 0x7f800000u) == 0x7f800000u;
      }
    }
    else
    {
      const unsigned char* p = cloud.Points.Data();
      for (std::uint64_t i = 0; i < 3 * n; ++i)
      {
        std::uint64_t bits;
        std::memcpy(&bits, p + 8 * i, 8);
        any |= (bits & 0x7ff0000000000000ull) == 0x7ff0000000000000ull;
      }
    }
    search = any;
  }
  if (search)
  {
    for (std::uint64_t i = 0; i < n && firstBad == n; ++i)
      if (!valid(i))
        firstBad = i;
  }
  if (firstBad < n)
  {
    kept.reserve(n);
    for (std::uint64_t i = 0; i < n; ++i)
      if (i < firstBad || (i > firstBad && valid(i)))
        kept.push_back(i);
    auto compact = [&](Buffer& buffer, std::size_t b) {
      unsigned char* d = buffer.Data();
      for (std::size_t k = firstBad; k < kept.size(); ++k)
        std::memmove(d + k * b, d + kept[k] * b, b);
      buffer.Shrink(kept.size() * b);
    };
    for (std::size_t c = 0; c < cloud.Columns.size(); ++c)
      compact(cloud.Columns[c], cloud.Head.Fields[cloud.ColumnField[c]].Bytes());
    if (cloud.PointsSize)
      compact(cloud.Points, 3 * static_cast<std::size_t>(cloud.PointsSize));
    if (cloud.NormalsSize)
      compact(cloud.Normals, 3 * static_cast<std::size_t>(cloud.NormalsSize));
    cloud.Head.Points = kept.size();
  }
  const std::uint64_t dropped = firstBad < n ? n - kept.size() : 0;
  if (keptIndex)
  {
    if (firstBad == n)
      kept.clear();
    keptIndex->swap(kept);
  }
  return dropped;
}

} // namespace pcd
} // namespace meshfree
