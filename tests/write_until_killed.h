// What tests/write_until_killed.cc writes, shared with file_io_test.cc.
#ifndef CAMPROJ_TESTS_WRITE_UNTIL_KILLED_H_
#define CAMPROJ_TESTS_WRITE_UNTIL_KILLED_H_

#include <string>

namespace camproj {
namespace testing {

// 4 KiB of JSON, larger than one write's page so that a partial file would show.
inline std::string WrittenContents() {
  std::string text = "{\"filler\": \"";
  text.append(4096, 'x');
  return text + "\"}\n";
}

}  // namespace testing
}  // namespace camproj

#endif  // CAMPROJ_TESTS_WRITE_UNTIL_KILLED_H_
