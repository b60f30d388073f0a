#pragma once
// Whole-file byte I/O with transparent gzip for names ending in ".gz".
#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace farlio::io {

using Bytes = std::vector<unsigned char>;
/// The bytes of a file in memory, as the parsers take them.
using ByteView = std::span<const unsigned char>;

/// True if the file name of `path` ends with `suffix` (case-sensitive), e.g. ".pcd.gz".
[[nodiscard]] bool has_suffix(const std::filesystem::path& path, const std::string& suffix);

/// Reads the whole file; a name ending in ".gz" is gunzipped. Throws InputError naming the file
/// if it is missing, unreadable or (for gzip) corrupt or truncated.
[[nodiscard]] Bytes read_file_bytes(const std::filesystem::path& path);

/// Writes `bytes` to the file (replacing it); a name ending in ".gz" is gzipped. Throws
/// std::runtime_error naming the file if it cannot be written.
void write_file_bytes(const std::filesystem::path& path, std::span<const unsigned char> bytes);

/// write_file_bytes for text.
void write_text_file(const std::filesystem::path& path, const std::string& text);

/// A file written through C stdio, so that a failed write says why: every error is a
/// std::runtime_error "<file>: write error: <strerror(errno)>", e.g. "No space left on device".
class OutputFile {
 public:
  /// Creates (truncates) the file; "<file>: cannot open for writing: <reason>" on failure.
  explicit OutputFile(const std::filesystem::path& path);
  /// Buffered: an error may only show at the next flush() or close().
  void write(std::string_view text);
  void write(std::span<const unsigned char> bytes);
  /// Hands the buffered bytes to the system.
  void flush();
  /// Flushes and closes; the destructor closes without reporting errors.
  void close();
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  [[noreturn]] void fail(int error_number) const;

  std::filesystem::path path_;
  std::unique_ptr<std::FILE, Closer> file_;
};

}  // namespace farlio::io
