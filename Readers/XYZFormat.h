// Text point clouds (.xyz, .pts) without VTK: one point per line, "x y z [more columns]", separated by
// white space, commas or semicolons. Optional first lines: Leica's point count (.pts), a header naming the
// columns ("x y z intensity", CloudCompare's "//X Y Z R G B"), comments (# or //).
#ifndef meshfree_XYZFormat_h
#define meshfree_XYZFormat_h

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace meshfree
{
namespace xyz
{

struct Table
{
  std::vector<std::string> Names; // one per column: from the header line, or "Column<k>" (1-based)
  bool NamedByHeader = false;
  std::uint64_t Rows = 0;
  std::vector<double> Values;     // Rows x Names.size(), row-major
  int Coordinate[3] = { 0, 1, 2 }; // the columns holding x, y and z
  std::int64_t DeclaredCount = -1; // Leica's first line, -1 when absent
};

/// Parses the whole text. On failure returns false, leaves the table empty and says why (with the line).
bool Parse(const char* data, std::size_t size, Table& table, std::string& error);

/// True when the start of data reads as a text point cloud (consistent rows of >= 3 numbers). Used to
/// tell point clouds from the other formats that use ".xyz" (PLOT3D grids, XMol molecules).
bool LooksLikeCloud(const char* data, std::size_t size);

} // namespace xyz
} // namespace meshfree

#endif
