// libFuzzer harness for the .pcd parser (Readers/PCDFormat). Besides "no crash, no sanitizer report", it
// checks a property: whatever decodes must re-encode (each encoding) and decode back to the same bytes.
// Build and run by hand (see README.md beside this file); ctest replays the corpus with ReplayCorpus.cxx.
#include "PCDFormat.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace meshfree::pcd;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  Cloud cloud;
  std::string error;
  {
    // The reader's path: x, y, z decoded straight into interleaved points.
    Cloud inter;
    std::string e;
    if (Decode(reinterpret_cast<const char*>(data), size, inter, e, true))
      DropInvalidPoints(inter);
  }
  if (!Decode(reinterpret_cast<const char*>(data), size, cloud, error))
  {
    if (error.empty() || !cloud.Columns.empty())
      std::abort(); // a refusal must say why and leave nothing behind
    return 0;
  }
  // Keep the re-encoding cheap for the fuzzer: skip huge clouds.
  if (cloud.Head.Points * cloud.Head.PointBytes(false) > (1u << 20))
    return 0;
  Header h = cloud.Head;
  h.Fields.clear();
  std::vector<const void*> columns;
  for (std::size_t c = 0; c < cloud.Columns.size(); ++c)
  {
    h.Fields.push_back(cloud.Head.Fields[cloud.ColumnField[c]]);
    columns.push_back(cloud.Columns[c].Data());
  }
  if (h.Fields.empty())
    return 0;
  for (Encoding e : { Encoding::Ascii, Encoding::Binary, Encoding::BinaryCompressed })
  {
    h.Data = e;
    std::string bytes;
    Cloud back;
    if (!Encode(h, columns, bytes, error) || !Decode(bytes.data(), bytes.size(), back, error))
      std::abort();
    for (std::size_t c = 0; c < cloud.Columns.size(); ++c)
    {
      const Field& f = h.Fields[c];
      const auto* a = cloud.Columns[c].Data();
      const auto* b = back.Columns[c].Data();
      // NaN payloads may change through text; compare everything else bit for bit.
      for (std::uint64_t v = 0; v < cloud.Head.Points * f.Count; ++v)
      {
        const std::size_t o = v * f.Size;
        if (std::memcmp(a + o, b + o, f.Size) == 0)
          continue;
        bool bothNaN = false;
        if (f.Type == 'F' && f.Size == 4)
        {
          float x, y;
          std::memcpy(&x, a + o, 4), std::memcpy(&y, b + o, 4);
          bothNaN = x != x && y != y;
        }
        else if (f.Type == 'F')
        {
          double x, y;
          std::memcpy(&x, a + o, 8), std::memcpy(&y, b + o, 8);
          bothNaN = x != x && y != y;
        }
        if (!bothNaN)
          std::abort();
      }
    }
  }
  DropInvalidPoints(cloud);
  return 0;
}
