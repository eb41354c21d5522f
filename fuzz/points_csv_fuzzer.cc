// libFuzzer target for the correspondences CSV reader (camproj/points_file.h).
//
// The contract under test: CorrespondencesFromCsvText either returns correspondences that satisfy
// the header's postconditions or throws camproj::InputError. Anything else -- another exception
// type (it escapes and aborts), a crash, a leak, undefined behaviour, a hang -- is a finding.
// Besides, for every input:
//   * the streamed reader (ReadCorrespondencesFile) must agree with the text reader exactly:
//     same result, or InputError with the same message ("share every rule and message");
//   * tight limits (short lines, few rows) may only turn a success into an InputError;
//   * an accepted file written back with CorrespondencesToCsvText reads back bit for bit.
//   * the reader by view (ReadCorrespondencesViewsFile) agrees with its text form, each view
//     meets the postconditions and its rows are the plain reader's rows of its lines (when both
//     accept the input); one view named "" is exactly the plain reader's result.
// A violated check prints what differs and aborts, so libFuzzer saves the input.
//
// Build and run: scripts/fuzz.sh.
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

#include "camproj/errors.h"
#include "camproj/points_file.h"

namespace {

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "points_csv_fuzzer: contract violated: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

void Expect(bool condition, const std::string& what) {
  if (!condition) Fail(what);
}

// The outcome of one parse: what it returned, or the InputError's message.
template <typename T>
struct ParseOutcome {
  std::optional<T> value;
  std::string error;
};
using Outcome = ParseOutcome<camproj::Correspondences>;
using ViewsOutcome = ParseOutcome<std::vector<camproj::CorrespondencesView>>;

template <typename Parse>
auto Run(Parse parse) {
  ParseOutcome<decltype(parse())> outcome;
  try {
    outcome.value = parse();
  } catch (const camproj::InputError& e) {
    outcome.error = e.what();
    Expect(!outcome.error.empty(), "InputError with an empty message");
  }
  return outcome;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool Same(const camproj::Correspondences& a, const camproj::Correspondences& b,
          bool compare_line_numbers) {
  if (a.points_in_world.size() != b.points_in_world.size() || a.ids != b.ids) return false;
  if (compare_line_numbers && a.line_numbers != b.line_numbers) return false;
  for (size_t i = 0; i < a.points_in_world.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!SameBits(a.points_in_world[i][k], b.points_in_world[i][k])) return false;
    }
    for (int k = 0; k < 2; ++k) {
      if (!SameBits(a.pixels[i][k], b.pixels[i][k])) return false;
    }
  }
  return true;
}

bool Same(const Outcome& a, const Outcome& b) {
  if (a.value.has_value() != b.value.has_value()) return false;
  if (!a.value) return a.error == b.error;
  return Same(*a.value, *b.value, /*compare_line_numbers=*/true);
}

std::string Describe(const Outcome& outcome) {
  if (!outcome.value) return "InputError \"" + outcome.error + "\"";
  return std::to_string(outcome.value->pixels.size()) + " rows";
}

// The header's postconditions on a successful parse.
void CheckPostconditions(const camproj::Correspondences& c) {
  const size_t n = c.points_in_world.size();
  Expect(n > 0, "success without rows");
  Expect(c.pixels.size() == n && c.ids.size() == n && c.line_numbers.size() == n,
         "vectors of different lengths");
  std::unordered_set<std::string> ids;
  for (size_t i = 0; i < n; ++i) {
    Expect(c.points_in_world[i].allFinite() && c.pixels[i].allFinite(), "a value is not finite");
    Expect(!c.ids[i].empty(), "an empty id");
    Expect(ids.insert(c.ids[i]).second, "a repeated id: " + c.ids[i]);
    Expect(c.line_numbers[i] >= 1 && (i == 0 || c.line_numbers[i] > c.line_numbers[i - 1]),
           "line numbers not increasing");
  }
}

bool Same(const ViewsOutcome& a, const ViewsOutcome& b) {
  if (a.value.has_value() != b.value.has_value()) return false;
  if (!a.value) return a.error == b.error;
  if (a.value->size() != b.value->size()) return false;
  for (size_t v = 0; v < a.value->size(); ++v) {
    if ((*a.value)[v].name != (*b.value)[v].name ||
        !Same((*a.value)[v].correspondences, (*b.value)[v].correspondences, true)) {
      return false;
    }
  }
  return true;
}

