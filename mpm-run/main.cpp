// mpm-run: entry point (filled in by the toolchain issue).
#include <cstdio>
#include "mpm/version.hpp"
int main() { std::printf("mpm-run %s\n", mpm::kVersion); return 0; }
