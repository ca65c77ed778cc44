// libFuzzer harness for the text-cloud parser (Readers/XYZFormat): no crash, consistent tables.
#include "XYZFormat.h"

#include <cstdint>
#include <cstdlib>
#include <string>

using namespace meshfree::xyz;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const char* text = reinterpret_cast<const char*>(data);
  LooksLikeCloud(text, size);
  // The PLOT3D sniffing reads words at offsets taken from the data: no read outside it.
  if (LooksLikePlot3D(text, size) && size < 8)
    std::abort();
  LooksBinary(text, size);
  Table t;
  std::string error;
  if (!Parse(text, size, t, error))
  {
    if (error.empty() || t.Rows != 0 || !t.Values.empty())
      std::abort();
    return 0;
  }
  if (t.Values.size() != t.Rows * t.Names.size())
    std::abort();
  for (int k = 0; k < 3; ++k)
    if (t.Coordinate[k] < 0 || static_cast<std::size_t>(t.Coordinate[k]) >= t.Names.size() + (t.Rows == 0 ? 3 : 0))
      std::abort();
  return 0;
}
