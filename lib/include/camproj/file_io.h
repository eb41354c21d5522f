// Whole-file reading and atomic writing.
#ifndef CAMPROJ_FILE_IO_H_
#define CAMPROJ_FILE_IO_H_

#include <string>

namespace camproj {

// Writes `contents` to a temporary file in the same folder, flushes it to disk and renames it over
// `path`: readers see the old file or the new one, never a partial one. Throws InputError naming
// the path on any failure (and removes the temporary file).
void WriteFileAtomically(const std::string& path, const std::string& contents);

// The whole file; throws InputError naming the path if it cannot be read or exceeds `max_bytes`.
std::string ReadWholeFile(const std::string& path, size_t max_bytes = size_t{1} << 30);

}  // namespace camproj

#endif  // CAMPROJ_FILE_IO_H_
