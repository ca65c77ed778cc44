// Pieces shared by PCDFormat.cxx and PCDAscii.cxx (not installed, not wrapped).
#ifndef meshfree_PCDInternal_h
#define meshfree_PCDInternal_h

#include "PCDFormat.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace meshfree
{
namespace pcd
{
namespace detail
{

/// Where the values of one field go: point i's first value at Base + i * Stride (Base null: padding).
struct Target
{
  unsigned char* Base = nullptr;
  std::size_t Stride = 0;
};

/// Decodes the ascii data section (after the header) into the targets (one per field, already allocated).
bool DecodeAscii(const char* data, std::size_t size, const Header& header, const std::vector<Target>& targets,
  std::string& error);

/// Where the lines of an ascii piece are (TextPiece) and which points they hold.
struct AsciiPiece
{
  std::size_t Begin = 0, End = 0; // bytes of the file
  std::uint64_t First = 0, Count = 0;
  std::size_t Line = 1; // the number of the line at Begin
};

/// The piece's lines and points; counts the point lines of the whole data section, which must be POINTS.
bool AsciiPieceBounds(const char* data, std::size_t size, const Header& header, const PieceRequest& request,
  AsciiPiece& piece, std::string& error);

/// Decodes the piece's lines into targets (one per field) allocated for piece.Count points.
bool DecodeAsciiPiece(const char* data, const Header& header, const std::vector<Target>& targets,
  const AsciiPiece& piece, std::string& error);

/// found: whether a line outside the piece has a NaN or infinite x, y or z (parses those lines).
bool AsciiInvalidElsewhere(const char* data, std::size_t size, const Header& header, const AsciiPiece& piece,
  const MappedFile* mapping, bool& found, std::string& error);

/// Appends the ascii data section of an encoded cloud.
void EncodeAscii(const Header& header, const std::vector<const void*>& columns, std::string& out);

/// PCL's packed colour: a 4-byte float (rgb) or unsigned (rgba) field whose bits are 0xAARRGGBB.
inline bool IsPackedColor(const Field& f)
{
  return f.Size == 4 && f.Count == 1 && (f.Type == 'F' || f.Type == 'U') &&
    (f.Name == "rgb" || f.Name == "rgba");
}

/// Shared by the decoder and the encoder (PCDFormat.cxx).
std::vector<std::string> Tokens(const char* b, const char* e);
bool MulOverflows(std::uint64_t a, std::uint64_t b, std::uint64_t& product);
bool ValidateField(const Field& f, std::string& error);
/// n values of `bytes` bytes from src (every srcStride bytes) to dst (every dstStride bytes).
void StridedCopy(const unsigned char* src, std::size_t srcStride, std::uint64_t n, std::size_t bytes,
  unsigned char* dst, std::size_t dstStride);

inline bool IsSpace(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

} // namespace detail
} // namespace pcd
} // namespace meshfree

#endif
