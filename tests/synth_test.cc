// SynthesizeScene (synth.h): the scene its options and header promise, on a grid of fields of
// view and seeds.
#include "camproj/synth.h"

#include <cmath>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "camproj/camera.h"
#include "camproj/pose.h"
#include "seeds.h"

namespace camproj {
namespace {

// The box's half extents (synth.cc: (1, 0.6, 0.8) * object_size / 2) and the cosine from a
// face's normal at its centre below which synth.h says the face is not used.
const Eigen::Vector3d kBoxHalf(0.5, 0.3, 0.4);
constexpr double kMinFaceCosine = 0.1;
// Noise-free pixels are the truth's projections up to double rounding of ~1e3 px values.
constexpr double kExactPx = 1e-9;

// The outward normal of the box face a point lies on (exactly: synth sets that coordinate to
// +-half).
Eigen::Vector3d FaceNormal(const Eigen::Vector3d& point) {
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(point[axis]) == kBoxHalf[axis]) {
      return Eigen::Vector3d::Unit(axis) * (point[axis] > 0 ? 1.0 : -1.0);
    }
  }
  ADD_FAILURE() << "point (" << point.transpose() << ") is on no face of the box";
  return Eigen::Vector3d::Zero();
}

// Every box point is on a face the eye sees (at more than kMinFaceCosine from the face's centre,
// and so in front of every point of it): near the box, the eye could be inside a face's slab,
// where the face is hidden (before: 13 % of the points at fovy 40, 54 % at 150, seeds 0-39).
// Noise-free pixels are the truth's projections, inside the image.
TEST(SynthTest, BoxPointsFaceTheEyeAndProjectIntoTheImage) {
  for (const double fovy_deg : {20.0, 40.0, 90.0, 150.0}) {
    for (int s = 0; s < 40; ++s) {
      SynthOptions options;
      options.seed = testing::Seed(s);
      options.num_points = 50;
      options.object = SynthObject::kBox;
      options.fovy_deg = fovy_deg;
      options.principal_point_offset = Eigen::Vector2d(0.0, s % 2 ? 0.5 : 0.0);
      const SynthScene scene = SynthesizeScene(options);
      SCOPED_TRACE("fovy " + std::to_string(fovy_deg) + ", seed " + std::to_string(options.seed));
      const Eigen::Vector3d eye = CameraCenterInWorld(scene.truth.cam_from_world);
      const Correspondences& c = scene.correspondences;
      ASSERT_EQ(c.points_in_world.size(), 50u);
      for (size_t i = 0; i < c.points_in_world.size(); ++i) {
        const Eigen::Vector3d& x = c.points_in_world[i];
        const Eigen::Vector3d normal = FaceNormal(x);
        const Eigen::Vector3d centre_to_eye = eye - normal.cwiseProduct(kBoxHalf);
        EXPECT_GT(normal.dot(centre_to_eye), kMinFaceCosine * centre_to_eye.norm())
            << "point " << i + 1;
        EXPECT_GT(normal.dot(eye - x), 0.0) << "point " << i + 1;
        const auto pixel = PixelFromWorld(scene.truth, x);
        ASSERT_TRUE(pixel.has_value()) << "point " << i + 1;
        EXPECT_NEAR((*pixel - c.pixels[i]).norm(), 0.0, kExactPx) << "point " << i + 1;
        EXPECT_GE(pixel->x(), 0.0);
        EXPECT_LE(pixel->x(), options.image_size.width - 1.0);
        EXPECT_GE(pixel->y(), 0.0);
        EXPECT_LE(pixel->y(), options.image_size.height - 1.0);
      }
    }
  }
}

}  // namespace
}  // namespace camproj
