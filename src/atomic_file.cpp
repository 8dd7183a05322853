#include "specdeform/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "specdeform/exceptions.h"

namespace specdeform {

void check_writable(const std::filesystem::path& path) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError(path.string() + ": is a folder, not a file to write");
  }
  if (!std::filesystem::is_directory(dir, ec)) {
    throw InputError(path.string() + ": the folder " + dir.string() + " does not exist");
  }
  if (access(dir.c_str(), W_OK | X_OK) != 0) {
    throw InputError(path.string() + ": cannot write in the folder " + dir.string() + ": " +
                     std::strerror(errno));
  }
}

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  write_file_atomically(path, std::span(&bytes, 1));
}

void write_file_atomically(const std::filesystem::path& path,
                           std::span<const std::string_view> parts) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
  std::string tmp_name = ".";
  tmp_name += path.filename().string();
  tmp_name += ".XXXXXX";
  std::string tmp = (dir / tmp_name).string();
  const int fd = mkstemp(tmp.data());
  if (fd < 0) {
    throw InputError(path.string() + ": cannot write: " + std::strerror(errno));
  }
  const auto fail = [&](const char* what) {
    const std::string reason = std::strerror(errno);
    ::close(fd);
    ::unlink(tmp.c_str());
    throw InputError(path.string() + ": " + what + ": " + reason);
  };
  for (const std::string_view bytes : parts) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t wrote = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (wrote < 0) {
        if (errno == EINTR) continue;
        fail("cannot write");
      }
      done += static_cast<size_t>(wrote);
    }
  }
  if (::fchmod(fd, 0644) != 0 || ::fsync(fd) != 0) fail("cannot write");
  if (::close(fd) != 0) {
    ::unlink(tmp.c_str());
    throw InputError(path.string() + ": cannot write: " + std::strerror(errno));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw InputError(path.string() + ": cannot write: " + reason);
  }
}

}  // namespace specdeform
