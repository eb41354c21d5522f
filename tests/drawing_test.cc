// The markup and geometry helpers the overlay and the report share (lib/src/drawing.h): text cut
// and escaped by UTF-8 character, never by byte, and border arrows on images of any size.

#include "drawing.h"

#include <string>

#include <gtest/gtest.h>

namespace camproj::internal {
namespace {

TEST(DrawingTest, Utf8CharLengthFollowsRfc3629) {
  EXPECT_EQ(Utf8CharLength("a", 0), 1u);
  EXPECT_EQ(Utf8CharLength("\xC3\xBC", 0), 2u);          // u-umlaut
  EXPECT_EQ(Utf8CharLength("\xE2\x82\xAC", 0), 3u);      // euro sign
  EXPECT_EQ(Utf8CharLength("\xF0\x9F\x93\xB7", 0), 4u);  // camera emoji
  EXPECT_EQ(Utf8CharLength("\xFC" "d", 0), 0u);          // Latin-1 u-umlaut
  EXPECT_EQ(Utf8CharLength("\xBC", 0), 0u);              // a lone continuation byte
  EXPECT_EQ(Utf8CharLength("\xC3", 0), 0u);              // cut at the end of the text
  EXPECT_EQ(Utf8CharLength("\xC0\xAF", 0), 0u);          // overlong '/'
  EXPECT_EQ(Utf8CharLength("\xED\xA0\x80", 0), 0u);      // a UTF-16 surrogate
  EXPECT_EQ(Utf8CharLength("\xF4\x90\x80\x80", 0), 0u);  // beyond U+10FFFF
}

TEST(DrawingTest, Utf8PrefixCutsBetweenCharacters) {
  // 11 ASCII characters then a two-byte one: 12 characters are 13 bytes, a byte cut at 12 split it.
  const std::string id = "corner_nord\xC3\xBC" "1";
  EXPECT_EQ(Utf8Prefix(id, 12), "corner_nord\xC3\xBC");
  EXPECT_EQ(Utf8Prefix(id, 11), "corner_nord");
  EXPECT_EQ(Utf8Prefix(id, 100), id);
  EXPECT_EQ(Utf8Prefix("", 3), "");
  // A byte that begins no character counts as one.
  EXPECT_EQ(Utf8Prefix("S\xFC" "d-1", 2), "S\xFC");
}

TEST(DrawingTest, MarkupEscapeWritesOnlyWellFormedUtf8) {
  EXPECT_EQ(MarkupEscape("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
  EXPECT_EQ(MarkupEscape("S\xC3\xBC" "d"), "S\xC3\xBC" "d");
  EXPECT_EQ(MarkupEscape("S\xFC" "d"), "S\xEF\xBF\xBD" "d");
  EXPECT_EQ(MarkupEscape("x\xC3"), "x\xEF\xBF\xBD");
}

// The arrow stays inside the image and points at the target for every image size, down to those
// smaller than two arrow lengths (std::clamp's bounds crossed there: undefined behaviour).
TEST(DrawingTest, BorderArrowsStayInsideImagesOfAnySize) {
  constexpr double kLength = 24.0;
  constexpr double kExact = 1e-12;  // px: a clamp and one normalisation
  for (const auto& [w, h] : {std::pair{1000, 800}, std::pair{30, 20}, std::pair{1, 1}}) {
    for (const Eigen::Vector2d& target : {Eigen::Vector2d(-50.0, 10.0), Eigen::Vector2d(5000.0, -3.0),
                                         Eigen::Vector2d(12.0, 1e6)}) {
      const auto [tail, tip] = BorderArrow(target, w, h, kLength);
      EXPECT_GE(tip.x(), 0.0);
      EXPECT_LE(tip.x(), w - 1.0);
      EXPECT_GE(tip.y(), 0.0);
      EXPECT_LE(tip.y(), h - 1.0);
      EXPECT_NEAR((tip - tail).norm(), kLength, kExact);
      // The tail-to-tip direction is the tip-to-target one.
      const Eigen::Vector2d along = (tip - tail).normalized(), to_target = (target - tip).normalized();
      EXPECT_NEAR(along.dot(to_target), 1.0, kExact) << w << "x" << h;
    }
  }
  // On a 30 x 20 image the margins are half the image: the tip is its middle on the short axis.
  const auto [tail, tip] = BorderArrow(Eigen::Vector2d(14.5, -100.0), 30, 20, kLength);
  EXPECT_NEAR(tip.x(), 14.5, kExact);
  EXPECT_NEAR(tip.y(), 9.5, kExact);
}

}  // namespace
}  // namespace camproj::internal
