#include "camproj/points_file.h"


#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>
#include <system_error>
#include <unordered_map>

#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/number_text.h"
#include "check.h"

namespace camproj {

namespace {

constexpr std::array<const char*, 5> kRequiredColumns = {"X", "Y", "Z", "u", "v"};
constexpr std::string_view kIdColumn = "id";
constexpr std::string_view kViewColumn = "view";
constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";
// File text quoted in a message is cut to this many bytes: a message is read, not a dump.
constexpr size_t kMaxQuotedBytes = 60;

std::string_view Trim(std::string_view text) {
  const size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string_view::npos) return {};
  return text.substr(begin, text.find_last_not_of(" \t") - begin + 1);
}

// File text made safe for a terminal and cut short.
std::string Printable(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size() && i < kMaxQuotedBytes; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (text.size() > kMaxQuotedBytes) out += "...";
  return out;
}

std::string Quoted(std::string_view text) { return "\"" + Printable(text) + "\""; }

void Split(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  size_t begin = 0;
  while (true) {
    const size_t comma = line.find(',', begin);
    if (comma == std::string_view::npos) {
      fields.push_back(Trim(line.substr(begin)));
      return;
    }
    fields.push_back(Trim(line.substr(begin, comma - begin)));
    begin = comma + 1;
  }
}

bool ParsesAsNumber(std::string_view field) {
  if (field.size() > 1 && field[0] == '+' && field[1] != '-' && field[1] != '+') {
    field.remove_prefix(1);
  }
  double value = 0.0;
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
  return error == std::errc() && end == field.data() + field.size();
}

// Fed one line at a time, so that text and streamed files share every rule and message.
class CsvParser {
 public:
  // by_view: a `view` column groups the rows (FinishViews); without it the column is ignored
  // like any extra column.
  CsvParser(std::string source, const CorrespondencesLimits& limits, bool by_view = false)
      : source_(std::move(source)), limits_(limits), by_view_(by_view) {}

  // The line number the next AddLine call will be given.
  int64_t next_line() const { return line_ + 1; }

  [[noreturn]] void FailLine(int64_t line, const std::string& what) const {
    throw InputError(source_ + ": line " + std::to_string(line) + ": " + what);
  }

  [[noreturn]] void FailLongLine(int64_t line) const {
    throw InputError(source_ + ": line " + std::to_string(line) + " is longer than " +
                     std::to_string(limits_.max_line_bytes) + " bytes");
  }

  // Lines ended by CR alone (classic Mac OS) read as one line with CRs inside.
  [[noreturn]] void FailCarriageReturn(int64_t line) const {
    FailLine(line, "a carriage return (CR) inside the line: lines that end in CR alone (classic "
                   "Mac OS) are not read; save the file with LF or CRLF line ends");
  }

  // `line` has no '\n'; a trailing '\r' is still there.
  void AddLine(std::string_view line) {
    ++line_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find('\r') != std::string_view::npos) FailCarriageReturn(line_);
    if (line.size() > limits_.max_line_bytes) FailLongLine(line_);
    if (line_ > INT_MAX) FailLine(line_, "more than " + std::to_string(INT_MAX) + " lines");
    if (line_ == 1 && line.substr(0, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark) {
      line.remove_prefix(kUtf8ByteOrderMark.size());
    }
    const std::string_view trimmed = Trim(line);
    if (trimmed.empty()) return;
    saw_text_ = true;
    if (trimmed.front() == '#') return;
    Split(line, fields_);
    if (header_line_ == 0) {
      ReadHeader();
    } else {
      ReadRow();
    }
  }

  Correspondences Finish() {
    Complete();
    return std::move(views_.front().correspondences);
  }

  std::vector<CorrespondencesView> FinishViews() {
    Complete();
    return std::move(views_);
  }

 private:
  // The checks at the end of the text, and the vectors' slack given back.
  void Complete() {
    if (header_line_ == 0) {
      throw InputError(
          source_ + ": " +
          (saw_text_ ? "no header: the file has only comments and blank lines" : "empty file") +
          "; expected a header line naming the columns X,Y,Z,u,v");
    }
    if (num_rows_ == 0) {
      throw InputError(source_ + ": the header (line " + std::to_string(header_line_) +
                       ") is followed by no data rows");
    }
    // The rows were appended one by one (capacity up to twice the size); the fit holds them
    // throughout, so give the slack back.
    for (CorrespondencesView& view : views_) {
      Correspondences& c = view.correspondences;
      c.points_in_world.shrink_to_fit();
      c.pixels.shrink_to_fit();
      c.ids.shrink_to_fit();
      c.line_numbers.shrink_to_fit();
    }
  }

