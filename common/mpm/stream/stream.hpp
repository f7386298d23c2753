#pragma once
/// The one stream format for models and results (reference: docs/format.md).
/// A 16-byte header, then records: fourcc type, u64 payload length, payload, CRC-32 of the
/// type, length and payload. Frames are appended as a run goes, so a reader can follow a pipe
/// frame by frame in bounded memory. Truncation and corruption are detected per record; the
/// records before the damage stay readable. "-" means stdin/stdout.
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/state_values.hpp"

namespace mpm {

inline constexpr std::uint16_t kStreamVersionMajor = 1;  ///< readers refuse other majors
/// Readers accept any minor (1: GRID; 2: CHKP; 3: ESCP; 4: the body column u32 in models of
/// more than 255 bodies; 5: REBR).
inline constexpr std::uint16_t kStreamVersionMinor = 5;
/// The minor a writer stamps unless told otherwise: a stream without REBR records is a 1.4
/// stream, byte for byte (stream_minor in docs/format.md: the lowest minor its records need).
inline constexpr std::uint16_t kStreamMinorWithoutRebar = 4;

/// Record types (little-endian fourcc).
enum class RecordType : std::uint32_t {
  Scene = 0x4E454353,    ///< "SCEN": the scene as TOML text, after overrides
  Info = 0x4F464E49,     ///< "INFO": TOML text about the producer (tool, version, run settings)
  Frame = 0x4D415246,    ///< "FRAM": particle columns at one time
  History = 0x54534948,  ///< "HIST": rows of scalar time histories
  End = 0x53444E45,      ///< "ENDS": status and message; absent when the writer was killed
  Grid = 0x44495247,     ///< "GRID": a graded grid's nodes and cells (since 1.1; graded_grid.hpp)
  Checkpoint = 0x504B4843,  ///< "CHKP": a solver's whole state, for mpm-run --restart (since 1.2)
  Escape = 0x50435345,      ///< "ESCP": particles that left the domain, as a frame (since 1.3)
  Rebar = 0x52424552,       ///< "REBR": truss elements of rebar, laid out as a frame (since 1.5)
};
/// "SCEN", "FRAM", ... for messages; "?xyz" style hex for unknown codes.
std::string record_name(std::uint32_t type);

/// Frame flags.
enum FrameFlags : std::uint32_t {
  kFrameModel = 1u,  ///< the initial state written by mpm-prep
  kFrameFinal = 2u,  ///< the last frame of a completed run
};

/// Particle state at one time.
struct Frame {
  std::int64_t step = 0;
  double time = 0;  ///< s
  std::uint32_t flags = 0;
  ColumnStore columns;
};

/// A solver's whole state between two steps (a CHKP record): the named scalars and every
/// particle column at full precision.
struct Checkpoint {
  StateValues state;
  Frame frame;
};

/// A block of rows of a time history; every value is f64.
struct HistoryBlock {
  std::vector<std::string> names;  ///< column names, e.g. "time", "dt", "kinetic"
  std::vector<std::string> units;  ///< SI unit of each column
  std::vector<double> values;      ///< row-major, rows() x names.size()
  std::size_t rows() const { return names.empty() ? 0 : values.size() / names.size(); }
};

/// Writes a stream to a file or stdout ("-"). Each record is flushed when written, so a
/// reader at the other end of a pipe sees frames as they come.
class StreamWriter {
 public:
  /// Opens the file (or takes stdout for "-") and writes the 16-byte header with the minor
  /// version `minor` (kStreamVersionMinor for a stream that holds REBR records); throws IoError.
  explicit StreamWriter(const std::string& path, std::uint16_t minor = kStreamMinorWithoutRebar);
  /// Continues the stream `source` after its first `keep` bytes (the header and whole
  /// records): when `path` is that file (by any name), cuts it there and appends to it;
  /// otherwise (another file, or "-") copies those bytes first. Throws IoError.
  StreamWriter(const std::string& path, const std::string& source, std::uint64_t keep);
  /// Closes the file (errors are ignored here; call close() to see them). stdout stays open.
  ~StreamWriter();
  StreamWriter(const StreamWriter&) = delete;
  StreamWriter& operator=(const StreamWriter&) = delete;

