#pragma once
/// What the three tools share on the command line: error reporting and exit statuses.
#include <functional>
#include <string>
#include <vector>

namespace mpm {

/// Runs a tool's body; prints "<tool>: error: <message>" for exceptions and maps them to
/// exit statuses: InputError/StreamError 2, IoError 4, anything else 1.
int guarded_main(const char* tool, const std::function<int()>& body);

/// Throws InputError when `path` is "-" and stdout is a terminal (binary output would be
/// garbage there).
void refuse_terminal_output(const std::string& path, const char* what);

/// Throws InputError when the output file `output` is a directory, or is one of the `inputs`
/// (the same file by any name: links and relative paths are resolved): writing it would
/// destroy the input before or while it is read. "-" (a pipe) passes, and so does an output
/// that does not exist yet.
void check_output_file(const std::string& output, const std::vector<std::string>& inputs);

/// The machine's physical memory in bytes (sysconf); 0 when unknown.
double machine_memory();

/// A memory size given on the command line (--max-memory): a number of bytes with an optional
/// suffix K, M, G or T (powers of 1024; "KB", "KiB" and lower case alike), e.g. "16G",
/// "512M". Throws InputError naming `option` when it is not one.
double parse_memory_size(const std::string& text, const std::string& option);

/// A number of bytes for messages in KiB, MiB, GiB, TiB or PiB, 3 significant digits
/// ("1.5 GiB"); larger as "1.2e+24 bytes".
std::string format_bytes(double bytes);

/// Ignores SIGPIPE so that a closed pipe shows up as a write error (IoError) with a message.
void ignore_sigpipe();

}  // namespace mpm
