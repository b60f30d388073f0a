#pragma once
// Whole-file byte I/O with transparent gzip for names ending in ".gz".
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace farlio::io {

using Bytes = std::vector<unsigned char>;

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

}  // namespace farlio::io
