// The correspondences file: CSV text pairing world points with the pixels they are seen at.
//
//   # comments: lines whose first non-blank character is '#'
//   id,X,Y,Z,u,v
//   corner_a, 0.1, -0.2, -2.0, 364.77, 251.37
//
// The first line that is neither blank nor a comment is the header. It names the columns X, Y, Z
// (the point in the world frame, user units) and u, v (the pixel, see conventions.h), in any order
// and case-sensitively; an optional `id` column names each point in reports; other columns
// (also `view`, except for the reader by view below) are ignored. Every following line that is
// neither blank nor a comment is a data row with exactly as many fields as the header. Fields are
// split at every comma (there is no quoting) and spaces or tabs around a field are dropped. Lines
// end in LF or CRLF; a UTF-8 byte-order mark before the header is skipped. Rows whose fields are
// all empty (spreadsheets write ",,,,") count as blank.
//
// Several views in one file (ReadCorrespondencesViewsFile, for `camproj calibrate`): a column
// named `view` groups the rows into views by its text; each view has its own world frame, so the
// same id may appear once in every view:
//   view,id,X,Y,Z,u,v
//   left01,1,0,0,0,244.41,94.14
//   left03,1,0,0,0,153.88,65.27
//
// The reader takes pixels as they are written: which pixel origin they follow is for the caller
// to state (docs/conventions.md, "pixel"); nothing here converts them.
#ifndef CAMPROJ_POINTS_FILE_H_
#define CAMPROJ_POINTS_FILE_H_

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace camproj {

// One entry per data row, in file order; all four vectors have the same length.
struct Correspondences {
  std::vector<Eigen::Vector3d> points_in_world;  // X, Y, Z
  std::vector<Eigen::Vector2d> pixels;           // u, v, in the file's pixel origin
  // The id column's text, or the 1-based number of the data row ("1", "2", ...) without one.
  // Ids are non-empty and unique.
  std::vector<std::string> ids;
  std::vector<int> line_numbers;  // 1-based line in the file of each row, for messages
};

// Bounds that refuse a wrong or hostile file before it exhausts memory.
struct CorrespondencesLimits {
  size_t max_line_bytes = size_t{1} << 20;  // per line, without the line ending
  size_t max_points = 50'000'000;           // data rows
  // false: the file is read as points only, with pixels (0, 0): u and v columns are neither
  // required nor read (a point with an empty u, as `camproj project` writes one behind the
  // camera, is a point).
  bool read_pixels = true;
  void Check() const;  // throws std::invalid_argument unless both are positive
};

// Parses correspondences text; `source` names it in messages ("cam0.csv"). Numbers are read
// locale-independently, as std::from_chars reads them (plus an optional leading '+'); the whole
// field must be a number. Throws InputError naming the source and the line, and for a bad field
// its 1-based column and name, on: an empty file or one without a header; a header that lacks one
// of X,Y,Z,u,v or repeats a column name; no data rows; a row with fewer or more fields than the
// header; a field that is not a number, or is infinite, NaN or outside a double's range; an empty
// or repeated id; a line longer than limits.max_line_bytes; more than limits.max_points rows.
// Example: "cam0.csv: line 7, column 4 (u): expected a number, got \"abc\"".
Correspondences CorrespondencesFromCsvText(const std::string& text, const std::string& source,
                                           const CorrespondencesLimits& limits = {});

// Reads the file at `path` (named in messages) as CorrespondencesFromCsvText does, streaming it:
// memory stays bounded by one line and the rows kept, so a line over limits.max_line_bytes fails
// after reading about that many bytes, whatever the file's size. Throws InputError also when the
// file cannot be opened or read.
Correspondences ReadCorrespondencesFile(const std::string& path,
                                        const CorrespondencesLimits& limits = {});

// The rows of one view of a file read by view.
struct CorrespondencesView {
  std::string name;  // the `view` column's text; "" for a file without that column
  // The view's rows in file order (line_numbers are the file's). Without an id column the ids
  // number the view's rows ("1", "2", ...), as if the view were a file of its own.
  Correspondences correspondences;
};

// Parses correspondences text as CorrespondencesFromCsvText does, but grouped into views by a
// column named `view`: one entry per distinct view name, in order of first appearance (a view's
// rows need not be adjacent). Ids must be unique within a view only. A file without a `view`
// column is one view named "", exactly what CorrespondencesFromCsvText returns. Throws InputError
// as CorrespondencesFromCsvText does, and also on an empty view field; a repeated id names its
// view: "all.csv: line 9, column 2 (id): duplicate id \"3\" in view \"left03\" (also on line 5)".
// limits.max_points bounds the rows of all views together.
std::vector<CorrespondencesView> CorrespondencesViewsFromCsvText(
    const std::string& text, const std::string& source, const CorrespondencesLimits& limits = {});

// Reads the file at `path` as CorrespondencesViewsFromCsvText reads text, streaming it as
// ReadCorrespondencesFile does.
std::vector<CorrespondencesView> ReadCorrespondencesViewsFile(
    const std::string& path, const CorrespondencesLimits& limits = {});

// Throws std::invalid_argument naming the first id that would not read back from a points file:
// one that is empty, repeated, contains a comma or line break, or has surrounding spaces or tabs
// ("id \"a,b\" (point 3) contains a comma or line break"; points numbered from 1).
void CheckPointIds(const std::vector<std::string>& ids);

// The file text: header "X,Y,Z,u,v", plus ",id" when `ids` is non-empty and differs from the
// default numbering "1", "2", ...; one row per point; doubles in the shortest form that reads back
// bit for bit. line_numbers is ignored. Throws std::invalid_argument when the sizes disagree,
// there are no points, a value is not finite, or an id would not read back (CheckPointIds).
std::string CorrespondencesToCsvText(const Correspondences& correspondences);

// A field of a CSV file camproj writes (overlay's labels, calibrate's poses) as RFC 4180 writes
// it: quoted, its quotes doubled, where it holds a comma, a quote or a line break; as it is
// otherwise. (Points files are read unquoted: see CorrespondencesFromCsvText.)
std::string CsvField(const std::string& text);

}  // namespace camproj

#endif  // CAMPROJ_POINTS_FILE_H_