  std::string ColumnLabel(size_t index) const {
    std::string label = "column " + std::to_string(index + 1);
    if (index < names_.size() && !names_[index].empty()) label += " (" + names_[index] + ")";
    return label;
  }

  [[noreturn]] void FailField(size_t index, const std::string& what) const {
    throw InputError(source_ + ": line " + std::to_string(line_) + ", " + ColumnLabel(index) +
                     ": " + what);
  }

  void ReadHeader() {
    header_line_ = line_;
    std::unordered_map<std::string_view, size_t> index_of_name;
    for (size_t i = 0; i < fields_.size(); ++i) {
      names_.emplace_back(fields_[i]);
      // Unnamed columns (a trailing comma) are ignored like any extra column.
      if (fields_[i].empty()) continue;
      const auto [it, inserted] = index_of_name.emplace(fields_[i], i);
      if (!inserted) {
        FailField(i, "duplicate column name; column " + std::to_string(it->second + 1) +
                         " is also " + Printable(fields_[i]));
      }
    }
    has_pixels_ = limits_.read_pixels;
    std::string missing;
    int missing_count = 0;
    for (size_t c = 0; c < (has_pixels_ ? kRequiredColumns.size() : 3); ++c) {
      const auto it = index_of_name.find(kRequiredColumns[c]);
      if (it == index_of_name.end()) {
        missing += (missing.empty() ? "" : ",") + std::string(kRequiredColumns[c]);
        ++missing_count;
      } else {
        column_[c] = it->second;
      }
    }
    if (missing_count > 0) {
      std::string has;
      for (size_t i = 0; i < names_.size(); ++i) has += (i == 0 ? "" : ",") + names_[i];
      FailLine(line_, std::string("header lacks column") + (missing_count > 1 ? "s " : " ") +
                          missing + "; it has " + Printable(has) + HeaderHint());
    }
    const auto id = index_of_name.find(kIdColumn);
    if (id != index_of_name.end()) id_column_ = id->second;
    const auto view = index_of_name.find(kViewColumn);
    if (by_view_ && view != index_of_name.end()) view_column_ = view->second;
  }

  // Names the likely cause of a header that lacks the required columns.
  std::string HeaderHint() const {
    if (ParsesAsNumber(fields_[0])) {
      return " (the first line that is not blank or a comment must be the header)";
    }
    for (const std::string& name : names_) {
      if (name.find_first_of(";\t") != std::string::npos) {
        return " (fields must be separated by commas)";
      }
      for (const char* required : kRequiredColumns) {
        if (name.size() == 1 && name[0] != required[0] &&
            std::tolower(static_cast<unsigned char>(name[0])) ==
                std::tolower(static_cast<unsigned char>(required[0]))) {
          return " (column names are case-sensitive)";
        }
      }
    }
    return "";
  }

  void ReadRow() {
    bool all_empty = true;  // ",,,,"
    for (const std::string_view field : fields_) all_empty = all_empty && field.empty();
    if (all_empty) return;
    if (fields_.size() < names_.size()) {
      FailLine(line_, std::to_string(fields_.size()) + " fields, but the header (line " +
                          std::to_string(header_line_) + ") has " + std::to_string(names_.size()) +
                          "; " + ColumnLabel(fields_.size()) + " is missing");
    }
    if (fields_.size() > names_.size()) {
      FailLine(line_, std::to_string(fields_.size()) + " fields, but the header (line " +
                          std::to_string(header_line_) + ") has " + std::to_string(names_.size()) +
                          "; column " + std::to_string(names_.size() + 1) +
                          " is not in the header");
    }
    if (num_rows_ >= limits_.max_points) {
      FailLine(line_, "more than " + std::to_string(limits_.max_points) + " data rows");
    }
    std::array<double, 5> values{};
    for (size_t c = 0; c < (has_pixels_ ? values.size() : 3); ++c) values[c] = Number(column_[c]);
    const size_t view = ViewOfRow();
    Correspondences& result = views_[view].correspondences;
    std::string id;
    if (id_column_) {
      const std::string_view text = fields_[*id_column_];
      if (text.empty()) FailField(*id_column_, "empty id");
      const auto [it, inserted] =
          line_of_id_[view].emplace(std::string(text), static_cast<int>(line_));
      if (!inserted) {
        FailField(*id_column_, "duplicate id " + Quoted(text) +
                                   (view_column_ ? " in view " + Quoted(views_[view].name) : "") +
                                   " (also on line " + std::to_string(it->second) + ")");
      }
      id = text;
    } else {
      id = std::to_string(result.pixels.size() + 1);
    }
    result.points_in_world.emplace_back(values[0], values[1], values[2]);
    result.pixels.emplace_back(values[3], values[4]);
    result.ids.push_back(std::move(id));
    result.line_numbers.push_back(static_cast<int>(line_));
    ++num_rows_;
  }

