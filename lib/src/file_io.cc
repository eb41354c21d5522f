#include "camproj/file_io.h"

#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <system_error>

#include "camproj/errors.h"

namespace camproj {

namespace {

std::string ErrnoText(int error) { return std::strerror(error); }

// Temporaries with a name, for the signal handler to remove: a fixed table of fixed-size slots,
// so that the handler only reads memory and calls unlink (async-signal-safe).
constexpr int kMaxPendingTemporaries = 64;
struct PendingTemporary {
  std::atomic<bool> used{false};
  std::atomic<bool> ready{false};
  char path[PATH_MAX] = {};
};
PendingTemporary pending_temporaries[kMaxPendingTemporaries];
// Set by the handler before it removes the registered temporaries: a thread that enters a
// CreationWindow after that point creates nothing, and one inside a window removes what it
// created itself (AbandonIfDying), so none is created behind the handler's back.
std::atomic<bool> dying{false};
// Threads inside a CreationWindow (from before a temporary's name is registered until
// AbandonIfDying has run on it): the handler waits for them before it removes the registered
// temporaries. Otherwise a thread could create its file just after the handler's unlink and the
// process die before that thread's AbandonIfDying (seen: a SIGTERM at the start of a 2-thread
// batch under the sanitizers left a .camproj-*.tmp).
std::atomic<int> creating{0};

// The signals InstallTemporaryFileCleanup handles.
sigset_t HandledSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&signals, signal_number);
  return signals;
}

// Once the handler has started: waits for the process to die of the signal (the handler's
// thread raises it), doing nothing a user could see meanwhile.
void WaitForDeathIfDying() {
  if (!dying) return;
  for (;;) pause();
}

// Called after a temporary's name is registered and created, inside that creation's
// CreationWindow: if a handler has started, removes it, leaves the window (the handler need not
// wait for this thread) and waits for the process to die of the signal.
void AbandonIfDying(const std::string& name) {
  if (!dying) return;
  unlink(name.c_str());
  --creating;
  WaitForDeathIfDying();
}

// Counts the calling thread in `creating` from before a temporary's name is registered until
// AbandonIfDying has run on it (or the creation failed), with the handled signals blocked in
// this thread meanwhile: the handler then never runs on a thread inside its window (it would
// wait for itself), and may wait for every window to close. A window opened after the handler
// set `dying` creates nothing: the thread waits for the process's death. The two orders are
// exclusive (sequentially consistent atomics, as in Dekker's algorithm): the handler sets `dying`
// then reads `creating`, a thread increments `creating` then reads `dying`, so either the handler
// sees this window and waits for it, or this thread sees `dying`.
class CreationWindow {
 public:
  CreationWindow() {
    const sigset_t handled = HandledSignals();
    pthread_sigmask(SIG_BLOCK, &handled, &previous_mask_);
    ++creating;
    if (dying) {
      --creating;
      WaitForDeathIfDying();
    }
  }
  ~CreationWindow() {
    --creating;
    pthread_sigmask(SIG_SETMASK, &previous_mask_, nullptr);
  }
  CreationWindow(const CreationWindow&) = delete;
  CreationWindow& operator=(const CreationWindow&) = delete;

 private:
  sigset_t previous_mask_;
};

// Registers a temporary's path for removal on a signal, until cleared or destroyed; silently
// does nothing if the table is full or the path too long (the temporary then just is not removed
// on a signal).
class SignalCleanup {
 public:
  SignalCleanup() = default;
  ~SignalCleanup() { Clear(); }
  SignalCleanup(const SignalCleanup&) = delete;
  SignalCleanup& operator=(const SignalCleanup&) = delete;

  void Set(const std::string& path) {
    Clear();
    if (path.size() >= PATH_MAX) return;
    for (PendingTemporary& slot : pending_temporaries) {
      bool expected = false;
      if (slot.used.compare_exchange_strong(expected, true)) {
        std::memcpy(slot.path, path.c_str(), path.size() + 1);
        slot.ready = true;
        slot_ = &slot;
        return;
      }
    }
  }
  void Clear() {
    if (slot_ == nullptr) return;
    slot_->ready = false;
    slot_->used = false;
    slot_ = nullptr;
  }

 private:
  PendingTemporary* slot_ = nullptr;
};

