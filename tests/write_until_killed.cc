// Test helper for file_io_test: WriteFileAtomically in a loop until a signal kills the process.
// Usage: write_until_killed FOLDER THREADS
// Installs InstallTemporaryFileCleanup's handlers, then each thread t replaces FOLDER/w<t>.json
// with kWrittenContents (file_io_test checks that whole file) for ever.
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "camproj/file_io.h"
#include "write_until_killed.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: write_until_killed FOLDER THREADS\n");
    return 2;
  }
  const std::string folder = argv[1];
  const int threads = std::stoi(argv[2]);
  camproj::InstallTemporaryFileCleanup();
  const std::string contents = camproj::testing::WrittenContents();
  std::vector<std::thread> writers;
  for (int t = 0; t < threads; ++t) {
    writers.emplace_back([&folder, &contents, t] {
      const std::string path = folder + "/w" + std::to_string(t) + ".json";
      for (;;) camproj::WriteFileAtomically(path, contents);
    });
  }
  for (std::thread& writer : writers) writer.join();
  return 0;
}