  // The index in views_ of the current row's view, added at its first row.
  size_t ViewOfRow() {
    if (!view_column_) {
      if (views_.empty()) AddView("");
      return 0;
    }
    const std::string_view name = fields_[*view_column_];
    if (name.empty()) FailField(*view_column_, "empty view name");
    // Rows usually come view by view: the previous row's view without a lookup.
    if (!views_.empty() && name == views_[last_view_].name) return last_view_;
    const auto it = view_index_.find(std::string(name));
    last_view_ = it != view_index_.end() ? it->second : AddView(name);
    return last_view_;
  }

  size_t AddView(std::string_view name) {
    view_index_.emplace(std::string(name), views_.size());
    views_.push_back({std::string(name), {}});
    line_of_id_.emplace_back();
    return views_.size() - 1;
  }

  double Number(size_t index) const {
    std::string_view field = fields_[index];
    // from_chars refuses the '+' that strtod and spreadsheets accept.
    if (field.size() > 1 && field[0] == '+' && field[1] != '-' && field[1] != '+') {
      field.remove_prefix(1);
    }
    double value = 0.0;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
    if (error == std::errc::result_out_of_range) {
      FailField(index, Quoted(fields_[index]) + " is out of the range of a double");
    }
    if (error != std::errc() || end != field.data() + field.size()) {
      FailField(index, "expected a number, got " + Quoted(fields_[index]));
    }
    if (!std::isfinite(value)) FailField(index, Quoted(fields_[index]) + " is not finite");
    return value;
  }

  std::string source_;
  CorrespondencesLimits limits_;
  int64_t line_ = 0;
  bool saw_text_ = false;
  int64_t header_line_ = 0;  // 0 until the header is read
  std::vector<std::string> names_;
  std::array<size_t, 5> column_{};  // index of X, Y, Z, u, v in a row
  bool has_pixels_ = true;
  bool by_view_ = false;
  std::optional<size_t> id_column_;
  std::optional<size_t> view_column_;  // only when by_view_
  std::vector<std::string_view> fields_;  // reused: one allocation for all rows
  // One view without a view column (named ""); else one per name, in order of first appearance.
  std::vector<CorrespondencesView> views_;
  std::unordered_map<std::string, size_t> view_index_;
  size_t last_view_ = 0;
  std::vector<std::unordered_map<std::string, int>> line_of_id_;  // per view: id -> its line
  size_t num_rows_ = 0;
};

std::string IdProblem(const std::string& id) {
  if (id.empty()) return "is empty";
  if (id.find_first_of(",\r\n") != std::string::npos) return "contains a comma or line break";
  if (Trim(id).size() != id.size()) return "has surrounding spaces or tabs";
  return "";
}

void AppendNumber(double value, std::string& out) { out += ShortestDouble(value); }

}  // namespace

void CorrespondencesLimits::Check() const {
  internal::Require(max_line_bytes > 0, "max_line_bytes must be positive, got ", max_line_bytes);
  internal::Require(max_points > 0, "max_points must be positive, got ", max_points);
}