// The reader by view against the plain reader on the same text (both having accepted it).
void CheckViews(const std::vector<camproj::CorrespondencesView>& views,
                const std::optional<camproj::Correspondences>& plain) {
  Expect(!views.empty(), "success without views");
  std::unordered_set<std::string> names;
  size_t rows = 0;
  for (const camproj::CorrespondencesView& view : views) {
    CheckPostconditions(view.correspondences);
    Expect(names.insert(view.name).second, "a repeated view: " + view.name);
    Expect(!view.name.empty() || views.size() == 1, "an unnamed view among others");
    rows += view.correspondences.pixels.size();
  }
  if (!plain) return;
  Expect(rows == plain->pixels.size(), "the views' rows are not the plain reader's rows");
  if (views.size() == 1 && views[0].name.empty()) {
    Expect(Same(views[0].correspondences, *plain, /*compare_line_numbers=*/true),
           "one unnamed view differs from the plain reader's result");
    return;
  }
  for (const camproj::CorrespondencesView& view : views) {
    const camproj::Correspondences& c = view.correspondences;
    for (size_t i = 0; i < c.pixels.size(); ++i) {
      // The plain reader's rows are in line order: find this row's line there.
      size_t lo = 0, hi = plain->line_numbers.size();
      while (lo < hi) {
        const size_t mid = (lo + hi) / 2;
        if (plain->line_numbers[mid] < c.line_numbers[i]) {
          lo = mid + 1;
        } else {
          hi = mid;
        }
      }
      Expect(lo < plain->line_numbers.size() && plain->line_numbers[lo] == c.line_numbers[i],
             "a view's row is on a line the plain reader did not read");
      for (int k = 0; k < 3; ++k) {
        Expect(SameBits(c.points_in_world[i][k], plain->points_in_world[lo][k]),
               "a view's point differs from the plain reader's");
      }
      for (int k = 0; k < 2; ++k) {
        Expect(SameBits(c.pixels[i][k], plain->pixels[lo][k]),
               "a view's pixel differs from the plain reader's");
      }
    }
  }
}

// A read-only view of `text` as a file, without touching the disk.
class MemoryFile {
 public:
  explicit MemoryFile(const std::string& text) {
    fd_ = memfd_create("points_csv_fuzzer", MFD_CLOEXEC);
    if (fd_ < 0) Fail(std::string("memfd_create: ") + std::strerror(errno));
    size_t written = 0;
    while (written < text.size()) {
      const ssize_t n = write(fd_, text.data() + written, text.size() - written);
      if (n < 0) Fail(std::string("write: ") + std::strerror(errno));
      written += static_cast<size_t>(n);
    }
    path_ = "/proc/self/fd/" + std::to_string(fd_);
  }
  ~MemoryFile() { close(fd_); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  int fd_ = -1;
  std::string path_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const MemoryFile file(text);
  // Messages name the source; text and stream use the same name so that messages must match.
  const std::string& source = file.path();

  const camproj::CorrespondencesLimits defaults;
  const Outcome text_outcome =
      Run([&] { return camproj::CorrespondencesFromCsvText(text, source, defaults); });
  if (text_outcome.value) CheckPostconditions(*text_outcome.value);

  const Outcome stream_outcome =
      Run([&] { return camproj::ReadCorrespondencesFile(source, defaults); });
  Expect(Same(text_outcome, stream_outcome), "text reader: " + Describe(text_outcome) +
                                                 "; streamed reader: " + Describe(stream_outcome));

  const ViewsOutcome views_text =
      Run([&] { return camproj::CorrespondencesViewsFromCsvText(text, source, defaults); });
  const ViewsOutcome views_stream =
      Run([&] { return camproj::ReadCorrespondencesViewsFile(source, defaults); });
  Expect(Same(views_text, views_stream), "the text and the streamed readers by view differ");
  if (views_text.value) CheckViews(*views_text.value, text_outcome.value);

  // Tight limits, chosen from the input so the fuzzer can reach both sides of each bound.
  camproj::CorrespondencesLimits tight;
  tight.max_line_bytes = 1 + size % 97;
  tight.max_points = 1 + size % 5;
  const Outcome tight_text =
      Run([&] { return camproj::CorrespondencesFromCsvText(text, source, tight); });
  const Outcome tight_stream = Run([&] { return camproj::ReadCorrespondencesFile(source, tight); });
  Expect(Same(tight_text, tight_stream), "with tight limits, text reader: " + Describe(tight_text) +
                                             "; streamed reader: " + Describe(tight_stream));
  if (tight_text.value) {
    Expect(text_outcome.value.has_value() && Same(tight_text, text_outcome),
           "tight limits accepted what the defaults did not, or read it differently");
  }

  // Round trip. The writer refuses ids it could not read back; the only such id the reader can
  // produce contains a '\r' (not at the end of the line, where it is a CRLF ending).
  if (text_outcome.value) {
    const camproj::Correspondences& c = *text_outcome.value;
    bool has_cr = false;
    for (const std::string& id : c.ids) has_cr = has_cr || id.find('\r') != std::string::npos;
    std::string written;
    try {
      written = camproj::CorrespondencesToCsvText(c);
    } catch (const std::invalid_argument& e) {
      Expect(has_cr, std::string("the writer refused what the reader accepted: ") + e.what());
      return 0;
    }
    Expect(!has_cr, "the writer accepted an id with a '\\r'");
    const Outcome again =
        Run([&] { return camproj::CorrespondencesFromCsvText(written, "written.csv"); });
    Expect(again.value.has_value(), "the written text does not read back: " + again.error);
    Expect(Same(c, *again.value, /*compare_line_numbers=*/false),
           "the written text reads back different values or ids");
  }
  return 0;
}
