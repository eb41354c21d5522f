// Whole-file reading, bounded reading of regular files, and atomic writing (docs/reliability.md).
#ifndef CAMPROJ_FILE_IO_H_
#define CAMPROJ_FILE_IO_H_

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace camproj {

// Writes `contents` to `path` so that readers see the old file or the new one, never a partial
// one, and a failure or a kill leaves no stray file:
//  - the data goes to an unnamed file (O_TMPFILE) in the target's folder, flushed to disk, then
//    linked under a short temporary name ".camproj-XXXXXX" and renamed over the target; where the
//    file system has no O_TMPFILE, that short name is created directly (it fits NAME_MAX for any
//    target name); either way InstallTemporaryFileCleanup's handlers remove it on SIGINT, SIGTERM
//    and SIGHUP (safe with several threads writing: docs/reliability.md);
//  - a `path` that is a symbolic link is written through: its target is replaced, the link stays;
//  - a replaced file keeps its permission bits; a new one gets 0666 minus the umask;
//  - after the rename, temporaries of this function in the folder last modified over an hour ago
//    (left by a kill in the instant before a rename) are removed.
// Throws InputError naming `path` and the reason (e.g. "File too large" under `ulimit -f`, when
// SIGXFSZ is ignored as InstallTemporaryFileCleanup arranges) and removes the temporary; also
// for an empty path.
void WriteFileAtomically(const std::string& path, const std::string& contents);

// One output of a command that writes several: the path, the bytes, and what names it in
// messages (an option: "-o", "--truth").
struct OutputFile {
  std::string path;
  std::string contents;
  std::string what;
};

// Writes every file as WriteFileAtomically does, but none gets its name until every one's data
// is in its temporary, flushed: a failure before that (a folder that does not exist or is not
// writable, a full disk, `ulimit -f`) leaves every target as it was and no temporary. (A failure
// of a later rename, after an earlier file was renamed, is reported but leaves the earlier one
// replaced; a rename within a folder fails only on a full directory or a changed file system.)
// Throws std::invalid_argument, before writing anything, if two paths name one file (SameFile).
void WriteFilesAtomically(const std::vector<OutputFile>& files);

// Whether two paths name one file: the same path once symbolic links and "." / ".." are
// resolved (the file need not exist), or two existing hard links to one inode.
bool SameFile(const std::string& a, const std::string& b);

// Throws std::invalid_argument ("-o and --truth both name X: give each output its own path") if
// two of the outputs (what names it, path) name one file (SameFile); empty paths are skipped.
void RequireDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs);

// Installs handlers that remove the temporary of a WriteFileAtomically in progress on SIGINT,
// SIGTERM and SIGHUP, then die of the signal as before; ignores SIGXFSZ so that a write beyond
// `ulimit -f` fails with EFBIG (reported, temporary removed) instead of killing the process.
// For programs (the command line calls it first); a library caller may keep its own handlers.
void InstallTemporaryFileCleanup();

// A file opened for reading that is known to be a regular file: FIFOs, character and block
// devices, sockets and folders are refused when opened, without blocking (a FIFO with no writer
// would otherwise wait forever, /dev/zero never end). Reads are bounded by the caller.
class InputFile {
 public:
  // Throws InputError naming `path`: cannot open, or not a regular file (says what it is).
  explicit InputFile(const std::string& path);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  // Up to `size` bytes into `buffer`; 0 at the end of the file. Throws InputError on a read error.
  size_t Read(char* buffer, size_t size);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

// The whole file; throws InputError naming the path if it cannot be opened, is not a regular
// file (see InputFile), cannot be read, or exceeds `max_bytes`.
std::string ReadWholeFile(const std::string& path, size_t max_bytes = size_t{1} << 30);

// Throws InputError unless `output_path` is a different file from every one of `input_paths`:
// the same device and inode after following symbolic links (so a link or a hard link to an input
// is refused too). An output that does not exist yet is different from every input. Call it
// before any work whose result would replace an input.
void RequireOutputIsNotAnInput(const std::string& output_path,
                               const std::vector<std::string>& input_paths);

}  // namespace camproj

#endif  // CAMPROJ_FILE_IO_H_
