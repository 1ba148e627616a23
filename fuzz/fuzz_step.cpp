// libFuzzer entry point: the STEP reader (through import_file) on arbitrary bytes.
#include "import_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  cadclash::fuzz::import_bytes(data, size, ".step");
  return 0;
}
