#include "camproj/points_file.h"
#include "seeds.h"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "camproj/errors.h"

namespace camproj {
namespace {

// Real correspondences bundled with the project (provenance in data/real/README.md).
const std::string kRealData = CAMPROJ_DATA_DIR "/real";

uint64_t Bits(double value) {
  uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// A folder of its own for each test, removed afterwards.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("camproj_points_" + name + "_" + std::to_string(getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string Write(const std::string& name, const std::string& contents) const {
    const std::string file = (path_ / name).string();
    std::ofstream(file, std::ios::binary) << contents;
    return file;
  }
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

// The message of the InputError that parsing `text` as "pts.csv" throws.
std::string ParseError(const std::string& text, const CorrespondencesLimits& limits = {}) {
  try {
    CorrespondencesFromCsvText(text, "pts.csv", limits);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return "";
}

void ExpectContainsAll(const std::string& message, std::initializer_list<const char*> parts) {
  for (const char* part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "\"" << part << "\" not in: " << message;
  }
}

TEST(PointsFileTest, ReadsTheRealBalbianelloAndChessboardFiles) {
  const std::string balbianello = kRealData + "/balbianello/cam0.csv";
  const std::string chessboard = kRealData + "/opencv_chessboard/left01.csv";
  const Correspondences b = ReadCorrespondencesFile(balbianello);
  ASSERT_EQ(b.points_in_world.size(), 279u);
  ASSERT_EQ(b.pixels.size(), 279u);
  ASSERT_EQ(b.ids.size(), 279u);
  ASSERT_EQ(b.line_numbers.size(), 279u);
  // Values as written in the file: the reader must not convert them.
  EXPECT_EQ(b.points_in_world[0], Eigen::Vector3d(0.10348687869, -0.12489429393, -2.015388832));
  EXPECT_EQ(b.pixels[0], Eigen::Vector2d(364.77, 251.37));
  EXPECT_EQ(b.points_in_world[278], Eigen::Vector3d(2.0214024246, 1.9591551936, -8.8957122689));
  EXPECT_EQ(b.pixels[278], Eigen::Vector2d(435.57, 99.14));
  EXPECT_EQ(b.ids[0], "1");
  EXPECT_EQ(b.ids[278], "279");
  EXPECT_EQ(b.line_numbers[0], 2);
  EXPECT_EQ(b.line_numbers[278], 280);

  const Correspondences c = ReadCorrespondencesFile(chessboard);
  ASSERT_EQ(c.pixels.size(), 54u);
  EXPECT_EQ(c.points_in_world[0], Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(c.pixels[0], Eigen::Vector2d(244.4052734375, 94.13685607910156));
  EXPECT_EQ(c.points_in_world[53], Eigen::Vector3d(8, 5, 0));
  EXPECT_EQ(c.pixels[53], Eigen::Vector2d(510.3648986816406, 266.2024841308594));
  EXPECT_EQ(c.line_numbers[53], 55);
}

TEST(PointsFileTest, ColumnsInAnyOrderAndExtraColumnsAreIgnored) {
  const Correspondences c = CorrespondencesFromCsvText(
      "note,v,u,Z,Y,X,,weight\n"
      "first,5,4,3,2,1,,0.5\n"
      "second,-5,-4,-3,-2,-1,,abc\n",
      "t");
  ASSERT_EQ(c.pixels.size(), 2u);
  EXPECT_EQ(c.points_in_world[0], Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(c.pixels[0], Eigen::Vector2d(4, 5));
  EXPECT_EQ(c.points_in_world[1], Eigen::Vector3d(-1, -2, -3));
  EXPECT_EQ(c.pixels[1], Eigen::Vector2d(-4, -5));
  // Without an id column the ids number the data rows.
  EXPECT_EQ(c.ids, (std::vector<std::string>{"1", "2"}));
}

TEST(PointsFileTest, IdColumnIsCarried) {
  const Correspondences c = CorrespondencesFromCsvText(
      "X,Y,Z,id,u,v\n"
      "1,2,3, corner a ,4,5\n"
      "# a comment between rows\n"
      "6,7,8,17,9,10\n",
      "t");
  EXPECT_EQ(c.ids, (std::vector<std::string>{"corner a", "17"}));
  EXPECT_EQ(c.line_numbers, (std::vector<int>{2, 4}));
}

TEST(PointsFileTest, CommentsBlankLinesCrlfSpacesAndByteOrderMarkAreAccepted) {
  const Correspondences c = CorrespondencesFromCsvText(
      "\xEF\xBB\xBF# exported by a spreadsheet\r\n"
      "\r\n"
      "   # indented comment\r\n"
      " X , Y ,\tZ\t, u , v \r\n"
      "\r\n"
      "  1 , 2 , 3 , +4.5 , -5e-1 \r\n"
      ",,,,\r\n"
      "\t \r\n"
      "1e2,.5,5.,0,-0\r\n"
      "# trailing comment without a line ending",
      "t");
  ASSERT_EQ(c.pixels.size(), 2u);
  EXPECT_EQ(c.points_in_world[0], Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(c.pixels[0], Eigen::Vector2d(4.5, -0.5));
  EXPECT_EQ(c.points_in_world[1], Eigen::Vector3d(100, 0.5, 5));
  EXPECT_EQ(Bits(c.pixels[1].y()), Bits(-0.0));
  EXPECT_EQ(c.line_numbers, (std::vector<int>{6, 9}));
  EXPECT_EQ(c.ids, (std::vector<std::string>{"1", "2"}));
}

TEST(PointsFileTest, MalformedFilesNameTheSourceLineAndColumn) {
  const std::string header = "X,Y,Z,u,v\n";
  ExpectContainsAll(ParseError(header + "1,2,3,4,5\n\n# c\n1,2,3,abc,5\n"),
                    {"pts.csv", "line 5, column 4 (u): expected a number, got \"abc\""});
  ExpectContainsAll(ParseError(header + "1,2,3,1.5x,5\n"),
                    {"pts.csv", "line 2, column 4 (u): expected a number, got \"1.5x\""});
  ExpectContainsAll(ParseError(header + "1,,3,4,5\n"),
                    {"pts.csv", "line 2, column 2 (Y): expected a number, got \"\""});
  ExpectContainsAll(ParseError(header + "1,2,3,4,0x10\n"), {"pts.csv", "line 2, column 5 (v)"});
  ExpectContainsAll(ParseError(header + "1,2,3,4,++5\n"), {"pts.csv", "line 2, column 5 (v)"});
  ExpectContainsAll(ParseError(header + "1,2,nan,4,5\n"),
                    {"pts.csv", "line 2, column 3 (Z): \"nan\" is not finite"});
  ExpectContainsAll(ParseError(header + "-inf,2,3,4,5\n"),
                    {"pts.csv", "line 2, column 1 (X): \"-inf\" is not finite"});
  // Lines ended by CR alone (classic Mac OS): one line with CRs inside, said as such (it read
  // "header lacks column v" before session 37).
  ExpectContainsAll(ParseError("X,Y,Z,u,v\r1,2,3,4,5\r"),
                    {"pts.csv", "line 1: a carriage return (CR) inside the line", "LF or CRLF"});
  ExpectContainsAll(ParseError(header + "1,2,3,4,5\r1,2,3,4,5\n"),
                    {"pts.csv", "line 2: a carriage return (CR) inside the line"});
  ExpectContainsAll(ParseError(header + "1e400,2,3,4,5\n"),
                    {"pts.csv", "line 2, column 1 (X): \"1e400\" is out of the range of a double"});
  ExpectContainsAll(ParseError("X,Y,Z,u\n1,2,3,4\n"),
                    {"pts.csv", "line 1: header lacks column v; it has X,Y,Z,u"});
  ExpectContainsAll(ParseError("# c\nX,Z,v\n1,2,3\n"),
                    {"pts.csv", "line 2: header lacks columns Y,u; it has X,Z,v"});
  ExpectContainsAll(ParseError("x,y,z,u,v\n1,2,3,4,5\n"),
                    {"pts.csv", "line 1", "lacks columns X,Y,Z", "case-sensitive"});
  ExpectContainsAll(ParseError("X;Y;Z;u;v\n1;2;3;4;5\n"),
                    {"pts.csv", "line 1", "separated by commas"});
  ExpectContainsAll(ParseError("1,2,3,4,5\n"), {"pts.csv", "line 1", "must be the header"});
  ExpectContainsAll(ParseError("X,Y,Z,u,v,u\n1,2,3,4,5,6\n"),
                    {"pts.csv", "line 1, column 6 (u): duplicate column name; column 4 is also u"});
  ExpectContainsAll(
      ParseError(header + "1,2,3,4,5\n1,2,3,4\n"),
      {"pts.csv", "line 3: 4 fields, but the header (line 1) has 5; column 5 (v) is missing"});
  ExpectContainsAll(
      ParseError(header + "1,2,3,4,5,6\n"),
      {"pts.csv",
       "line 2: 6 fields, but the header (line 1) has 5; column 6 is not in the header"});
  ExpectContainsAll(ParseError(""), {"pts.csv", "empty file", "X,Y,Z,u,v"});
  ExpectContainsAll(ParseError("\n  \r\n"), {"pts.csv", "empty file"});
  ExpectContainsAll(ParseError("# only\n# comments\n"), {"pts.csv", "no header", "X,Y,Z,u,v"});
  ExpectContainsAll(ParseError("# c\nX,Y,Z,u,v\n# c\n\n"),
                    {"pts.csv", "the header (line 2) is followed by no data rows"});
  ExpectContainsAll(ParseError("id,X,Y,Z,u,v\n,1,2,3,4,5\n"),
                    {"pts.csv", "line 2, column 1 (id): empty id"});
  ExpectContainsAll(ParseError("id,X,Y,Z,u,v\na,1,2,3,4,5\nb,1,2,3,4,5\na,1,2,3,4,5\n"),
                    {"pts.csv", "line 4, column 1 (id): duplicate id \"a\" (also on line 2)"});
  // Control bytes are escaped and long text cut short in messages.
  const std::string message = ParseError(header + "1,2,3,\x01" + std::string(500, '7') + "z,5\n");
  ExpectContainsAll(message, {"line 2, column 4 (u)", "\\x01", "...\""});
  EXPECT_LT(message.size(), 200u);
}

TEST(PointsFileTest, LimitsOnLineLengthAndRowCount) {
  CorrespondencesLimits limits;
  limits.max_line_bytes = 9;
  // "X,Y,Z,u,v" is exactly 9 bytes; the '\r' of CRLF does not count.
  EXPECT_EQ(CorrespondencesFromCsvText("X,Y,Z,u,v\r\n1,2,3,4,5\r\n", "t", limits).pixels.size(),
            1u);
  ExpectContainsAll(ParseError("X,Y,Z,u,v\n1,2,3,4,50\n", limits),
                    {"pts.csv: line 2 is longer than 9 bytes"});
  limits = {};
  limits.max_points = 2;
  EXPECT_EQ(CorrespondencesFromCsvText("X,Y,Z,u,v\n1,2,3,4,5\n1,2,3,4,5\n", "t", limits).ids.size(),
            2u);
  ExpectContainsAll(ParseError("X,Y,Z,u,v\n1,2,3,4,5\n1,2,3,4,5\n1,2,3,4,5\n", limits),
                    {"pts.csv: line 4: more than 2 data rows"});
  limits.max_points = 0;
  EXPECT_THROW(CorrespondencesFromCsvText("X,Y,Z,u,v\n1,2,3,4,5\n", "t", limits),
               std::invalid_argument);
}

TEST(PointsFileTest, WritingThenReadingGivesBitIdenticalDoubles) {
  std::mt19937_64 rng(testing::Seed(11));
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<uint64_t> any_bits;
  Correspondences c;
  const double specials[] = {0.0,
                             -0.0,
                             0.1,
                             1.0 / 3.0,
                             std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::lowest(),
                             std::numeric_limits<double>::min(),
                             std::numeric_limits<double>::denorm_min(),
                             -1e-310,
                             123456789.125};
  auto next = [&](int i) {
    if (i % 3 == 0) return specials[static_cast<size_t>(i / 3) % std::size(specials)];
    if (i % 3 == 1) {
      // Two statements: the order of a product's operands is unspecified.
      const double mantissa = unit(rng);
      return mantissa * std::pow(10.0, static_cast<int>(unit(rng) * 20));
    }
    double value = 0;
    do {
      const uint64_t bits = any_bits(rng);
      std::memcpy(&value, &bits, sizeof value);
    } while (!std::isfinite(value));
    return value;
  };
  for (int i = 0; i < 2000; i += 5) {
    c.points_in_world.emplace_back(next(i), next(i + 1), next(i + 2));
    c.pixels.emplace_back(next(i + 3), next(i + 4));
  }
  const auto expect_same = [&](const Correspondences& back) {
    ASSERT_EQ(back.pixels.size(), c.pixels.size());
    for (size_t i = 0; i < c.pixels.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        ASSERT_EQ(Bits(back.points_in_world[i][k]), Bits(c.points_in_world[i][k])) << i;
      }
      for (int k = 0; k < 2; ++k) ASSERT_EQ(Bits(back.pixels[i][k]), Bits(c.pixels[i][k])) << i;
    }
  };

  // No ids, or the default numbering: no id column.
  std::string text = CorrespondencesToCsvText(c);
  EXPECT_EQ(text.substr(0, 10), "X,Y,Z,u,v\n");
  Correspondences back = CorrespondencesFromCsvText(text, "t");
  expect_same(back);
  EXPECT_EQ(CorrespondencesToCsvText(back), text);

  for (size_t i = 0; i < c.pixels.size(); ++i) c.ids.push_back("p #" + std::to_string(i * 7));
  text = CorrespondencesToCsvText(c);
  EXPECT_EQ(text.substr(0, 13), "X,Y,Z,u,v,id\n");
  back = CorrespondencesFromCsvText(text, "t");
  expect_same(back);
  EXPECT_EQ(back.ids, c.ids);
  // Shortest round-trip form, not 17 digits: 0.1 stays readable.
  EXPECT_NE(text.find(",0.1,"), std::string::npos);
}

TEST(PointsFileTest, WritingRefusesWhatWouldNotReadBack) {
  Correspondences c;
  EXPECT_THROW(CorrespondencesToCsvText(c), std::invalid_argument);
  c.points_in_world = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6)};
  c.pixels = {Eigen::Vector2d(1, 2)};
  EXPECT_THROW(CorrespondencesToCsvText(c), std::invalid_argument);
  c.pixels.emplace_back(3, std::nan(""));
  EXPECT_THROW(CorrespondencesToCsvText(c), std::invalid_argument);
  c.pixels[1].y() = 4;
  EXPECT_NO_THROW(CorrespondencesToCsvText(c));
  for (const auto& ids : std::vector<std::vector<std::string>>{
           {"a"}, {"a", ""}, {"a", "b,c"}, {"a", "b\n"}, {"a", " b"}, {"a", "a"}}) {
    c.ids = ids;
    EXPECT_THROW(CorrespondencesToCsvText(c), std::invalid_argument) << ids.back();
  }
}

// Points numbered from 1, as the file's rows are; the first problem is named.
TEST(PointsFileTest, CheckPointIdsNamesTheIdAndThePoint) {
  const auto message = [](const std::vector<std::string>& ids) {
    try {
      CheckPointIds(ids);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({"a", "b", "c1"}), "accepted");
  EXPECT_EQ(message({}), "accepted");
  EXPECT_EQ(message({"a", ""}), "id \"\" (point 2) is empty");
  EXPECT_EQ(message({"a", "b", "c,d"}), "id \"c,d\" (point 3) contains a comma or line break");
  EXPECT_EQ(message({"a\r"}), "id \"a\\x0d\" (point 1) contains a comma or line break");
  EXPECT_EQ(message({"a", "b "}), "id \"b \" (point 2) has surrounding spaces or tabs");
  EXPECT_EQ(message({"x", "a", "b", "a"}), "id \"a\" is repeated (points 2 and 4)");
  Correspondences c;
  c.points_in_world = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6)};
  c.pixels = {Eigen::Vector2d(1, 2), Eigen::Vector2d(3, std::nan(""))};
  try {
    CorrespondencesToCsvText(c);
    ADD_FAILURE() << "wrote a NaN";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("point 2 is not finite", 0), 0u) << e.what();
  }
}

TEST(PointsFileTest, StreamedFileMatchesTextAcrossBufferBoundaries) {
  const TempDir dir("stream");
  // CRLF rows spanning well over one 64 KiB read, so lines straddle the buffer edge.
  std::string text = "# generated\r\nid,X,Y,Z,u,v\r\n";
  for (int i = 0; i < 5000; ++i) {
    text += "pt" + std::to_string(i) + "," + std::to_string(i) + ".25,-1,2,3.5," +
            std::to_string(i % 640) + "\r\n";
  }
  text += "last,1,2,3,4,5";  // no final line ending
  const std::string path = dir.Write("many.csv", text);
  const Correspondences from_file = ReadCorrespondencesFile(path);
  const Correspondences from_text = CorrespondencesFromCsvText(text, path);
  ASSERT_EQ(from_file.pixels.size(), 5001u);
  EXPECT_EQ(from_file.points_in_world, from_text.points_in_world);
  EXPECT_EQ(from_file.pixels, from_text.pixels);
  EXPECT_EQ(from_file.ids, from_text.ids);
  EXPECT_EQ(from_file.line_numbers, from_text.line_numbers);
  EXPECT_EQ(from_file.ids.back(), "last");
  EXPECT_EQ(from_file.line_numbers.back(), 5003);

  // Errors from a file name its path.
  const std::string bad = dir.Write("bad.csv", "X,Y,Z,u,v\r\n1,2,3,4,oops\r\n");
  try {
    ReadCorrespondencesFile(bad);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    ExpectContainsAll(e.what(),
                      {bad.c_str(), "line 2, column 5 (v): expected a number, got \"oops\""});
  }
}

TEST(PointsFileTest, StreamedFileWithAnOverlongLineFailsCleanly) {
  const TempDir dir("long");
  const std::string path = dir.Write(
      "long.csv", "X,Y,Z,u,v\n1,2,3,4,5\n" + std::string(size_t{2} << 20, '7') + "\n1,2,3,4,5\n");
  try {
    ReadCorrespondencesFile(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": line 3 is longer than 1048576 bytes");
  }
  // The same bound with a small limit, at the exact edge, through the streaming path.
  CorrespondencesLimits limits;
  limits.max_line_bytes = 9;
  const std::string edge = dir.Write("edge.csv", "X,Y,Z,u,v\r\n1,2,3,4,5\r\n");
  EXPECT_EQ(ReadCorrespondencesFile(edge, limits).pixels.size(), 1u);
  const std::string over = dir.Write("over.csv", "X,Y,Z,u,v\r\n1,2,3,4,5\r\n1,2,3,4,50\r\n");
  try {
    ReadCorrespondencesFile(over, limits);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), over + ": line 3 is longer than 9 bytes");
  }
  // No bound at all: max_line_bytes + 1 wrapped to 0 and refused every line.
  limits.max_line_bytes = std::numeric_limits<size_t>::max();
  EXPECT_EQ(ReadCorrespondencesFile(over, limits).pixels.size(), 2u);
}

