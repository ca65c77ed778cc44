// Text point clouds (.xyz, .pts) without VTK: one point per line, "x y z [more columns]", separated by
// white space, commas or semicolons. Optional first lines: Leica's point count (.pts), a header naming the
// columns ("x y z intensity", CloudCompare's "//X Y Z R G B"), comments (# or //).
#ifndef meshfree_XYZFormat_h
#define meshfree_XYZFormat_h

#include "PCDFormat.h" // AllocateBulk

#include <cstddef>
#include <cstdint>
#include <functional>
#include <new>
#include <string>
#include <utility>
#include <vector>

namespace meshfree
{
namespace xyz
{

/// A std::vector allocator over pcd::AllocateBulk that leaves new elements uninitialised: the parser
/// writes every value, so resize() neither zero-fills nor takes a page fault per 4 KB.
template <class T>
struct BulkAllocator
{
  using value_type = T;
  BulkAllocator() = default;
  template <class U>
  BulkAllocator(const BulkAllocator<U>&)
  {
  }
  T* allocate(std::size_t n)
  {
    void* p = pcd::AllocateBulk(n * sizeof(T));
    if (!p)
      throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) { pcd::FreeBulk(p); }
  template <class U, class... A>
  void construct(U* p, A&&... args)
  {
    if constexpr (sizeof...(A) == 0)
      ::new (static_cast<void*>(p)) U;
    else
      ::new (static_cast<void*>(p)) U(std::forward<A>(args)...);
  }
  bool operator==(const BulkAllocator&) const { return true; }
  bool operator!=(const BulkAllocator&) const { return false; }
};

struct Table
{
  std::vector<std::string> Names; // one per column: from the header line, or "Column<k>" (1-based)
  bool NamedByHeader = false;
  std::uint64_t Rows = 0;
  std::vector<double, BulkAllocator<double>> Values; // Rows x Names.size(), row-major
  int Coordinate[3] = { 0, 1, 2 }; // the columns holding x, y and z
  std::int64_t DeclaredCount = -1; // Leica's first line, -1 when absent
  /// A piece (ParsePiece): the data section starts at DataBegin (the first row's line) and runs to the end of the
  /// file; the piece's Rows are the rows of the lines in [PieceBegin, PieceEnd). The whole file: IsPiece false.
  std::size_t DataBegin = 0, PieceBegin = 0, PieceEnd = 0;
  bool IsPiece = false;
};

/// Parses the whole text. On failure returns false, leaves the table empty and says why (with the line).
/// The header lines are read one by one; the data rows are counted, allocated once and parsed in place,
/// in pieces on several threads for large files.
bool Parse(const char* data, std::size_t size, Table& table, std::string& error);

/// Parses the lines before the data (header, count, comments) and then only the rows of piece
/// request.Piece of request.Pieces: the data section cut into byte ranges of equal size (pcd::TextPiece), each
/// line going to the piece whose range holds its first byte. Concatenating the pieces' rows in order gives Parse's
/// rows; the shares are contiguous but not of equal row counts. A Leica count line makes every piece count the
/// rows of the whole section (memchr, nothing kept), so that a count that does not match fails on every piece; a
/// row that does not parse fails on the piece that holds it only. Pieces = 1 is Parse.
bool ParsePiece(const char* data, std::size_t size, const pcd::PieceRequest& request, Table& table, std::string& error);

/// Calls visit(row) with each row (all columns) of the data section outside the piece that table holds, in file order,
/// until visit returns false. For what depends on every row (the reader's colour columns). False, with the line
/// and what is wrong, on a row that does not parse. mapping: the pages it read are given back.
bool ForEachRowElsewhere(const char* data, std::size_t size, const Table& table, const pcd::MappedFile* mapping,
  const std::function<bool(const double*)>& visit, std::string& error);

/// True when the start of data reads as a text point cloud (consistent rows of >= 3 numbers). Used to
/// tell point clouds from the other formats that use ".xyz" (PLOT3D grids, XMol molecules).
bool LooksLikeCloud(const char* data, std::size_t size);

/// True when the start of data has NUL or other control bytes (not a text file).
bool LooksBinary(const char* data, std::size_t size);

/// True when the start of a binary file could be a PLOT3D grid (ParaView's other ".xyz" reader): in one byte
/// order, a Fortran record (a length marker repeated after the record), or two positive counts (grids,
/// dimensions) first. Binary files failing this are no grid: the text-cloud reader claims them and refuses
/// them with an error, rather than leaving them to the PLOT3D reader, which aborts the process on garbage.
bool LooksLikePlot3D(const char* data, std::size_t size);

} // namespace xyz
} // namespace meshfree

#endif
