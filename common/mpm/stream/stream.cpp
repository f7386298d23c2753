#include "mpm/stream/stream.hpp"

#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <limits>
#include <new>
#include <stdexcept>

#include "mpm/core/error.hpp"

#ifdef _WIN32
#include <fcntl.h>
#include <io.h>
#endif

namespace mpm {

static_assert(std::endian::native == std::endian::little,
              "the stream format is little-endian and is read and written by memcpy");
static_assert(std::numeric_limits<double>::is_iec559 && std::numeric_limits<float>::is_iec559,
              "f64 and f32 must be IEEE 754");

namespace {

constexpr unsigned char kMagic[8] = {0x89, 'M', 'P', 'M', '\r', '\n', 0x1a, '\n'};
constexpr std::size_t kHeaderBytes = 16;
constexpr std::size_t kRecordHeaderBytes = 12;
constexpr std::uint64_t kMaxPayload = std::uint64_t(1) << 44;
constexpr std::size_t kChunk = std::size_t(1)
                               << 16;  ///< bytes per chunk when skipping or converting
constexpr std::size_t kFrameFixedBytes = 8 + 8 + 4 + 8 + 4;

std::uint32_t crc_update(std::uint32_t crc, const void* data, std::size_t n) {
  if (n == 0) return crc;  // zlib returns 0 for a null buffer, even with a running CRC
  return static_cast<std::uint32_t>(crc32_z(crc, static_cast<const Bytef*>(data), n));
}
std::uint32_t crc_init() {
  return static_cast<std::uint32_t>(crc32_z(0, Z_NULL, 0));
}

/// Little-endian serialisation into a small byte buffer (the machine is little-endian).
struct Bytes {
  std::string b;
  template <class T>
  void put(T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    b.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_str16(const std::string& s, const char* what) {
    if (s.size() > 0xFFFF)
      throw std::invalid_argument(std::string(what) + " longer than 65535 bytes: '" +
                                  s.substr(0, 40) + "...'");
    put(static_cast<std::uint16_t>(s.size()));
    b += s;
  }
};

/// Reads little-endian values from a payload held in memory; malformed payloads throw.
struct Cursor {
  const std::vector<std::byte>& p;
  const char* what;
  std::size_t at = 0;
  void need(std::size_t n) const {
    if (p.size() - at < n)
      throw StreamError("", std::string("malformed ") + what + " payload: it ends at byte " +
                                std::to_string(p.size()) + " where " + std::to_string(n) +
                                " more bytes are due");
  }
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, p.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::string get_str16() {
    const auto n = get<std::uint16_t>();
    need(n);
    std::string s(reinterpret_cast<const char*>(p.data() + at), n);
    at += n;
    return s;
  }
};

/// f64 -> f32, rounding to nearest; out of range gives +-inf (a plain cast would be undefined).
inline float narrow(double v) {
  constexpr double m = std::numeric_limits<float>::max();
  if (v > m) return std::numeric_limits<float>::infinity();
  if (v < -m) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(v);  // NaN stays NaN
}

bool valid_scalar_type(std::uint8_t code) {
  return code >= 1 && code <= 6;
}

bool fourcc_char(std::uint8_t c) {
  return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}
bool plausible_type(std::uint32_t type) {
  for (int i = 0; i < 4; ++i)
    if (!fourcc_char(std::uint8_t(type >> (8 * i)))) return false;
  return true;
}
bool known_type(std::uint32_t type) {
  switch (static_cast<RecordType>(type)) {
    case RecordType::Scene:
    case RecordType::Info:
    case RecordType::Frame:
    case RecordType::History:
    case RecordType::Grid:
    case RecordType::Escape:
    case RecordType::Rebar:
    case RecordType::Checkpoint:
    case RecordType::End:
      return true;
  }
  return false;
}

/// True when the first bytes of an input look like text (a TOML scene) rather than binary.
bool looks_like_toml(const unsigned char* b, std::size_t n) {
  if (n == 0) return false;
  std::size_t i = 0;
  if (n >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF) i = 3;  // UTF-8 BOM
  for (std::size_t k = i; k < n; ++k) {
    const unsigned char c = b[k];
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') return false;
    if (c == 0x7F) return false;
  }
  while (i < n && (b[i] == ' ' || b[i] == '\t' || b[i] == '\r' || b[i] == '\n')) ++i;
  if (i == n) return true;  // blank text
  const unsigned char c = b[i];
  return c == '#' || c == '[' || c == '"' || c == '\'' || c == '_' || c == '-' ||
         (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
}

std::string display_name(const std::string& path, bool output) {
  return path == "-" ? (output ? "<stdout>" : "<stdin>") : path;
}

/// Selected columns of a frame and the type each is written with.
struct OutColumn {
  const Column* column;
  ScalarType type;
};

}  // namespace

std::string record_name(std::uint32_t type) {
  if (known_type(type) || plausible_type(type)) {
    std::string s(4, ' ');
    for (int i = 0; i < 4; ++i) s[i] = char(type >> (8 * i));
    return known_type(type) ? s : "?" + s;
  }
  char hex[16];
  std::snprintf(hex, sizeof hex, "?0x%08x", type);
  return hex;
}

// ---------------------------------------------------------------------------------------------
// Writer

StreamWriter::StreamWriter(const std::string& path, std::uint16_t minor) : path_(path) {
  if (path == "-") {
    f_ = stdout;
#ifdef _WIN32
    _setmode(_fileno(stdout), _O_BINARY);
#endif
  } else {
    f_ = std::fopen(path.c_str(), "wb");
    if (!f_) throw IoError(path + ": cannot open for writing: " + std::strerror(errno));
    owns_ = true;
  }
  Bytes h;
  h.b.append(reinterpret_cast<const char*>(kMagic), sizeof kMagic);
  h.put(kStreamVersionMajor);
  h.put(minor);
  h.put(std::uint32_t(0));
  errno = 0;
  if (std::fwrite(h.b.data(), 1, h.b.size(), f_) != h.b.size()) fail_io(errno ? errno : EIO);
  offset_ += h.b.size();
  if (std::fflush(f_) != 0) fail_io(errno ? errno : EIO);
}

StreamWriter::~StreamWriter() {
  if (!f_) return;
  if (owns_)
    std::fclose(f_);
  else
    std::fflush(f_);
}

void StreamWriter::close() {
  if (!f_) return;
  std::FILE* f = f_;
  f_ = nullptr;
  errno = 0;
  const int rc = owns_ ? std::fclose(f) : std::fflush(f);
  if (rc != 0) fail_io(errno ? errno : EIO);
}

void StreamWriter::fail_io(int err) {
  const std::string name = display_name(path_, true);
  if (err == 0)
    throw IoError(name + (broken_ ? ": an earlier write failed; nothing more is written"
                                  : ": the stream is closed"));
  broken_ = true;
  throw IoError(name + ": write failed: " + std::strerror(err));
}

void StreamWriter::put(const void* data, std::size_t n) {
  if (n == 0) return;
  if (n > remaining_) throw std::logic_error("stream writer: record payload longer than announced");
  errno = 0;
  if (std::fwrite(data, 1, n, f_) != n) fail_io(errno ? errno : EIO);
  crc_ = crc_update(crc_, data, n);
  offset_ += n;
  remaining_ -= n;
}

void StreamWriter::begin_record(RecordType type, std::uint64_t length) {
  if (!f_ || broken_) fail_io(0);
  if (length > kMaxPayload)
    throw std::invalid_argument("stream writer: record of " + std::to_string(length) +
                                " bytes exceeds the format's limit of 2^44");
  crc_ = crc_init();
  Bytes h;
  h.put(static_cast<std::uint32_t>(type));
  h.put(length);
  remaining_ = h.b.size();
  put(h.b.data(), h.b.size());
  remaining_ = length;
}

void StreamWriter::end_record() {
  if (remaining_ != 0)
    throw std::logic_error("stream writer: record payload shorter than announced");
  const std::uint32_t crc = crc_;
  errno = 0;
  if (std::fwrite(&crc, 1, sizeof crc, f_) != sizeof crc) fail_io(errno ? errno : EIO);
  offset_ += sizeof crc;
  if (std::fflush(f_) != 0) fail_io(errno ? errno : EIO);
}

void StreamWriter::write_text(RecordType type, const std::string& text) {
  if (type != RecordType::Scene && type != RecordType::Info)
    throw std::invalid_argument("write_text: " + record_name(std::uint32_t(type)) +
                                " is not a text record");
  begin_record(type, text.size());
  put(text.data(), text.size());
  end_record();
}

void StreamWriter::write_record(RecordType type, const std::vector<std::byte>& payload) {
  if (type != RecordType::Grid)
    throw std::invalid_argument("write_record: " + record_name(std::uint32_t(type)) +
                                " has its own writer");
  begin_record(type, payload.size());
  put(payload.data(), payload.size());
  end_record();
}

void StreamWriter::write_frame(const Frame& frame, const std::vector<std::string>& fields,
                               Precision precision) {
  write_columns(RecordType::Frame, {}, frame, fields, precision);
}

void StreamWriter::write_escapes(const Frame& escaped) {
  write_columns(RecordType::Escape, {}, escaped, {}, Precision::Float64);
}

void StreamWriter::write_rebar(const Frame& elements) {
  write_columns(RecordType::Rebar, {}, elements, {}, Precision::Float64);
}

void StreamWriter::write_columns(RecordType type, const std::string& prefix, const Frame& frame,
                                 const std::vector<std::string>& fields, Precision precision) {
  const ColumnStore& store = frame.columns;
  const std::size_t n = store.size();
  std::vector<OutColumn> out;
  auto choose = [&](const Column& c) {
    ScalarType t = c.info().type;
    if (precision == Precision::Float32 && t == ScalarType::F64 && c.info().name != "x")
      t = ScalarType::F32;
    out.push_back({&c, t});
  };
  if (fields.empty()) {
    for (const Column& c : store.columns()) choose(c);
  } else {
    for (const std::string& name : fields) {
      const Column* c = store.find(name);
      if (!c) {
        std::string avail;
        for (const Column& k : store.columns())
          avail += (avail.empty() ? "" : ", ") + k.info().name;
        throw InputError("output.fields",
                         "unknown field '" + name + "' (available: " + avail + ")");
      }
      for (const OutColumn& o : out)
        if (o.column == c)
          throw InputError("output.fields", "field '" + name + "' is listed twice");
      choose(*c);
    }
  }
  if (out.size() > 0xFFFFFFFFu) throw std::invalid_argument("write_frame: too many columns");

  Bytes head;
  head.put(std::int64_t(frame.step));
  head.put(double(frame.time));
  head.put(std::uint32_t(frame.flags));
  head.put(std::uint64_t(n));
  head.put(std::uint32_t(out.size()));
  std::uint64_t data_bytes = 0;
  for (const OutColumn& o : out) {
    const ColumnInfo& info = o.column->info();
    if (info.components < 1 || info.components > 255)
      throw std::invalid_argument("write_frame: column '" + info.name + "' has " +
                                  std::to_string(info.components) + " components (1..255)");
    head.put_str16(info.name, "column name");
    head.put(static_cast<std::uint8_t>(o.type));
    head.put(static_cast<std::uint8_t>(info.components));
    head.put_str16(info.unit, "column unit");
    data_bytes += std::uint64_t(n) * info.components * scalar_size(o.type);
  }

  begin_record(type, prefix.size() + head.b.size() + data_bytes);
  put(prefix.data(), prefix.size());
  put(head.b.data(), head.b.size());
  std::vector<float> buf;
  for (const OutColumn& o : out) {
    const Column& c = *o.column;
    if (o.type == c.info().type) {
      put(c.data(), c.bytes());  // straight from the column
      continue;
    }
    // f64 -> f32, chunk by chunk.
    const double* src = reinterpret_cast<const double*>(c.data());
    const std::size_t count = n * std::size_t(c.info().components);
    buf.resize(std::min(count, kChunk / sizeof(float)));
    for (std::size_t i = 0; i < count; i += buf.size()) {
      const std::size_t m = std::min(buf.size(), count - i);
      for (std::size_t k = 0; k < m; ++k) buf[k] = narrow(src[i + k]);
      put(buf.data(), m * sizeof(float));
    }
  }
  end_record();
}

void StreamWriter::write_history(const HistoryBlock& block) {
  const std::size_t cols = block.names.size();
  if (block.units.size() != cols)
    throw std::invalid_argument("write_history: " + std::to_string(cols) + " names but " +
                                std::to_string(block.units.size()) + " units");
  if (cols == 0 ? !block.values.empty() : block.values.size() % cols != 0)
    throw std::invalid_argument("write_history: " + std::to_string(block.values.size()) +
                                " values do not fill rows of " + std::to_string(cols));
  Bytes head;
  head.put(std::uint32_t(cols));
  for (std::size_t i = 0; i < cols; ++i) {
    head.put_str16(block.names[i], "history column name");
    head.put_str16(block.units[i], "history column unit");
  }
  head.put(std::uint64_t(block.rows()));
  const std::uint64_t data = block.values.size() * sizeof(double);
  begin_record(RecordType::History, head.b.size() + data);
  put(head.b.data(), head.b.size());
  put(block.values.data(), data);
  end_record();
}

void StreamWriter::write_end(int status, const std::string& message) {
  Bytes p;
  p.put(std::int32_t(status));
  p.b += message;
  begin_record(RecordType::End, p.b.size());
  put(p.b.data(), p.b.size());
  end_record();
}

// ---------------------------------------------------------------------------------------------
// Reader

StreamReader::StreamReader(const std::string& path) : path_(path) {
  const std::string name = display_name(path, false);
  if (path == "-") {
    f_ = stdin;
#ifdef _WIN32
    _setmode(_fileno(stdin), _O_BINARY);
#endif
  } else {
    f_ = std::fopen(path.c_str(), "rb");
    if (!f_) throw StreamError(name, std::string("cannot open: ") + std::strerror(errno));
    owns_ = true;
  }
  unsigned char h[kHeaderBytes];
  const std::size_t got = std::fread(h, 1, sizeof h, f_);
  offset_ = got;
  if (got < sizeof h && std::ferror(f_))
    throw StreamError(name, std::string("read failed: ") + std::strerror(errno));
  const std::size_t cmp = std::min(got, sizeof kMagic);
  if (got == 0)
    throw StreamError(name, "not an mpm stream (empty input: the producer wrote nothing)");
  if (std::memcmp(h, kMagic, cmp) != 0) {
    std::string msg = "not an mpm stream (bad magic)";
    if (looks_like_toml(h, got))
      msg += "; this looks like a scene file; run mpm-prep on it first";
    else if (got >= 5 && std::memcmp(h, kMagic, 4) == 0 && h[4] == '\n')
      msg += "; its line endings were converted (copied in text mode?)";
    throw StreamError(name, msg);
  }
  if (got < sizeof h)
    throw StreamError(name, "stream truncated in its header: expected " + std::to_string(sizeof h) +
                                " bytes, found " + std::to_string(got));
  std::uint16_t major, minor;
  std::memcpy(&major, h + 8, 2);
  std::memcpy(&minor, h + 10, 2);
  if (major != kStreamVersionMajor)
    throw StreamError(
        name, std::string("written by ") + (major > kStreamVersionMajor ? "a newer" : "an older") +
                  " mpm (format " + std::to_string(major) + ".x); this reader knows " +
                  std::to_string(kStreamVersionMajor) + ".x");
  // The reserved word is ignored: later minors may use it.
}

StreamReader::~StreamReader() {
  if (owns_ && f_) std::fclose(f_);
}

std::string StreamReader::record_label() const {
  // type_ is 0 when the header ended before the type (0 is no valid type code).
  return "record " + std::to_string(records_ + 1) + " (" +
         (type_ ? record_name(type_) + " at byte " : "at byte ") + std::to_string(record_offset_) +
         ")";
}

std::string StreamReader::intact_label() const {
  if (frames_ == 0) return "no frame precedes it";
  if (frames_ == 1) return "the 1 frame before it is intact";
  return "the " + std::to_string(frames_) + " frames before it are intact";
}

void StreamReader::fail(const std::string& message) {
  const StreamError e(display_name(path_, false), message);
  damage_ = e.message();
  pending_ = false;
  throw e;
}

void StreamReader::fail_truncated(const std::string& expected, std::uint64_t found) {
  if (std::ferror(f_))
    fail("read failed in " + record_label() + ": " + std::strerror(errno) + "; " + intact_label());
  fail("stream truncated in " + record_label() + ": expected " + expected + ", found " +
       std::to_string(found) + "; " + intact_label());
}

void StreamReader::fail_corrupt(const std::string& why) {
  fail(record_label() + " is corrupted (" + why + "); " + intact_label());
}

void StreamReader::read_exact(void* data, std::size_t n) {
  if (n > length_ - done_)
    fail_corrupt("its content runs past its length of " + std::to_string(length_) + " bytes");
  const std::size_t got = n ? std::fread(data, 1, n, f_) : 0;
  offset_ += got;
  crc_ = crc_update(crc_, data, got);
  done_ += got;
  if (got < n) fail_truncated(std::to_string(length_) + " payload bytes", done_);
}

void StreamReader::finish_record() {
  if (done_ != length_)
    fail_corrupt("its content ends at byte " + std::to_string(done_) + " of " +
                 std::to_string(length_));
  std::uint32_t stored = 0;
  const std::size_t got = std::fread(&stored, 1, sizeof stored, f_);
  offset_ += got;
  if (got < sizeof stored) fail_truncated("a 4-byte CRC", got);
  if (stored != crc_) fail_corrupt("CRC mismatch");
  pending_ = false;
  ++records_;
  if (type_ == std::uint32_t(RecordType::Frame)) ++frames_;
}

bool StreamReader::next(std::uint32_t& type) {
  if (!damage_.empty()) throw StreamError(display_name(path_, false), damage_);
  if (pending_) skip();
  record_offset_ = offset_;
  type_ = 0;
  unsigned char h[kRecordHeaderBytes];
  const std::size_t got = std::fread(h, 1, sizeof h, f_);
  offset_ += got;
  if (got >= 4) std::memcpy(&type_, h, 4);
  if (got == 0 && !std::ferror(f_)) return false;
  if (got < sizeof h) fail_truncated("a 12-byte record header", got);
  std::memcpy(&length_, h + 4, 8);
  if (!plausible_type(type_)) fail_corrupt("invalid record type");
  if (length_ > kMaxPayload) fail_corrupt("implausible payload length " + std::to_string(length_));
  crc_ = crc_update(crc_init(), h, sizeof h);
  done_ = 0;
  pending_ = true;
  type = type_;
  return true;
}

std::vector<std::byte> StreamReader::read_payload() {
  if (!pending_) throw std::logic_error("StreamReader::read_payload without a record");
  // Grow as the bytes come, so that a corrupted length cannot make us allocate terabytes.
  std::vector<std::byte> p;
  p.reserve(std::min<std::uint64_t>(length_, std::uint64_t(1) << 26));
  while (done_ < length_) {
    const std::size_t m =
        std::min<std::uint64_t>(length_ - done_, std::max<std::size_t>(p.size(), kChunk));
    const std::size_t at = p.size();
    p.resize(at + m);
    read_exact(p.data() + at, m);
  }
  finish_record();
  return p;
}

void StreamReader::skip() {
  if (!pending_) throw std::logic_error("StreamReader::skip without a record");
  std::byte buf[kChunk];
  while (done_ < length_) read_exact(buf, std::min<std::uint64_t>(sizeof buf, length_ - done_));
  finish_record();
}

Frame StreamReader::read_frame() {
  if (!pending_ ||
      (type_ != std::uint32_t(RecordType::Frame) && type_ != std::uint32_t(RecordType::Escape) &&
       type_ != std::uint32_t(RecordType::Rebar)))
    throw std::logic_error("StreamReader::read_frame: the current record is not a frame");
  return read_frame_body();
}

Frame StreamReader::read_frame_body() {
  if (length_ - done_ < kFrameFixedBytes) {
    fail_corrupt("a frame needs at least " + std::to_string(kFrameFixedBytes) + " bytes, it has " +
                 std::to_string(length_ - done_));
  }
  Frame frame;
  auto get = [&](auto& v) { read_exact(&v, sizeof v); };
  std::uint64_t n = 0;
  std::uint32_t ncols = 0;
  get(frame.step);
  get(frame.time);
  get(frame.flags);
  get(n);
  get(ncols);
  struct In {
    ColumnInfo info;
    ScalarType stored;
  };
  std::vector<In> cols;
  std::uint64_t data_bytes = 0;
  const std::uint64_t limit = length_;  // data_bytes can never legitimately exceed it
  for (std::uint32_t i = 0; i < ncols; ++i) {
    auto get_str = [&](std::string& s) {
      std::uint16_t len = 0;
      get(len);
      s.resize(len);
      read_exact(s.data(), len);
    };
    In c;
    std::uint8_t code = 0, comps = 0;
    get_str(c.info.name);
    get(code);
    get(comps);
    get_str(c.info.unit);
    if (!valid_scalar_type(code))
      fail_corrupt("column " + std::to_string(i + 1) + " has unknown scalar type " +
                   std::to_string(code));
    if (comps == 0) fail_corrupt("column '" + c.info.name + "' has 0 components");
    for (const In& o : cols)
      if (o.info.name == c.info.name) fail_corrupt("column '" + c.info.name + "' appears twice");
    c.stored = static_cast<ScalarType>(code);
    c.info.components = comps;
    c.info.type = c.stored == ScalarType::F32 ? ScalarType::F64 : c.stored;
    const std::uint64_t per = std::uint64_t(comps) * scalar_size(c.stored);
    if (n > limit / per || data_bytes + n * per > limit)
      fail_corrupt("its column table needs more bytes than its length of " +
                   std::to_string(length_));
    data_bytes += n * per;
    cols.push_back(std::move(c));
  }
  if (done_ + data_bytes != length_)
    fail_corrupt("its length " + std::to_string(length_) + " disagrees with its column table (" +
                 std::to_string(done_ + data_bytes) + " bytes)");

  // A corrupted count must not allocate more than the stream holds: a file says how many bytes
  // are left (a pipe does not; there an impossible allocation is refused as corruption).
  struct stat st;
  if (fstat(fileno(f_), &st) == 0 && S_ISREG(st.st_mode) && data_bytes > 0) {
    const std::uint64_t left = std::uint64_t(st.st_size) > offset_ ? st.st_size - offset_ : 0;
    if (data_bytes > left) fail_truncated(std::to_string(length_) + " payload bytes", done_ + left);
  }
  for (const In& c : cols) frame.columns.add(c.info);
  try {
    frame.columns.resize(n);
  } catch (const std::bad_alloc&) {
    fail_corrupt("its " + std::to_string(n) + " particles need " + std::to_string(data_bytes) +
                 " bytes, more than can be allocated");
  }
  std::vector<float> buf;
  for (const In& c : cols) {
    Column& col = frame.columns.at(c.info.name);
    if (c.stored == c.info.type) {
      read_exact(col.data(), col.bytes());  // straight into the column
      continue;
    }
    double* dst = reinterpret_cast<double*>(col.data());
    const std::size_t count = n * std::size_t(c.info.components);
    buf.resize(std::min(count, kChunk / sizeof(float)));
    for (std::size_t i = 0; i < count; i += buf.size()) {
      const std::size_t m = std::min(buf.size(), count - i);
      read_exact(buf.data(), m * sizeof(float));
      for (std::size_t k = 0; k < m; ++k) dst[i + k] = buf[k];
    }
  }
  finish_record();
  return frame;
}

std::string StreamReader::decode_text(const std::vector<std::byte>& payload) {
  return std::string(reinterpret_cast<const char*>(payload.data()), payload.size());
}

HistoryBlock StreamReader::decode_history(const std::vector<std::byte>& payload) {
  Cursor c{payload, "HIST"};
  HistoryBlock b;
  const auto cols = c.get<std::uint32_t>();
  for (std::uint32_t i = 0; i < cols; ++i) {
    c.need(4);  // bounds the loop by the payload size before anything grows
    b.names.push_back(c.get_str16());
    b.units.push_back(c.get_str16());
  }
  const auto rows = c.get<std::uint64_t>();
  const std::uint64_t left = payload.size() - c.at;
  if (cols == 0 ? left != 0 : (rows > left / 8 / cols || rows * cols * 8 != left)) {
    const bool fits = cols == 0 || rows <= UINT64_MAX / 8 / cols;
    throw StreamError("", "malformed HIST payload: " + std::to_string(rows) + " rows of " +
                              std::to_string(cols) + " values need " +
                              (fits ? std::to_string(rows * cols * 8) : "more than 2^64") +
                              " bytes, " + std::to_string(left) + " are left");
  }
  b.values.resize(std::size_t(cols) * rows);
  if (!b.values.empty()) std::memcpy(b.values.data(), payload.data() + c.at, left);
  return b;
}

std::pair<int, std::string> StreamReader::decode_end(const std::vector<std::byte>& payload) {
  Cursor c{payload, "ENDS"};
  const auto status = c.get<std::int32_t>();
  return {status,
          std::string(reinterpret_cast<const char*>(payload.data()) + c.at, payload.size() - c.at)};
}

// ---------------------------------------------------------------------------------------------

StreamSummary read_stream(const std::string& path, const StreamVisitor& visitor) {
  StreamReader r(path);  // a bad header throws
  StreamSummary s;
  const std::string name = display_name(path, false);
  for (;;) {
    std::uint32_t type = 0;
    Frame frame;
    std::string text;
    HistoryBlock history;
    std::pair<int, std::string> end;
    std::vector<std::byte> grid;
    // Only the reader's errors are damage; errors thrown by the visitor propagate.
    try {
      if (!r.next(type)) break;
      const std::string label = r.record_label();
      auto decode = [&](auto&& f) {
        std::vector<std::byte> payload = r.read_payload();
        try {
          f(payload);
        } catch (const StreamError& e) {
          throw StreamError(name,
                            label + " is corrupted (" + e.message() + "); " + r.intact_label());
        }
      };
      switch (static_cast<RecordType>(type)) {
        case RecordType::Frame:
          if (visitor.frame && visitor.want_frames)
            frame = r.read_frame();
          else
            r.skip();
          break;
        case RecordType::Scene:
        case RecordType::Info:
          if ((type == std::uint32_t(RecordType::Scene) ? visitor.scene : visitor.info))
            decode([&](auto& p) { text = StreamReader::decode_text(p); });
          else
            r.skip();
          break;
        case RecordType::History:
          if (visitor.history)
            decode([&](auto& p) { history = StreamReader::decode_history(p); });
          else
            r.skip();
          break;
        case RecordType::End:
          decode([&](auto& p) { end = StreamReader::decode_end(p); });
          break;
        case RecordType::Grid:
          if (visitor.grid)
            grid = r.read_payload();
          else
            r.skip();
          break;
        case RecordType::Escape:
          if (visitor.escapes)
            frame = r.read_frame();
          else
            r.skip();
          break;
        case RecordType::Rebar:
          if (visitor.rebar)
            frame = r.read_frame();
          else
            r.skip();
          break;
        default:
          r.skip();  // a record type of a later minor version
      }
    } catch (const StreamError& e) {
      s.damage = e.what();
      s.frames = r.frames_read();
      return s;
    }
    s.frames = r.frames_read();
    switch (static_cast<RecordType>(type)) {
      case RecordType::Scene:
        if (visitor.scene) visitor.scene(text);
        break;
      case RecordType::Info:
        if (visitor.info) visitor.info(text);
        break;
      case RecordType::Frame:
        if (visitor.frame && visitor.want_frames) visitor.frame(std::move(frame));
        break;
      case RecordType::History:
        if (visitor.history) visitor.history(std::move(history));
        break;
      case RecordType::Grid:
        if (visitor.grid) visitor.grid(std::move(grid));
        break;
      case RecordType::Escape:
        if (visitor.escapes) visitor.escapes(std::move(frame));
        break;
      case RecordType::Rebar:
        if (visitor.rebar) visitor.rebar(std::move(frame));
        break;
      case RecordType::End:
        s.ended = true;
        s.end_status = end.first;
        s.end_message = end.second;
        if (visitor.end) visitor.end(end.first, end.second);
        return s;  // ENDS is the last record; anything after it is ignored
      case RecordType::Checkpoint:
        break;  // read by mpm-run --restart only (restart.hpp)
    }
  }
  return s;
}

}  // namespace mpm