  /// Writes a SCEN or INFO record holding UTF-8 text.
  void write_text(RecordType type, const std::string& text);
  /// Writes the columns named in `fields` (all when empty; unknown names throw InputError).
  /// Float32 precision stores f64 columns as f32, except "x" (positions keep f64).
  void write_frame(const Frame& frame, const std::vector<std::string>& fields = {},
                   Precision precision = Precision::Float64);
  /// Writes an ESCP record: the particles that left the domain, every column in f64 (the
  /// layout of a frame; docs/format.md).
  void write_escapes(const Frame& escaped);
  /// Writes a REBR record: the rebar's truss elements and their state (columns of
  /// rebar_elements.hpp) at the frame's step and time, every column as stored.
  void write_rebar(const Frame& elements);
  /// Writes a CHKP record: the state values, then every column of the frame as stored (f64
  /// stays f64).
  void write_checkpoint(const StateValues& state, const Frame& frame);
  /// Writes a record of binary payload (GRID: encode_grid in grid_record.hpp).
  void write_record(RecordType type, const std::vector<std::byte>& payload);
  /// Writes a HIST record (names and units must have the same size, values a multiple of it).
  void write_history(const HistoryBlock& block);
  /// Writes the ENDS record: status 0 for a completed run, non-zero with a message otherwise.
  void write_end(int status, const std::string& message);
  /// Flushes and closes the file (stdout is flushed, not closed); throws IoError on failure.
  /// Later writes throw, as do writes after a failed one. The destructor closes silently.
  void close();
  /// Bytes written so far, header included.
  std::uint64_t bytes_written() const { return offset_; }
  /// The path given to the constructor ("-" for stdout).
  const std::string& path() const { return path_; }

 private:
  /// Writes a FRAM, ESCP or CHKP record: `prefix` (CHKP's state values), then the frame.
  void write_columns(RecordType type, const std::string& prefix, const Frame& frame,
                     const std::vector<std::string>& fields, Precision precision);
  void begin_record(RecordType type, std::uint64_t length);
  void put(const void* data, std::size_t n);  ///< writes and updates the running CRC
  void end_record();
  [[noreturn]] void fail_io(int err);  ///< throws IoError naming the path and strerror
  std::string path_;
  std::FILE* f_ = nullptr;
  bool owns_ = false;
  std::uint64_t offset_ = 0;
  std::uint32_t crc_ = 0;
  std::uint64_t remaining_ = 0;  ///< payload bytes still due in the current record
  bool broken_ = false;          ///< a write failed: later writes throw (no record after a cut one)
};

/// Reads a stream sequentially from a file or stdin ("-").
class StreamReader {
 public:
  /// Opens and checks the header; throws StreamError (bad magic, other major version).
  explicit StreamReader(const std::string& path);
  ~StreamReader();
  StreamReader(const StreamReader&) = delete;
  StreamReader& operator=(const StreamReader&) = delete;

  /// One record. For frames, use read_frame() instead of payload.
  struct Record {
    std::uint32_t type = 0;
    std::uint64_t offset = 0;        ///< byte offset of the record in the stream
    std::vector<std::byte> payload;  ///< empty for frames read through read_frame()
  };

  /// Reads the next record's type; false at the end of the stream (EOF at a record boundary).
  /// Should be followed by read_payload(), read_frame() or skip() (a record left unread is
  /// skipped). Throws StreamError on a truncated record header, an implausible length or a
  /// type code that is not four characters [A-Z0-9_]. After a StreamError, every call
  /// throws it again.
  bool next(std::uint32_t& type);
  /// The payload of the current record (checked against its CRC).
  std::vector<std::byte> read_payload();
  /// The current record as a frame (must be a FRAM, ESCP or REBR record), decoded straight into
  /// columns; f32 columns are widened to f64. Checked against its CRC.
  Frame read_frame();
  /// The current record as a checkpoint (must be a CHKP record). Checked against its CRC.
  Checkpoint read_checkpoint();
  /// Skips the current record (still checks its CRC), reading in chunks (works on pipes).
  void skip();

