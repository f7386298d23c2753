// The CHKP record (docs/format.md): a solver's named state values, then a frame of every
// particle column as stored. The frame part is encoded and decoded as FRAM's (stream.cpp).
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

StreamWriter::StreamWriter(const std::string& path, const std::string& source, std::uint64_t keep)
    : path_(path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const bool same = path != "-" && fs::exists(path, ec) && fs::equivalent(path, source, ec);
  if (same) {
    // Cut the damaged or superseded tail, then append.
    fs::resize_file(path, keep, ec);
    if (ec)
      throw IoError(path + ": cannot cut the stream at byte " + std::to_string(keep) + ": " +
                    ec.message());
    f_ = std::fopen(path.c_str(), "ab");
    if (!f_) throw IoError(path + ": cannot open for appending: " + std::strerror(errno));
    owns_ = true;
    offset_ = keep;
    return;
  }
  if (path == "-") {
    f_ = stdout;
  } else {
    f_ = std::fopen(path.c_str(), "wb");
    if (!f_) throw IoError(path + ": cannot open for writing: " + std::strerror(errno));
    owns_ = true;
  }
  std::FILE* in = std::fopen(source.c_str(), "rb");
  if (!in) throw IoError(source + ": cannot open for reading: " + std::strerror(errno));
  std::vector<char> buf(std::size_t(1) << 16);
  while (offset_ < keep) {
    const std::size_t want = std::size_t(std::min<std::uint64_t>(buf.size(), keep - offset_));
    const std::size_t got = std::fread(buf.data(), 1, want, in);
    if (got == 0) {
      std::fclose(in);
      throw IoError(source + ": ended at byte " + std::to_string(offset_) + " while copying " +
                    std::to_string(keep) + " bytes");
    }
    errno = 0;
    if (std::fwrite(buf.data(), 1, got, f_) != got) {
      std::fclose(in);
      fail_io(errno ? errno : EIO);
    }
    offset_ += got;
  }
  std::fclose(in);
  if (std::fflush(f_) != 0) fail_io(errno ? errno : EIO);
}

void StreamWriter::write_checkpoint(const StateValues& state, const Frame& frame) {
  std::string prefix;
  auto put = [&](const void* p, std::size_t n) { prefix.append(static_cast<const char*>(p), n); };
  const auto count = std::uint32_t(state.items().size());
  put(&count, 4);
  for (const auto& [name, value] : state.items()) {
    if (name.size() > 0xFFFF) throw std::invalid_argument("checkpoint value name too long");
    const auto len = std::uint16_t(name.size());
    put(&len, 2);
    put(name.data(), len);
    put(&value, 8);
  }
  write_columns(RecordType::Checkpoint, prefix, frame, {}, Precision::Float64);
}

Checkpoint StreamReader::read_checkpoint() {
  if (!pending_ || type_ != std::uint32_t(RecordType::Checkpoint))
    throw std::logic_error("StreamReader::read_checkpoint: the current record is not CHKP");
  Checkpoint c;
  std::uint32_t count = 0;
  read_exact(&count, 4);
  for (std::uint32_t k = 0; k < count; ++k) {
    std::uint16_t len = 0;
    read_exact(&len, 2);  // a count beyond the payload fails here, before anything grows
    std::string name(len, '\0');
    read_exact(name.data(), len);
    double value = 0;
    read_exact(&value, 8);
    if (c.state.has(name)) fail_corrupt("checkpoint value '" + name + "' appears twice");
    c.state.set(name, value);
  }
  c.frame = read_frame_body();
  return c;
}

}  // namespace mpm