namespace {

void ParseText(const std::string& text, CsvParser& parser) {
  const std::string_view all(text);
  size_t begin = 0;
  while (begin < all.size()) {
    size_t end = all.find('\n', begin);
    if (end == std::string_view::npos) end = all.size();
    parser.AddLine(all.substr(begin, end - begin));
    begin = end + 1;
  }
}

void ParseFile(const std::string& path, const CorrespondencesLimits& limits, CsvParser& parser) {
  InputFile in(path);
  // `pending` holds the start of a line that runs past the buffer; a line may end in '\r' that
  // AddLine drops, so one byte more than the limit is still a candidate.
  std::string pending;
  std::vector<char> buffer(size_t{1} << 16);
  for (size_t n; (n = in.Read(buffer.data(), buffer.size())) > 0;) {
    const std::string_view chunk(buffer.data(), n);
    size_t begin = 0;
    while (begin < chunk.size()) {
      const size_t newline = chunk.find('\n', begin);
      const size_t end = newline == std::string_view::npos ? chunk.size() : newline;
      const std::string_view piece = chunk.substr(begin, end - begin);
      // A line of max_line_bytes and its CR (the parser strips it); written as a subtraction,
      // since max_line_bytes + 1 wraps at SIZE_MAX (which then refused every line).
      if (pending.size() + piece.size() > limits.max_line_bytes &&
          pending.size() + piece.size() - limits.max_line_bytes > 1) {
        const size_t cr = piece.find('\r');
        if (cr != std::string_view::npos && cr + 1 < piece.size()) {
          parser.FailCarriageReturn(parser.next_line());
        }
        parser.FailLongLine(parser.next_line());
      }
      if (newline == std::string_view::npos) {
        pending.append(piece);
      } else if (pending.empty()) {
        parser.AddLine(piece);
      } else {
        pending.append(piece);
        parser.AddLine(pending);
        pending.clear();
      }
      begin = end + 1;
    }
  }
  if (!pending.empty()) parser.AddLine(pending);
}

}  // namespace

Correspondences CorrespondencesFromCsvText(const std::string& text, const std::string& source,
                                           const CorrespondencesLimits& limits) {
  limits.Check();
  CsvParser parser(source, limits);
  ParseText(text, parser);
  return parser.Finish();
}

Correspondences ReadCorrespondencesFile(const std::string& path,
                                        const CorrespondencesLimits& limits) {
  limits.Check();
  CsvParser parser(path, limits);
  ParseFile(path, limits, parser);
  return parser.Finish();
}

std::vector<CorrespondencesView> CorrespondencesViewsFromCsvText(
    const std::string& text, const std::string& source, const CorrespondencesLimits& limits) {
  limits.Check();
  CsvParser parser(source, limits, /*by_view=*/true);
  ParseText(text, parser);
  return parser.FinishViews();
}

std::vector<CorrespondencesView> ReadCorrespondencesViewsFile(
    const std::string& path, const CorrespondencesLimits& limits) {
  limits.Check();
  CsvParser parser(path, limits, /*by_view=*/true);
  ParseFile(path, limits, parser);
  return parser.FinishViews();
}

void CheckPointIds(const std::vector<std::string>& ids) {
  std::unordered_map<std::string_view, size_t> index_of_id;
  for (size_t i = 0; i < ids.size(); ++i) {
    const std::string problem = IdProblem(ids[i]);
    // Points numbered from 1, as the file's rows and the summary number them.
    internal::Require(problem.empty(), "id ", Quoted(ids[i]), " (point ", i + 1, ") ", problem);
    const auto [it, inserted] = index_of_id.emplace(ids[i], i);
    internal::Require(inserted, "id ", Quoted(ids[i]), " is repeated (points ", it->second + 1,
                      " and ", i + 1, ")");
  }
}

std::string CorrespondencesToCsvText(const Correspondences& correspondences) {
  const Correspondences& c = correspondences;
  const size_t n = c.points_in_world.size();
  internal::Require(n > 0, "no correspondences to write");
  internal::Require(c.pixels.size() == n, "points_in_world has ", n, " entries but pixels has ",
                    c.pixels.size());
  internal::Require(c.ids.empty() || c.ids.size() == n, "points_in_world has ", n,
                    " entries but ids has ", c.ids.size());
  CheckPointIds(c.ids);
  bool write_ids = false;
  for (size_t i = 0; i < c.ids.size(); ++i) {
    write_ids = write_ids || c.ids[i] != std::to_string(i + 1);
  }
  std::string text = write_ids ? "X,Y,Z,u,v,id\n" : "X,Y,Z,u,v\n";
  for (size_t i = 0; i < n; ++i) {
    internal::Require(c.points_in_world[i].allFinite() && c.pixels[i].allFinite(), "point ", i + 1,
                      " is not finite: X,Y,Z = ", c.points_in_world[i].transpose(),
                      ", u,v = ", c.pixels[i].transpose());
    const double values[] = {c.points_in_world[i].x(), c.points_in_world[i].y(),
                             c.points_in_world[i].z(), c.pixels[i].x(), c.pixels[i].y()};
    for (size_t k = 0; k < 5; ++k) {
      if (k > 0) text += ',';
      AppendNumber(values[k], text);
    }
    if (write_ids) text += "," + c.ids[i];
    text += '\n';
  }
  return text;
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace camproj
