// libFuzzer entry point: the IGES reader (through import_file) on arbitrary bytes.
#include "import_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  cadclash::fuzz::import_bytes(data, size, ".igs");
  return 0;
}