extern "C" void RemoveTemporariesAndDie(int signal_number) {
  dying = true;
  // Let the threads inside a CreationWindow finish creating their temporary (it is then
  // registered, and removed below) or see `dying` and remove it themselves. Each window is a
  // few system calls (open, or linkat, on a local folder); the bound only keeps a kill working
  // where one hangs (an unresponsive network file system), at the risk of leaving its file.
  constexpr int kWaitsMs = 10000;
  const timespec millisecond{0, 1000000};
  for (int i = 0; i < kWaitsMs && creating.load() > 0; ++i) nanosleep(&millisecond, nullptr);
  for (PendingTemporary& slot : pending_temporaries) {
    if (slot.ready) unlink(slot.path);
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

// ".camproj-XXXXXX.tmp" in `folder`: 19 bytes whatever the target's name, so within NAME_MAX.
std::string TemporaryName(const std::string& folder) {
  static constexpr char kLetters[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  unsigned char random[6] = {};
  if (getrandom(random, sizeof random, 0) != static_cast<ssize_t>(sizeof random)) {
    // No entropy source: the process id and a counter are unique enough, and a collision is
    // only a retry (O_EXCL, linkat's EEXIST).
    static std::atomic<unsigned> counter{0};
    const unsigned long long seed =
        static_cast<unsigned long long>(getpid()) * 2654435761u + 977u * counter++;
    for (size_t i = 0; i < sizeof random; ++i) random[i] = static_cast<unsigned char>(seed >> (8 * i));
  }
  std::string name = folder + "/.camproj-";
  for (unsigned char c : random) name += kLetters[c % (sizeof kLetters - 1)];
  return name + ".tmp";
}

// The file a write to `path` lands on: symbolic links followed (relative ones from their folder).
std::string ResolveLinks(const std::string& path) {
  std::string target = path;
  for (int depth = 0; depth < 40; ++depth) {
    struct stat info {};
    if (lstat(target.c_str(), &info) != 0 || !S_ISLNK(info.st_mode)) return target;
    std::string link(static_cast<size_t>(PATH_MAX), '\0');
    const ssize_t n = readlink(target.c_str(), link.data(), link.size());
    if (n < 0 || static_cast<size_t>(n) >= link.size()) return target;
    link.resize(static_cast<size_t>(n));
    const size_t slash = target.rfind('/');
    target = link.front() == '/' || slash == std::string::npos ? link : target.substr(0, slash + 1) + link;
  }
  throw InputError("cannot write " + path + ": too many levels of symbolic links");
}

std::string FolderOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

void WriteAll(int fd, const std::string& contents, const std::string& path) {
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = write(fd, contents.data() + written, contents.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError("cannot write " + path + ": " + ErrnoText(errno));
    }
    written += static_cast<size_t>(n);
  }
}

// Closes on scope exit; removes the named temporary too unless released.
struct TemporaryGuard {
  int fd = -1;
  std::string name;  // empty: nothing to remove
  ~TemporaryGuard() {
    if (fd >= 0) close(fd);
    if (!name.empty()) unlink(name.c_str());
  }
};

// Removes this tool's temporaries in `folder` (".camproj-XXXXXX.tmp", regular files) last modified
// over kStaleTemporarySeconds ago: left by a kill at the instant between linkat and rename when
// replacing a file, or during a write on a file system without O_TMPFILE. A write in progress touches its temporary
// within milliseconds, so an hour-old one belongs to no running camproj. Best effort: errors are
// ignored.
constexpr time_t kStaleTemporarySeconds = 3600;
void SweepStaleTemporaries(const std::string& folder) {
  DIR* dir = opendir(folder.c_str());
  if (dir == nullptr) return;
  const time_t now = time(nullptr);
  static constexpr char kPrefix[] = ".camproj-";
  static constexpr char kSuffix[] = ".tmp";
  const size_t length = sizeof kPrefix - 1 + 6 + sizeof kSuffix - 1;
  while (const dirent* entry = readdir(dir)) {
    const std::string name = entry->d_name;
    if (name.size() != length || name.compare(0, sizeof kPrefix - 1, kPrefix) != 0 ||
        name.compare(length - (sizeof kSuffix - 1), std::string::npos, kSuffix) != 0) {
      continue;
    }
    struct stat info {};
    if (fstatat(dirfd(dir), name.c_str(), &info, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(info.st_mode) &&
        info.st_mtime < now - kStaleTemporarySeconds) {
      unlinkat(dirfd(dir), name.c_str(), 0);
    }
  }
  closedir(dir);
}

const char* KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace

void InstallTemporaryFileCleanup() {
  struct sigaction action {};
  action.sa_handler = RemoveTemporariesAndDie;
  sigemptyset(&action.sa_mask);
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction previous {};
    // A signal the caller's parent set to be ignored (nohup) stays ignored.
    if (sigaction(signal_number, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
    sigaction(signal_number, &action, nullptr);
  }
  std::signal(SIGXFSZ, SIG_IGN);
}

namespace {

// A write whose data is in its temporary, flushed, not yet under the target's name: the
// temporary (unnamed, or named and registered for the signal handler) is removed if the write
// is dropped before CommitWrite.
struct PreparedWrite {
  std::string path;    // as given, for messages
  std::string target;  // links resolved
  std::string folder;
  bool replacing = false;
  bool unnamed = false;
  TemporaryGuard temporary;
  SignalCleanup cleanup;
};

// Everything of a write but giving the file its name: the temporary in the target's folder,
// the contents, the replaced file's owner and permissions, fsync.
std::unique_ptr<PreparedWrite> PrepareWrite(const std::string& path, const std::string& contents) {
  // An empty path names no file (open("") fails with a message about links and folders).
  if (path.empty()) throw InputError("cannot write a file with an empty path");
  auto write = std::make_unique<PreparedWrite>();
  write->path = path;
  write->target = ResolveLinks(path);
  write->folder = FolderOf(write->target);
  const std::string& folder = write->folder;
  struct stat existing {};
  write->replacing = stat(write->target.c_str(), &existing) == 0;
  if (write->replacing && !S_ISREG(existing.st_mode)) {
    throw InputError("cannot write " + path + ": it is " + KindOf(existing.st_mode) +
                     ", not a regular file");
  }

  TemporaryGuard& temporary = write->temporary;
  // An unnamed file first: nothing to leave behind if the process dies while writing. The test
  // suite sets CAMPROJ_TEST_NO_TMPFILE to run the fallback on file systems that have O_TMPFILE.
  const bool try_unnamed = std::getenv("CAMPROJ_TEST_NO_TMPFILE") == nullptr;
  temporary.fd = try_unnamed ? open(folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666) : -1;
  write->unnamed = temporary.fd >= 0;
  if (!write->unnamed) {
    const CreationWindow window;
    std::string name;
    for (int attempt = 0; attempt < 100 && temporary.fd < 0; ++attempt) {
      name = TemporaryName(folder);
      write->cleanup.Set(name);
      temporary.fd = open(name.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0666);
      if (temporary.fd < 0) {
        const int error = errno;
        write->cleanup.Clear();
        if (error != EEXIST) {
          throw InputError("cannot write " + path + ": cannot create a file in " + folder + ": " +
                           ErrnoText(error));
        }
      }
    }
    if (temporary.fd < 0) throw InputError("cannot write " + path + ": no free temporary name in " + folder);
    temporary.name = name;
    AbandonIfDying(name);
  }
  WriteAll(temporary.fd, contents, path);
  if (write->replacing) {
    // The replaced file's owner and permissions carry over (the owner only where allowed).
    if (fchown(temporary.fd, existing.st_uid, existing.st_gid) != 0) {
      // Not the owner: the new file is ours, with the old permission bits.
    }
    if (fchmod(temporary.fd, existing.st_mode & 07777) != 0) {
      throw InputError("cannot write " + path + ": chmod: " + ErrnoText(errno));
    }
  }
  if (fsync(temporary.fd) != 0) throw InputError("cannot write " + path + ": fsync: " + ErrnoText(errno));
  return write;
}

// Gives a prepared write the target's name: linkat for a new file from an unnamed temporary,
// else a short temporary name and rename over the target.
void CommitWrite(PreparedWrite* write) {
  const std::string& path = write->path;
  const std::string& target = write->target;
  const std::string& folder = write->folder;
  TemporaryGuard& temporary = write->temporary;
  std::string name = temporary.name;
  if (write->unnamed) {
    const std::string fd_path = "/proc/self/fd/" + std::to_string(temporary.fd);
    // A new file gets its final name at once: no instant with a named temporary, which a kill
    // there would leave behind (a batch writing into a fresh folder; seen under load).
    if (!write->replacing) {
      if (linkat(AT_FDCWD, fd_path.c_str(), AT_FDCWD, target.c_str(), AT_SYMLINK_FOLLOW) == 0) {
        const int fd = temporary.fd;
        temporary.fd = -1;
        if (close(fd) != 0) throw InputError("cannot write " + path + ": close: " + ErrnoText(errno));
        SweepStaleTemporaries(folder);
        return;
      }
      if (errno != EEXIST) throw InputError("cannot write " + path + ": link: " + ErrnoText(errno));
      // Created meanwhile: replace it as below.
    }
    // Give it a name only now, for the instant before rename (linkat cannot replace a file).
    const CreationWindow window;
    for (int attempt = 0; attempt < 100; ++attempt) {
      name = TemporaryName(folder);
      write->cleanup.Set(name);
      if (linkat(AT_FDCWD, fd_path.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) == 0) {
        AbandonIfDying(name);
        break;
      }
      if (errno != EEXIST) {
        const int error = errno;
        write->cleanup.Clear();
        throw InputError("cannot write " + path + ": link: " + ErrnoText(error));
      }
      write->cleanup.Clear();
      name.clear();
    }
    if (name.empty()) throw InputError("cannot write " + path + ": no free temporary name in " + folder);
    temporary.name = name;
  }
  const int fd = temporary.fd;
  temporary.fd = -1;
  if (close(fd) != 0) throw InputError("cannot write " + path + ": close: " + ErrnoText(errno));
  if (std::rename(name.c_str(), target.c_str()) != 0) {
    const int error = errno;
    // The handler removed the temporary (ENOENT): no message, the process is about to die.
    WaitForDeathIfDying();
    throw InputError("cannot write " + path + ": rename: " + ErrnoText(error));
  }
  temporary.name.clear();
  SweepStaleTemporaries(folder);
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  const std::unique_ptr<PreparedWrite> write = PrepareWrite(path, contents);
  CommitWrite(write.get());
}

bool SameFile(const std::string& a, const std::string& b) {
  // Absolute first: weakly_canonical leaves a relative path with no existing prefix relative.
  std::error_code error;
  const std::filesystem::path canonical_a =
      std::filesystem::weakly_canonical(std::filesystem::absolute(a, error), error);
  if (error) return false;
  const std::filesystem::path canonical_b =
      std::filesystem::weakly_canonical(std::filesystem::absolute(b, error), error);
  if (error) return false;
  if (canonical_a == canonical_b) return true;
  struct stat info_a {};
  struct stat info_b {};
  return stat(a.c_str(), &info_a) == 0 && stat(b.c_str(), &info_b) == 0 &&
         info_a.st_dev == info_b.st_dev && info_a.st_ino == info_b.st_ino;
}

void RequireDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (!outputs[i].second.empty() && !outputs[j].second.empty() &&
          SameFile(outputs[i].second, outputs[j].second)) {
        throw std::invalid_argument(outputs[j].first + " and " + outputs[i].first + " both name " +
                                    outputs[i].second + ": give each output its own path");
      }
    }
  }
}

void WriteFilesAtomically(const std::vector<OutputFile>& files) {
  std::vector<std::pair<std::string, std::string>> named_paths;
  for (const OutputFile& file : files) named_paths.emplace_back(file.what, file.path);
  RequireDistinctOutputs(named_paths);
  std::vector<std::unique_ptr<PreparedWrite>> writes;
  for (const OutputFile& file : files) writes.push_back(PrepareWrite(file.path, file.contents));
  for (const std::unique_ptr<PreparedWrite>& write : writes) CommitWrite(write.get());
}

InputFile::InputFile(const std::string& path) : path_(path) {
  // O_NONBLOCK: opening a FIFO with no writer returns at once instead of waiting for one.
  fd_ = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd_ < 0) throw InputError(path + ": cannot open: " + ErrnoText(errno));
  struct stat info {};
  if (fstat(fd_, &info) != 0) {
    const int error = errno;
    close(fd_);
    throw InputError(path + ": cannot read: " + ErrnoText(error));
  }
  if (!S_ISREG(info.st_mode)) {
    close(fd_);
    throw InputError(path + ": is " + std::string(KindOf(info.st_mode)) + ", expected a regular file");
  }
}

InputFile::~InputFile() { close(fd_); }

size_t InputFile::Read(char* buffer, size_t size) {
  for (;;) {
    const ssize_t n = read(fd_, buffer, size);
    if (n >= 0) return static_cast<size_t>(n);
    if (errno != EINTR) throw InputError(path_ + ": cannot read: " + ErrnoText(errno));
  }
}

std::string ReadWholeFile(const std::string& path, size_t max_bytes) {
  InputFile in(path);
  std::string contents;
  char buffer[1 << 16];
  for (size_t n; (n = in.Read(buffer, sizeof buffer)) > 0;) {
    contents.append(buffer, n);
    if (contents.size() > max_bytes) {
      throw InputError(path + ": larger than " + std::to_string(max_bytes) + " bytes");
    }
  }
  return contents;
}

void RequireOutputIsNotAnInput(const std::string& output_path,
                               const std::vector<std::string>& input_paths) {
  struct stat output {};
  if (stat(output_path.c_str(), &output) != 0) return;
  for (const std::string& input_path : input_paths) {
    struct stat input {};
    if (stat(input_path.c_str(), &input) == 0 && input.st_dev == output.st_dev &&
        input.st_ino == output.st_ino) {
      throw InputError(output_path + ": the output is the input " + input_path +
                       " (the same file): writing it would destroy the input; choose another "
                       "output path");
    }
  }
}

}  // namespace camproj
