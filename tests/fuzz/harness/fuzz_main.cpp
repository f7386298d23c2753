// One libFuzzer harness per entry point of entry_points.hpp: MPM_FUZZ_ENTRY names it
// (scene, mesh, stream, expression). Built only in the fuzz build (make fuzz, clang).
#include <cstddef>
#include <cstdint>

#include "entry_points.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)mpm::fuzz::MPM_FUZZ_ENTRY(data, size);
  return 0;
}
