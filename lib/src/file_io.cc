#include "camproj/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "camproj/errors.h"

namespace camproj {

namespace {

std::string ErrnoText() { return std::strerror(errno); }

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  // The temporary lives beside the target so that rename() stays within one file system.
  std::vector<char> temp_path(path.begin(), path.end());
  const std::string suffix = ".tmp.XXXXXX";
  temp_path.insert(temp_path.end(), suffix.begin(), suffix.end());
  temp_path.push_back('\0');
  const int fd = mkstemp(temp_path.data());
  if (fd < 0) throw InputError("cannot create a temporary file next to " + path + ": " + ErrnoText());
  auto fail = [&](const std::string& what) {
    const std::string reason = ErrnoText();
    close(fd);
    unlink(temp_path.data());
    throw InputError("cannot write " + path + ": " + what + ": " + reason);
  };
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = write(fd, contents.data() + written, contents.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write");
    }
    written += static_cast<size_t>(n);
  }
  // mkstemp creates 0600; a camera file is an ordinary document.
  if (fchmod(fd, 0644) != 0) fail("chmod");
  if (fsync(fd) != 0) fail("fsync");
  if (close(fd) != 0) {
    const std::string reason = ErrnoText();
    unlink(temp_path.data());
    throw InputError("cannot write " + path + ": close: " + reason);
  }
  if (std::rename(temp_path.data(), path.c_str()) != 0) {
    const std::string reason = ErrnoText();
    unlink(temp_path.data());
    throw InputError("cannot write " + path + ": rename: " + reason);
  }
}

std::string ReadWholeFile(const std::string& path, size_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open: " + ErrnoText());
  struct stat info {};
  if (stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) {
    throw InputError(path + ": is a directory, expected a file");
  }
  std::string contents;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    contents.append(buffer, static_cast<size_t>(in.gcount()));
    if (contents.size() > max_bytes) {
      throw InputError(path + ": larger than " + std::to_string(max_bytes) + " bytes");
    }
  }
  return contents;
}

}  // namespace camproj
