// The mirrored reading of the default path's mirror test (lib/src/fit/mirror.h): the depth
// reversal is exact algebra, and the refinement from it runs in the frame it was built in.
#include "fit/mirror.h"

#include <cmath>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "camproj/synth.h"
#include "seeds.h"
#include "fit/common.h"

namespace camproj {
namespace {

// Exact algebra on O(1) numbers: a few ulps of the cam-frame coordinates (~1-10 units).
constexpr double kAlgebraTolerance = 1e-12;

using internal::MirroredZ;

// For every point x, the reversal sees the mirrored point at the same x, y and at the depth
// reflected about the centroid's: 2 z_c - z. Its rotation is proper, and reversing twice gives
// the camera back. 50 seeds of clouds and boxes with lens shift.
TEST(MirrorTest, NeckerReversalReflectsDepthAboutTheCentroid) {
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(seed);
    synth.object = seed % 2 ? SynthObject::kCloud : SynthObject::kBox;
    synth.principal_point_offset = Eigen::Vector2d(0.1, 0.4);
    const SynthScene scene = SynthesizeScene(synth);
    const std::vector<Eigen::Vector3d>& points = scene.correspondences.points_in_world;
    const Camera reversed = internal::NeckerReversal(scene.truth, points);
    EXPECT_NEAR(reversed.cam_from_world.rotation.determinant(), 1.0, kAlgebraTolerance);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& x : points) centroid += x / points.size();
    const double z_c = (scene.truth.cam_from_world * centroid).z();
    const std::vector<Eigen::Vector3d> mirrored = MirroredZ(points);
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = scene.truth.cam_from_world * points[i];
      const Eigen::Vector3d q = reversed.cam_from_world * mirrored[i];
      EXPECT_NEAR(q.x(), p.x(), kAlgebraTolerance * p.norm()) << "seed " << seed;
      EXPECT_NEAR(q.y(), p.y(), kAlgebraTolerance * p.norm()) << "seed " << seed;
      EXPECT_NEAR(q.z(), 2.0 * z_c - p.z(), kAlgebraTolerance * p.norm()) << "seed " << seed;
    }
    const Camera twice = internal::NeckerReversal(reversed, mirrored);
    EXPECT_LE((twice.cam_from_world.rotation - scene.truth.cam_from_world.rotation).norm(),
              kAlgebraTolerance);
    EXPECT_LE((twice.cam_from_world.translation - scene.truth.cam_from_world.translation).norm(),
              kAlgebraTolerance * scene.truth.cam_from_world.translation.norm());
  }
}

// Noise-free pixels of a right-handed world, handed to the test as if the world were the
// mirrored one with the reversed camera fitted to it: the mirrored reading is the true camera,
// and the refinement starts exactly there, so it stays at RMS 0 -- up to the refinement's
// convergence tolerance (relative cost change 1e-10 of pixels ~1e3: 1e-6 px is generous).
TEST(MirrorTest, RefinementFromTheReversalOfTheReversalFindsTheTruth) {
  constexpr double kConvergedRmsPx = 1e-6;
  FitOptions model;  // focal, aspect, principal point free
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(seed);
    synth.object = seed % 2 ? SynthObject::kCloud : SynthObject::kBox;
    synth.principal_point_offset = Eigen::Vector2d(0.0, 0.4);
    synth.aspect = 1.01;
    const SynthScene scene = SynthesizeScene(synth);
    const std::vector<Eigen::Vector3d> mirrored = MirroredZ(scene.correspondences.points_in_world);
    const Camera fitted_to_mirrored =
        internal::NeckerReversal(scene.truth, scene.correspondences.points_in_world);
    const std::optional<internal::MirroredReading> reading = internal::FitMirroredReading(
        fitted_to_mirrored, model, mirrored, scene.correspondences.pixels);
    ASSERT_TRUE(reading.has_value()) << "seed " << seed;
    EXPECT_LE(reading->rms_px, kConvergedRmsPx) << "seed " << seed;
    // The reading's camera sees the mirrored world of `mirrored`, the scene's own points.
    const std::vector<Eigen::Vector2d>& pixels = scene.correspondences.pixels;
    for (size_t i = 0; i < pixels.size(); ++i) {
      const std::optional<Eigen::Vector2d> pixel =
          PixelFromWorld(reading->camera, scene.correspondences.points_in_world[i]);
      ASSERT_TRUE(pixel.has_value()) << "seed " << seed << ", point " << i;
      EXPECT_LE((*pixel - pixels[i]).norm(), kConvergedRmsPx * std::sqrt(pixels.size()))
          << "seed " << seed << ", point " << i;
    }
  }
}

// The refinement's early stop (read_below_px2): a reading the caller reads (one that fits) is
// the same with or without it, and one it stops is left above the cost asked for, never below
// the full refinement's cost. A strong perspective (the default synthetic cloud, 20 points):
// the proper world read as mirrored from the true camera's depth reversal fits tens of px off;
// the mirrored world read from the reversal of the truth fits exactly (as above).
TEST(MirrorTest, RefinementStopsOnlyWhereTheCostAskedForIsOutOfReach) {
  constexpr double kReadBelowPx2 = 1.0;  // the caller reads a sum of squares up to 1 px^2
  FitOptions model;
  int stopped = 0;
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(seed);
    synth.num_points = 20;
    const SynthScene scene = SynthesizeScene(synth);
    const std::vector<Eigen::Vector3d>& points = scene.correspondences.points_in_world;
    const std::vector<Eigen::Vector2d>& pixels = scene.correspondences.pixels;
    const double n = static_cast<double>(points.size());
    // Read: the same reading to the last bit.
    const std::vector<Eigen::Vector3d> mirrored = MirroredZ(points);
    const Camera exact = internal::NeckerReversal(scene.truth, points);
    const auto fits = internal::FitMirroredReading(exact, model, mirrored, pixels);
    const auto fits_limited =
        internal::FitMirroredReading(exact, model, mirrored, pixels, nullptr, kReadBelowPx2);
    ASSERT_TRUE(fits && fits_limited) << "seed " << seed;
    EXPECT_EQ(fits_limited->rms_px, fits->rms_px) << "seed " << seed;
    // Not read: stopped above the cost asked for, or the same as the full refinement.
    const auto full = internal::FitMirroredReading(scene.truth, model, points, pixels);
    const auto limited =
        internal::FitMirroredReading(scene.truth, model, points, pixels, nullptr, kReadBelowPx2);
    if (!full || !limited) continue;  // a point behind the reading: nothing to compare
    if (limited->rms_px == full->rms_px) continue;
    ++stopped;
    EXPECT_GT(n * limited->rms_px * limited->rms_px, kReadBelowPx2) << "seed " << seed;
    EXPECT_GT(limited->rms_px, full->rms_px) << "seed " << seed;
  }
  // Far out of reach at 20 points of a 45-degree view: most stop (all 50 at seeds 1-50).
  EXPECT_GE(stopped, 25);
}

}  // namespace
}  // namespace camproj
