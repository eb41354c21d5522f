// The outlier stage (lib/src/fit/outliers.h): the search for a mis-click the fit absorbed.
#include "fit/outliers.h"

#include <vector>

#include <gtest/gtest.h>

#include "camproj/model_select.h"
#include "camproj/synth.h"
#include "fit/statistics.h"
#include "seeds.h"

namespace camproj {
namespace {

// Clean points with Gaussian noise at exactly the assumed noise (the 1 px prior): a point's drop
// in the sum of squares when it is left out is sigma^2 chi2_2 for a model linear near its one
// minimum, so the largest of N exceeds sigma^2 chi2_2(1 - alpha / N) with probability at most
// alpha (Bonferroni) = AutoFitOptions::significance = 1e-3 per scene, which bounds how often
// FindAbsorbedOutlier may name a point of a clean scene. A projector before a box (lens shift 0.4
// of the image height), 10 and 12 points (at 8 only 2N - 9 = 7 equations are left: a box's
// clicks are then nearer the nonlinear regime than the bound assumes), 500 seeds each.
TEST(OutliersTest, AbsorbedOutliersAreRarelyFoundInCleanScenes) {
  constexpr double kFalseAlarm = 1e-3;  // AutoFitOptions::significance
  constexpr int kSeeds = 500;
  const AutoFitOptions options;
  ASSERT_EQ(options.significance, kFalseAlarm);
  const internal::NoiseReference noise = internal::NoiseReferenceOf(options);
  ASSERT_EQ(noise.sigma_px, 1.0);
  int trials = 0;
  int found = 0;
  int searched = 0;
  for (const int n : {10, 12}) {
    for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
      SynthOptions synth;
      synth.seed = testing::Seed(1000 * n + seed);
      synth.num_points = n;
      synth.noise_px = noise.sigma_px;
      synth.object = SynthObject::kBox;
      synth.principal_point_offset = Eigen::Vector2d(0.0, 0.4);
      const SynthScene scene = SynthesizeScene(synth);
      const auto& x = scene.correspondences.points_in_world;
      const auto& u = scene.correspondences.pixels;
      const internal::Screen screen = internal::ScreenPoints(x, u, scene.truth.image_size, options, noise);
      if (!screen.consistent) continue;  // the exhaustive search's case, not this one's
      ++trials;
      const internal::OutlierSearch search =
          internal::FindAbsorbedOutlier(x, u, scene.truth.image_size, options, noise, screen);
      double all_px2 = 0.0;
      for (const Eigen::Vector2d& r : screen.fit->fit.residuals_px) all_px2 += r.squaredNorm();
      searched += all_px2 > noise.sigma_px * noise.sigma_px *
                                internal::ChiSquareQuantile(2.0, 1.0 - kFalseAlarm / n);
      if (search.found) {
        ++found;
        EXPECT_EQ(search.outliers.size(), 1u);
        EXPECT_EQ(search.method, "leave-one-out");
      }
    }
  }
  ASSERT_GE(trials, 900) << "the screen refused too many clean scenes to measure the rate";
  EXPECT_GT(searched, 0) << "no scene reached the bound: the search was never tried";
  testing::ExpectRate("clean scenes with an absorbed outlier found", found, trials, kFalseAlarm);
}

}  // namespace
}  // namespace camproj