  /// Decoders for payloads; a malformed payload throws StreamError (where is empty).
  static std::string decode_text(const std::vector<std::byte>& payload);
  static HistoryBlock decode_history(const std::vector<std::byte>& payload);
  static std::pair<int, std::string> decode_end(const std::vector<std::byte>& payload);

  /// The path given to the constructor ("-" for stdin).
  const std::string& path() const { return path_; }
  /// Bytes consumed so far, header included.
  std::uint64_t offset() const { return offset_; }
  /// Byte offset of the current (last announced) record.
  std::uint64_t record_offset() const { return record_offset_; }
  /// Records passed intact (CRC checked).
  std::size_t records_read() const { return records_; }
  /// FRAM records passed intact, whether decoded or skipped.
  std::size_t frames_read() const { return frames_; }
  /// "record 7 (FRAM at byte 123456)" for the current record, for messages.
  std::string record_label() const;
  /// "the 3 frames before it are intact", for messages.
  std::string intact_label() const;

 private:
  void read_exact(void* data, std::size_t n);  ///< payload bytes; updates the CRC
  Frame read_frame_body();                     ///< a frame from the current payload position
  void finish_record();                        ///< reads and checks the CRC
  [[noreturn]] void fail(const std::string& message);
  [[noreturn]] void fail_truncated(const std::string& expected, std::uint64_t found);
  [[noreturn]] void fail_corrupt(const std::string& why);
  std::string path_;
  std::FILE* f_ = nullptr;
  bool owns_ = false;
  std::uint64_t offset_ = 0;
  std::uint64_t record_offset_ = 0;
  std::uint32_t type_ = 0;
  std::uint64_t length_ = 0;
  bool pending_ = false;
  std::size_t records_ = 0, frames_ = 0;
  std::uint32_t crc_ = 0;   ///< running CRC of the current record
  std::uint64_t done_ = 0;  ///< payload bytes of the current record read so far
  std::string damage_;      ///< what() of the first StreamError, rethrown afterwards
};

/// Everything in a stream, delivered record by record. Every callback may be empty.
struct StreamVisitor {
  /// Callbacks per record type: SCEN text, INFO text, frames, history blocks, ENDS.
  std::function<void(const std::string&)> scene;
  std::function<void(const std::string&)> info;
  std::function<void(Frame&&)> frame;
  std::function<void(HistoryBlock&&)> history;
  std::function<void(int, const std::string&)> end;
  /// GRID payloads (decode_grid in grid_record.hpp); skipped when empty.
  std::function<void(std::vector<std::byte>&&)> grid;
  /// ESCP records: particles that left the domain, as a frame (since 1.2); skipped when empty.
  std::function<void(Frame&&)> escapes;
  /// REBR records: the rebar's elements, as a frame (since 1.5); skipped when empty.
  std::function<void(Frame&&)> rebar;
  bool want_frames = true;  ///< false: frames are skipped without decoding
};

/// Result of reading a whole stream.
struct StreamSummary {
  std::size_t frames = 0;  ///< intact frames (delivered, or skipped when !want_frames)
  bool ended = false;      ///< an END record was seen
  int end_status = 0;
  std::string end_message;
  std::string damage;  ///< empty, or what was wrong (truncation, CRC mismatch)
};

/// Reads a stream to its end, calling the visitor. On damage, stops there and returns the
/// damage message in the summary instead of throwing: the records before it were delivered.
/// Throws StreamError only when the header itself is bad.
StreamSummary read_stream(const std::string& path, const StreamVisitor& visitor);

}  // namespace mpm
