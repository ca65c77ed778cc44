// Replays every file of the given folders through a libFuzzer harness (LLVMFuzzerTestOneInput), so that
// ctest checks the committed corpus without libFuzzer. Exit 0 when every input ran (harnesses abort on
// a violated property).
#include <cstdint>
#include <cstdio>
#include <dirent.h>
#include <string>
#include <sys/stat.h>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char* argv[])
{
  int files = 0;
  for (int a = 1; a < argc; ++a)
  {
    DIR* dir = opendir(argv[a]);
    if (!dir)
    {
      std::fprintf(stderr, "cannot open corpus folder %s\n", argv[a]);
      return 1;
    }
    while (dirent* e = readdir(dir))
    {
      const std::string path = std::string(argv[a]) + "/" + e->d_name;
      struct stat st;
      if (stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
        continue;
      std::FILE* f = std::fopen(path.c_str(), "rb");
      if (!f)
        continue;
      std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
      const std::size_t got = std::fread(bytes.data(), 1, bytes.size(), f);
      std::fclose(f);
      LLVMFuzzerTestOneInput(bytes.data(), got);
      ++files;
    }
    closedir(dir);
  }
  std::printf("replayed %d inputs\n", files);
  return files > 0 ? 0 : 1;
}
