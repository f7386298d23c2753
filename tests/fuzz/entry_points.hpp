#pragma once
// The entry points that the fuzzers (harness/*.cpp, clang's libFuzzer: make fuzz) and the
// corpus replay of the default test set (test_fuzz_corpus.cpp) feed bytes to, so that both
// exercise the same code. Each returns the error a tool would print for the input ("" when
// it was accepted). Any other exception escapes: for the fuzzer it is a crash, as is every
// sanitizer report, a hang (-timeout) and an allocation past -rss_limit_mb.
#include <cstddef>
#include <cstdint>
#include <string>

namespace mpm::fuzz {

/// A scene file: TOML text with units, formulas and materials, parsed and checked as
/// mpm-prep does (parse_scene). After a line "%%set", each further line is a --set override.
std::string scene(const std::uint8_t* data, std::size_t size);

/// A mesh file, read as STL (ASCII or binary), OBJ and OFF in turn as mpm-prep reads a mesh
/// body (MeshRegion: read, repaired, checked closed and free of self-intersections), then its
/// volume, bounds and an inside test. "" when one of the formats reads it whole, else the three
/// errors, one a line.
std::string mesh(const std::uint8_t* data, std::size_t size);

/// A model or result stream, every record decoded (frames, checkpoints, escapes, grids,
/// histories, texts, ends) as mpm-post and mpm-run --restart read them. Read once as given
/// and, when the record CRCs do not match, again with them corrected, so that mutations
/// reach the decoders behind the CRC check.
std::string stream(const std::uint8_t* data, std::size_t size);

/// A formula of position (a body's velocity_field or stress_field): compiled over the field
/// variables and evaluated at a few points.
std::string expression(const std::uint8_t* data, std::size_t size);

}  // namespace mpm::fuzz