TEST(PointsFileTest, UnreadablePathsNameThePath) {
  const TempDir dir("paths");
  try {
    ReadCorrespondencesFile(dir.path() + "/missing.csv");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    ExpectContainsAll(e.what(), {"missing.csv: cannot open"});
  }
  EXPECT_THROW(ReadCorrespondencesFile(dir.path()), InputError);
  ExpectContainsAll(
      [&] {
        try {
          ReadCorrespondencesFile(dir.Write("empty.csv", ""));
        } catch (const InputError& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      {"empty.csv: empty file"});
}

// The message of the InputError that parsing `text` by view as "all.csv" throws.
std::string ViewsParseError(const std::string& text) {
  try {
    CorrespondencesViewsFromCsvText(text, "all.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return "";
}

TEST(PointsFileTest, ViewColumnGroupsRowsByFirstAppearanceAndIdsRepeatAcrossViews) {
  const std::string text =
      "view,id,X,Y,Z,u,v\n"
      "b,p1,1,2,3,4,5\n"
      "a,p1,6,7,8,9,10\n"
      "# a comment\n"
      "b,p2,11,12,13,14,15\n"
      "a,p2,16,17,18,19,20\n"
      "c,p1,21,22,23,24,25\n";
  const std::vector<CorrespondencesView> views = CorrespondencesViewsFromCsvText(text, "t");
  ASSERT_EQ(views.size(), 3u);
  EXPECT_EQ(views[0].name, "b");
  EXPECT_EQ(views[1].name, "a");
  EXPECT_EQ(views[2].name, "c");
  EXPECT_EQ(views[0].correspondences.ids, (std::vector<std::string>{"p1", "p2"}));
  EXPECT_EQ(views[0].correspondences.line_numbers, (std::vector<int>{2, 5}));
  EXPECT_EQ(views[0].correspondences.points_in_world[1], Eigen::Vector3d(11, 12, 13));
  EXPECT_EQ(views[0].correspondences.pixels[1], Eigen::Vector2d(14, 15));
  EXPECT_EQ(views[1].correspondences.ids, (std::vector<std::string>{"p1", "p2"}));
  EXPECT_EQ(views[1].correspondences.line_numbers, (std::vector<int>{3, 6}));
  EXPECT_EQ(views[1].correspondences.points_in_world[0], Eigen::Vector3d(6, 7, 8));
  EXPECT_EQ(views[2].correspondences.pixels, (std::vector<Eigen::Vector2d>{{24, 25}}));
  // The plain reader ignores the view column, so its ids must be unique in the whole file.
  EXPECT_NE(ParseError(text).find("pts.csv: line 3, column 2 (id): duplicate id \"p1\" (also on "
                                  "line 2)"),
            std::string::npos);
}

TEST(PointsFileTest, ViewsWithoutAnIdColumnNumberTheirOwnRows) {
  const std::vector<CorrespondencesView> views = CorrespondencesViewsFromCsvText(
      "X,Y,Z,u,v,view\n1,2,3,4,5,a\n1,2,3,4,5,b\n1,2,3,4,5,a\n", "t");
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[0].correspondences.ids, (std::vector<std::string>{"1", "2"}));
  EXPECT_EQ(views[1].correspondences.ids, (std::vector<std::string>{"1"}));
}

TEST(PointsFileTest, FileWithoutViewColumnIsOneUnnamedView) {
  const std::string text = "id,X,Y,Z,u,v\nq,1,2,3,4,5\nr,6,7,8,9,10\n";
  const std::vector<CorrespondencesView> views = CorrespondencesViewsFromCsvText(text, "t");
  const Correspondences plain = CorrespondencesFromCsvText(text, "t");
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].name, "");
  EXPECT_EQ(views[0].correspondences.ids, plain.ids);
  EXPECT_EQ(views[0].correspondences.points_in_world, plain.points_in_world);
  EXPECT_EQ(views[0].correspondences.pixels, plain.pixels);
  EXPECT_EQ(views[0].correspondences.line_numbers, plain.line_numbers);
}

TEST(PointsFileTest, ViewErrorsNameTheSourceLineAndColumn) {
  EXPECT_EQ(ViewsParseError("view,id,X,Y,Z,u,v\na,1,1,2,3,4,5\nb,1,1,2,3,4,5\na,1,1,2,3,4,5\n"),
            "all.csv: line 4, column 2 (id): duplicate id \"1\" in view \"a\" (also on line 2)");
  EXPECT_EQ(ViewsParseError("view,X,Y,Z,u,v\na,1,2,3,4,5\n ,1,2,3,4,5\n"),
            "all.csv: line 3, column 1 (view): empty view name");
  EXPECT_EQ(ViewsParseError("view,X,Y,Z,u,v\na,1,2,x,4,5\n"),
            "all.csv: line 2, column 4 (Z): expected a number, got \"x\"");
  EXPECT_EQ(ViewsParseError("view,X,Y,Z,u,v\n"),
            "all.csv: the header (line 1) is followed by no data rows");
  CorrespondencesLimits limits;
  limits.max_points = 2;  // all views together
  try {
    CorrespondencesViewsFromCsvText("view,X,Y,Z,u,v\na,1,2,3,4,5\nb,1,2,3,4,5\nc,1,2,3,4,5\n",
                                    "all.csv", limits);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "all.csv: line 4: more than 2 data rows");
  }
}

