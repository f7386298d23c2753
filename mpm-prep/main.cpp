// mpm-prep: entry point (filled in by the toolchain issue).
#include <cstdio>
#include "mpm/version.hpp"
int main() { std::printf("mpm-prep %s\n", mpm::kVersion); return 0; }
