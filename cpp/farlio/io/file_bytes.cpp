#include "farlio/io/file_bytes.hpp"

#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "farlio/core/error.hpp"

namespace farlio::io {
namespace {

constexpr std::size_t kGzipChunkBytes = std::size_t{1} << 20;

/// "<file>: <what>: <reason of errno>" for errors of the system's file calls.
std::runtime_error system_error(const std::filesystem::path& path, const std::string& what, int error_number) {
  const std::string reason = error_number != 0 ? std::strerror(error_number) : "reason unknown";
  return std::runtime_error(path.string() + ": " + what + ": " + reason);
}

/// The reason of a zlib error on `f` (errno for Z_ERRNO, else zlib's own message).
std::string gzip_reason(gzFile f) {
  int code = 0;
  const char* msg = gzerror(f, &code);
  return code == Z_ERRNO ? std::strerror(errno) : std::string(msg);
}

Bytes read_gzip(const std::filesystem::path& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) throw InputError(path.string() + ": cannot open file");
  Bytes out;
  for (;;) {
    const std::size_t old_size = out.size();
    out.resize(old_size + kGzipChunkBytes);
    const int got = gzread(f, out.data() + old_size, static_cast<unsigned>(kGzipChunkBytes));
    if (got < 0) {
      int code = 0;
      const std::string msg = gzerror(f, &code);
      gzclose(f);
      throw InputError(path.string() + ": corrupt gzip data (" + msg + ")");
    }
    out.resize(old_size + static_cast<std::size_t>(got));
    if (got == 0) break;
  }
  int code = 0;
  const std::string msg = gzerror(f, &code);
  gzclose(f);
  if (code != Z_OK) throw InputError(path.string() + ": corrupt or truncated gzip data (" + msg + ")");
  return out;
}

}  // namespace

bool has_suffix(const std::filesystem::path& path, const std::string& suffix) {
  const std::string name = path.filename().string();
  return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

Bytes read_file_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(path.string() + ": no such file");
  }
  if (has_suffix(path, ".gz")) return read_gzip(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open file");
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::size_t>(in.tellg());
  in.seekg(0, std::ios::beg);
  Bytes out(size);
  in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(size));
  if (!in) throw InputError(path.string() + ": read error");
  return out;
}

void write_file_bytes(const std::filesystem::path& path, std::span<const unsigned char> bytes) {
  if (has_suffix(path, ".gz")) {
    errno = 0;
    gzFile f = gzopen(path.c_str(), "wb");
    if (f == nullptr) throw system_error(path, "cannot open for writing", errno);
    std::size_t done = 0;
    while (done < bytes.size()) {
      const auto chunk = static_cast<unsigned>(std::min(bytes.size() - done, kGzipChunkBytes));
      if (gzwrite(f, bytes.data() + done, chunk) != static_cast<int>(chunk)) {
        const std::string reason = gzip_reason(f);
        gzclose(f);
        throw std::runtime_error(path.string() + ": gzip write error: " + reason);
      }
      done += chunk;
    }
    errno = 0;
    const int closed = gzclose(f);
    if (closed == Z_ERRNO) throw system_error(path, "gzip write error", errno);
    if (closed != Z_OK)
      throw std::runtime_error(path.string() + ": gzip close error (zlib code " + std::to_string(closed) + ")");
    return;
  }
  OutputFile out(path);
  out.write(bytes);
  out.close();
}

void write_text_file(const std::filesystem::path& path, const std::string& text) {
  write_file_bytes(path,
                   std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

OutputFile::OutputFile(const std::filesystem::path& path) : path_(path) {
  errno = 0;
  file_.reset(std::fopen(path.c_str(), "wb"));
  if (!file_) throw system_error(path_, "cannot open for writing", errno);
}

void OutputFile::write(std::string_view text) {
  write(std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

void OutputFile::write(std::span<const unsigned char> bytes) {
  if (!file_) fail(EBADF);
  errno = 0;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_.get()) != bytes.size()) fail(errno);
}

void OutputFile::flush() {
  if (!file_) fail(EBADF);
  errno = 0;
  if (std::fflush(file_.get()) != 0) fail(errno);
}

void OutputFile::close() {
  if (!file_) return;
  errno = 0;
  const int flushed = std::fflush(file_.get());
  const int flush_errno = errno;
  const int closed = std::fclose(file_.release());
  if (flushed != 0) fail(flush_errno);
  if (closed != 0) fail(errno);
}

void OutputFile::fail(int error_number) const { throw system_error(path_, "write error", error_number); }

}  // namespace farlio::io