TEST(PointsFileTest, StreamedViewsMatchText) {
  const TempDir dir("views");
  std::string text = "view,id,X,Y,Z,u,v\r\n";
  for (int i = 0; i < 3000; ++i) {
    text += "v" + std::to_string(i % 7) + "," + std::to_string(i / 7) + "," + std::to_string(i) +
            ".5,1,2,3," + std::to_string(i % 640) + "\r\n";
  }
  const std::string path = dir.Write("all.csv", text);
  const std::vector<CorrespondencesView> from_file = ReadCorrespondencesViewsFile(path);
  const std::vector<CorrespondencesView> from_text = CorrespondencesViewsFromCsvText(text, path);
  ASSERT_EQ(from_file.size(), 7u);
  ASSERT_EQ(from_text.size(), 7u);
  for (size_t v = 0; v < 7; ++v) {
    EXPECT_EQ(from_file[v].name, "v" + std::to_string(v));
    EXPECT_EQ(from_file[v].name, from_text[v].name);
    EXPECT_EQ(from_file[v].correspondences.points_in_world,
              from_text[v].correspondences.points_in_world);
    EXPECT_EQ(from_file[v].correspondences.pixels, from_text[v].correspondences.pixels);
    EXPECT_EQ(from_file[v].correspondences.ids, from_text[v].correspondences.ids);
    EXPECT_EQ(from_file[v].correspondences.line_numbers, from_text[v].correspondences.line_numbers);
  }
  EXPECT_EQ(from_file[6].correspondences.pixels.size(), 428u);  // 3000 = 7 * 428 + 4
  EXPECT_EQ(from_file[0].correspondences.pixels.size(), 429u);
}

}  // namespace
}  // namespace camproj
