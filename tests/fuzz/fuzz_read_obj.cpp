// libFuzzer target: arbitrary bytes through the OBJ reader (see fuzz_read.h).
#include "fuzz_read.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return vertexflow::fuzz::read_one(data, size, vertexflow::MeshFormat::Obj);
}
