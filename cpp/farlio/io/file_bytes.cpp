#include "farlio/io/file_bytes.hpp"

#include <zlib.h>

#include <fstream>
#include <limits>
#include <stdexcept>

#include "farlio/core/error.hpp"

namespace farlio::io {
namespace {

constexpr std::size_t kGzipChunkBytes = std::size_t{1} << 20;

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
    gzFile f = gzopen(path.c_str(), "wb");
    if (f == nullptr) throw std::runtime_error(path.string() + ": cannot open for writing");
    std::size_t done = 0;
    while (done < bytes.size()) {
      const auto chunk = static_cast<unsigned>(std::min(bytes.size() - done, kGzipChunkBytes));
      if (gzwrite(f, bytes.data() + done, chunk) != static_cast<int>(chunk)) {
        gzclose(f);
        throw std::runtime_error(path.string() + ": gzip write error");
      }
      done += chunk;
    }
    if (gzclose(f) != Z_OK) throw std::runtime_error(path.string() + ": gzip close error");
    return;
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path.string() + ": cannot open for writing");
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.flush();
  if (!out) throw std::runtime_error(path.string() + ": write error");
}

void write_text_file(const std::filesystem::path& path, const std::string& text) {
  write_file_bytes(path,
                   std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

}  // namespace farlio::io
