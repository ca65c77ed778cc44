// The Point Cloud Library's .pcd format, version 0.7, without VTK: header, the three encodings
// (ascii, binary, binary_compressed with LZF) in both directions. The VTK readers and writers in this
// folder are thin layers over it; the fuzz harness and the unit tests link it alone.
//
// Format facts (PCL's "The PCD (Point Cloud Data) file format", v0.7):
// - The header lists FIELDS, then per field SIZE (bytes), TYPE (I/U/F) and COUNT (values), then WIDTH,
//   HEIGHT (1 for an unorganised cloud), VIEWPOINT (tx ty tz qw qx qy qz), POINTS (= WIDTH*HEIGHT) and
//   DATA ascii|binary|binary_compressed; the data starts right after the DATA line.
// - binary: POINTS records of the fields in order (array of structures).
// - binary_compressed: uint32 compressed size, uint32 uncompressed size, then LZF bytes that expand to
//   one block per field (structure of arrays). PCL leaves the padding fields ("_") out of these blocks.
// - ascii: one point per line; PCL leaves the padding fields out, and writes the packed "rgb" float as
//   the uint32 of its bits (older versions wrote the float itself): both are accepted. PCL 1.13's ascii
//   reader takes the float only, so that is what the encoder writes wherever it cannot read as an integer.
// - binary: PCL's writers leave zero bytes after the data (PCL 1.13: up to a page); they are accepted, any
//   other trailing bytes refused.
#ifndef meshfree_PCDFormat_h
#define meshfree_PCDFormat_h

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace meshfree
{
namespace pcd
{

enum class Encoding
{
  Ascii,
  Binary,
  BinaryCompressed
};
const char* EncodingName(Encoding encoding);

struct Field
{
  std::string Name;
  int Size = 4;     // bytes per value: 1, 2, 4 or 8
  char Type = 'F';  // 'I' signed, 'U' unsigned, 'F' floating point (4 or 8 bytes)
  int Count = 1;    // values per point
  bool IsPadding() const { return this->Name == "_"; }
  std::size_t Bytes() const { return static_cast<std::size_t>(this->Size) * this->Count; }
};

struct Header
{
  std::vector<Field> Fields;
  std::uint64_t Width = 0;
  std::uint64_t Height = 1;
  std::uint64_t Points = 0;
  double Viewpoint[7] = { 0, 0, 0, 1, 0, 0, 0 };
  Encoding Data = Encoding::Ascii;
  std::size_t DataStart = 0; // byte offset of the data section in the file

  std::size_t PointBytes(bool withPadding) const;
  int FieldIndex(const std::string& name) const; // -1 when absent
};

/// Memory for a large output array, released with FreeBulk (a VTK array adopts it with
/// VTK_DATA_ARRAY_USER_DEFINED and SetArrayFreeFunction(FreeBulk)): blocks of 4 MB and more are anonymous
/// mappings backed by transparent huge pages where the kernel offers them, and prefaulted, so that filling
/// fresh memory does not pay one page fault per 4 KB. 64-byte aligned. Null when out of memory.
void* AllocateBulk(std::size_t bytes);
/// Gives back a block of AllocateBulk (null: nothing).
void FreeBulk(void* block);

/// A block of AllocateBulk, so that a VTK array can adopt it without a copy (see AllocateBulk).
class Buffer
{
public:
  bool Allocate(std::size_t bytes); // AllocateBulk; false when out of memory
  unsigned char* Data() const { return this->Ptr.get(); }
  std::size_t Bytes() const { return this->Size; }
  unsigned char* Release(); // the caller must FreeBulk() it
  void Shrink(std::size_t bytes) { this->Size = bytes; }

private:
  struct Free
  {
    void operator()(unsigned char* p) const { FreeBulk(p); }
  };
  std::unique_ptr<unsigned char, Free> Ptr;
  std::size_t Size = 0;
};

/// A decoded cloud: one column per non-padding field (Points x Count values of the field's own type,
/// interleaved), in the order of Header::Fields. When decoded with interleaveXYZ (the VTK reader's layout)
/// and the fields x, y, z are one floating type with COUNT 1, they go straight into Points as x y z triples
/// (PointsSize 4: float, 8: double), the layout of vtkPoints, and have no column; likewise PCL's normal_x,
/// normal_y, normal_z go into Normals as triples (NormalsSize 4 or 8).
struct Cloud
{
  Header Head; // Points: the points decoded (a piece's share, see DecodePiece); Width, Height: the file's
  std::vector<int> ColumnField; // index into Head.Fields of each column
  std::vector<Buffer> Columns;
  Buffer Points;
  int PointsSize = 0; // 0: no interleaved points
  Buffer Normals;
  int NormalsSize = 0; // 0: no interleaved normals
  std::uint64_t First = 0;       // index in the file of the first decoded point (0 unless a piece)
  std::uint64_t FilePoints = 0;  // POINTS of the file
  bool InvalidElsewhere = false; // a piece with PieceRequest::FindInvalid: a point outside it has a NaN x, y or z
};

/// Parses the header at the start of data. On failure returns false and a message naming the problem.
bool ParseHeader(const char* data, std::size_t size, Header& header, std::string& error);

/// Decodes a whole file held in memory. On failure the cloud is left empty and error says why.
bool Decode(const char* data, std::size_t size, Cloud& cloud, std::string& error, bool interleaveXYZ = false);

/// Reads and decodes a file (one bulk read).
bool ReadFile(const std::string& path, Cloud& cloud, std::string& error, bool interleaveXYZ = false);

class MappedFile;

/// Piece Piece of Pieces of a file, as the VTK pipeline asks for it under MPI.
struct PieceRequest
{
  int Piece = 0;
  int Pieces = 1;
  /// For an organised cloud (HEIGHT > 1), also find out whether a point outside the piece has a NaN (or infinite)
  /// x, y or z (Cloud::InvalidElsewhere): what its PixelIndex depends on. Costs a pass over the rest of the file
  /// (ascii: parsing its lines, so that their errors are found by every piece too).
  bool FindInvalid = false;
  /// The mapping that holds the data, if any: the pages outside the piece that a pass over the whole file
  /// touched are given back (the rank keeps only its share's pages).
  const MappedFile* Mapping = nullptr;
};

/// Decodes the share of the points that piece p of N gets, in file order (concatenating the pieces in order gives
/// exactly Decode's cloud): cloud.First is its first point's index in the file, cloud.Head.Points its count.
/// - binary: points [floor(p n / N), floor((p+1) n / N)); only their records are touched.
/// - binary_compressed: the same share, but the LZF blob (all fields, column-major) cannot be split: it is
///   decompressed whole, the share copied out and the rest freed.
/// - ascii: the data section is cut into N byte ranges of equal size; a line belongs to the piece whose range holds
///   its first byte. The shares are contiguous but not of floor(p n / N) points. Every piece counts the lines of the
///   whole section (memchr; nothing kept) so that a POINTS that does not match fails on every piece; a value that
///   does not parse fails on the piece that holds its line only.
/// Errors in the header, the sizes or the counts are found by every piece alike. Pieces = 1 is Decode.
bool DecodePiece(const char* data, std::size_t size, const PieceRequest& request, Cloud& cloud, std::string& error,
  bool interleaveXYZ = false);

/// Maps a file (lazily: only the pages a piece touches are read) and decodes a piece of it (DecodePiece).
bool ReadPiece(const std::string& path, PieceRequest request, Cloud& cloud, std::string& error,
  bool interleaveXYZ = false);

/// Piece `piece` of `pieces` of the lines of a text section [begin, end) of data: the section cut into byte ranges of
/// equal size, each line going to the range that holds its first byte. [pieceBegin, pieceEnd) start at line starts;
/// the pieces in order tile the section.
void TextPiece(const char* data, std::size_t begin, std::size_t end, int piece, int pieces, std::size_t& pieceBegin,
  std::size_t& pieceEnd);

/// Removes the points whose x, y or z is NaN or infinite (PCL's marker of invalid points), from every
/// column (and from Points and Normals). keptIndex (optional) receives the original index of each kept point, or
/// nothing when no point was dropped. Returns how many went.
std::uint64_t DropInvalidPoints(Cloud& cloud, std::vector<std::uint64_t>* keptIndex = nullptr);

/// Encodes a cloud: header.Fields (no padding), Width/Height/Points, Viewpoint, Data are used;
/// columns[i] holds Points x Count values of field i, interleaved. The result is appended to out.
bool Encode(const Header& header, const std::vector<const void*>& columns, std::string& out,
  std::string& error);

/// Encode + write to path.
bool WriteFile(const std::string& path, const Header& header,
  const std::vector<const void*>& columns, std::string& error);

/// A read-only memory map of a whole file (pre-faulted unless asked not to: the kernel maps the page cache in one
/// call, no copy).
class MappedFile
{
public:
  MappedFile() = default;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile();
  /// populate false: map only, the pages are read when touched (a piece of the file).
  bool Open(const std::string& path, std::string& error, bool populate = true);
  const char* Data() const { return this->Ptr; }
  std::size_t Size() const { return this->Length; }
  /// Gives back the pages wholly inside [begin, end) (read again from the file if touched later).
  void Release(std::size_t begin, std::size_t end) const;

private:
  const char* Ptr = "";
  std::size_t Length = 0;
  bool Mapped = false;
};

/// Calls scan(window_begin, window_end) over [b, e) of data in windows of about 32 MiB cut at line ends, giving back
/// each window's pages afterwards when a mapping holds the data: a pass over a whole text file keeps none of it.
template <class Scan>
void ScanTextReleasing(const char* data, std::size_t b, std::size_t e, const MappedFile* mapping, Scan scan)
{
  constexpr std::size_t Window = std::size_t(32) << 20;
  while (b < e)
  {
    std::size_t w = e - b > Window ? b + Window : e;
    if (w < e)
    {
      const char* nl = static_cast<const char*>(std::memchr(data + w, '\n', e - w));
      w = nl ? static_cast<std::size_t>(nl - data) + 1 : e;
    }
    scan(data + b, data + w);
    if (mapping)
    {
      mapping->Release(b, w);
    }
    b = w;
  }
}

/// Whole file into memory with one read; false with a message on failure.
bool LoadFile(const std::string& path, Buffer& bytes, std::string& error);

} // namespace pcd
} // namespace meshfree

#endif
