#include "camproj/conventions.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace camproj {
namespace {

TEST(ConventionsTest, GlEyeFromCamFlipsYAndZ) {
  const Eigen::Matrix3d m = GlEyeFromCam();
  EXPECT_EQ(m, Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix());
  // A point straight ahead of the CV camera (z > 0) is at negative z in GL eye space.
  EXPECT_EQ((m * Eigen::Vector3d(0, 0, 2)).z(), -2.0);
}

TEST(ConventionsTest, PixelOriginShiftIsHalfAPixel) {
  EXPECT_EQ(PixelOriginShift(PixelOrigin::kCenter, PixelOrigin::kCorner), 0.5);
  EXPECT_EQ(PixelOriginShift(PixelOrigin::kCorner, PixelOrigin::kCenter), -0.5);
  EXPECT_EQ(PixelOriginShift(PixelOrigin::kCenter, PixelOrigin::kCenter), 0.0);
  EXPECT_EQ(PixelOriginShift(PixelOrigin::kCorner, PixelOrigin::kCorner), 0.0);
  // The centre of the top-left pixel: (0,0) in OpenCV's convention, (0.5,0.5) in COLMAP's.
  EXPECT_EQ(ConvertPixelOrigin(Eigen::Vector2d(0, 0), PixelOrigin::kCenter, PixelOrigin::kCorner),
            Eigen::Vector2d(0.5, 0.5));
}

TEST(ConventionsTest, WindowCoordinatesHaveTheirOriginAtTheBottomLeftCorner) {
  const ImageSize size{640, 480};
  // x_win = u + 0.5, y_win = H - (v + 0.5) for the default convention.
  EXPECT_EQ(WindowFromPixel({0, 0}, size), Eigen::Vector2d(0.5, 479.5));
  EXPECT_EQ(WindowFromPixel({639, 479}, size), Eigen::Vector2d(639.5, 0.5));
  EXPECT_EQ(WindowFromPixel({-0.5, 479.5}, size), Eigen::Vector2d(0, 0));
  EXPECT_EQ(WindowFromPixel({0.5, 0.5}, size, PixelOrigin::kCorner), Eigen::Vector2d(0.5, 479.5));
  EXPECT_EQ(PixelFromWindow({0.5, 479.5}, size), Eigen::Vector2d(0, 0));
  EXPECT_EQ(PixelFromWindow({0.5, 479.5}, size, PixelOrigin::kCorner), Eigen::Vector2d(0.5, 0.5));
  const Eigen::Vector2d pixel(123.25, 77.75);
  EXPECT_EQ(PixelFromWindow(WindowFromPixel(pixel, size), size), pixel);
}

// kCenter: a w x h image spans -0.5 to w - 0.5, its edges included.
TEST(ConventionsTest, PixelInImageSpansHalfAPixelBeyondTheOuterCentres) {
  EXPECT_TRUE(PixelInImage({-0.5, -0.5}, {30, 20}));
  EXPECT_TRUE(PixelInImage({29.5, 19.5}, {30, 20}));
  EXPECT_FALSE(PixelInImage({29.5 + 1e-9, 10.0}, {30, 20}));
  EXPECT_FALSE(PixelInImage({10.0, -0.5 - 1e-9}, {30, 20}));
  EXPECT_FALSE(PixelInImage({std::nan(""), 10.0}, {30, 20}));
}

TEST(ConventionsTest, StringsRoundTripAndBadTextIsNamed) {
  EXPECT_EQ(PixelOriginFromString(ToString(PixelOrigin::kCorner)), PixelOrigin::kCorner);
  EXPECT_EQ(PixelOriginFromString(ToString(PixelOrigin::kCenter)), PixelOrigin::kCenter);
  EXPECT_EQ(ClipDepthFromString(ToString(ClipDepth::kZeroToOne)), ClipDepth::kZeroToOne);
  EXPECT_EQ(ClipDepthFromString(ToString(ClipDepth::kNegativeOneToOne)),
            ClipDepth::kNegativeOneToOne);
  try {
    PixelOriginFromString("middle");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("middle"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ClipDepthFromString("01"), std::invalid_argument);
}

TEST(ConventionsTest, ZeroSizeImageIsRefused) {
  EXPECT_THROW((ImageSize{0, 480}.Check()), std::invalid_argument);
  EXPECT_THROW((ImageSize{640, -1}.Check()), std::invalid_argument);
  // The camera files' limit: a side beyond it would be written and then refused on reading.
  EXPECT_NO_THROW((ImageSize{kMaxImageSide, kMaxImageSide}.Check()));
  EXPECT_THROW((ImageSize{kMaxImageSide + 1, 480}.Check()), std::invalid_argument);
  EXPECT_THROW(WindowFromPixel({0, 0}, ImageSize{0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace camproj
